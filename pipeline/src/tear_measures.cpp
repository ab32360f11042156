#include "crumple/pipeline/tear_measures.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace crumple::pipeline {

std::vector<Vec2> tearTips(const ShotReport& report, int tear) {
  std::vector<Vec2> tips;
  for (const auto& a : report.tearAdvances) {
    if (a.event.tear != tear) continue;
    if (tips.empty()) tips.push_back(a.event.from);
    tips.push_back(a.event.to);
  }
  return tips;
}

double straightTearDeviation(const std::vector<Vec2>& points, double bisectorU) {
  double worst = 0.0;
  for (const Vec2& q : points) worst = std::max(worst, std::abs(q.x() - bisectorU));
  return worst;
}

// Roman (thesis 3.3.1): the tangent at every point c of the path bisects the
// angle between the directions from the pulling points A and B to c.
std::vector<double> hyperbolaAngleErrors(const std::vector<Vec2>& tips, const Vec2& a,
                                         const Vec2& b, double step) {
  std::vector<double> errors;
  for (std::size_t k = 0; k + 1 < tips.size(); ++k) {
    const Vec2 d = tips[k + 1] - tips[k];
    const int n = std::max(1, static_cast<int>(d.norm() / step));
    for (int i = 0; i < n; ++i) {
      const Vec2 c = tips[k] + d * ((i + 0.5) / n);
      const Vec2 bisector = (c - a).normalized() + (c - b).normalized();
      errors.push_back(std::acos(std::clamp(bisector.normalized().dot(d.normalized()), -1.0, 1.0)) *
                       180.0 / std::numbers::pi);
    }
  }
  return errors;
}

}  // namespace crumple::pipeline
