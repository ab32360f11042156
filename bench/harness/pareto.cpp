#include "pareto.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace crumple::bench {

std::vector<ParetoPoint> paretoFront(std::vector<ParetoPoint> points) {
  std::erase_if(points, [](const ParetoPoint& p) {
    return !std::isfinite(p.error) || !std::isfinite(p.ms) || p.error < 0.0 || p.ms < 0.0;
  });
  std::stable_sort(points.begin(), points.end(), [](const ParetoPoint& a, const ParetoPoint& b) {
    return a.error < b.error || (a.error == b.error && a.ms < b.ms);
  });
  // Sweeping by increasing error, a point is on the front when it is cheaper
  // than every point with a smaller or equal error.
  std::vector<ParetoPoint> front;
  double cheapest = std::numeric_limits<double>::infinity();
  for (const ParetoPoint& p : points)
    if (p.ms < cheapest) {
      front.push_back(p);
      cheapest = p.ms;
    }
  return front;
}

ParetoVerdict paretoVerdict(const std::vector<ParetoPoint>& hybrid,
                            const std::vector<ParetoPoint>& elastic) {
  const std::vector<ParetoPoint> hybridFront = paretoFront(hybrid);
  ParetoVerdict verdict;
  verdict.below = true;
  for (const ParetoPoint& e : paretoFront(elastic)) {
    VerdictLevel level;
    level.elastic = e;
    for (const ParetoPoint& h : hybridFront)  // the cheapest is the last one that qualifies
      if (h.error <= e.error) level.hybrid = h;
    if (level.hybrid && level.hybrid->ms > 0.0) level.ratio = e.ms / level.hybrid->ms;
    verdict.below = verdict.below && level.hybrid && level.ratio > 1.0;
    verdict.levels.push_back(level);
  }
  verdict.below = verdict.below && !verdict.levels.empty();
  return verdict;
}

}  // namespace crumple::bench
