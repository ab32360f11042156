#include "crumple/paper/boundary_curve.hpp"

#include <algorithm>
#include <stdexcept>

namespace crumple::paper {

std::vector<double> outlineCornerParameters(const GeometricMesh& g) {
  std::vector<double> s(g.outline.size(), 0.0);
  for (std::size_t k = 1; k < g.outline.size(); ++k)
    s[k] = s[k - 1] + (g.outline[k] - g.outline[k - 1]).norm();
  return s;
}

BoundaryCurve boundaryCurveFromMesh(const GeometricMesh& g, std::span<const Vec2> pattern,
                                    std::span<const Vec3> positions, double tolerance) {
  if (pattern.size() != positions.size()) {
    throw std::invalid_argument("boundaryCurveFromMesh: pattern and positions differ in size");
  }
  const std::size_t nc = g.outline.size();
  if (nc < 3)
    throw std::invalid_argument("boundaryCurveFromMesh: outline has fewer than 3 corners");
  std::vector<BoundarySample> samples;
  for (std::size_t v = 0; v < pattern.size(); ++v) {
    const Vec2& p = pattern[v];
    // Nearest outline segment.
    int best = -1;
    double bestDist = tolerance;
    for (std::size_t k = 0; k < nc; ++k) {
      const Vec2& a = g.outline[k];
      const Vec2& b = g.outline[(k + 1) % nc];
      const Vec2 d = b - a;
      const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
      const double dist = (a + t * d - p).norm();
      if (dist <= bestDist) {
        bestDist = dist;
        best = static_cast<int>(k);
      }
    }
    if (best < 0) continue;
    samples.push_back({outlineParameter(g, p, best), positions[v]});
  }
  if (samples.empty())
    throw std::invalid_argument("boundaryCurveFromMesh: no vertex lies on the outline");
  const std::vector<double> corners = outlineCornerParameters(g);
  return BoundaryCurve(std::move(samples), outlinePerimeter(g), corners);
}

}  // namespace crumple::paper
