#pragma once
// Speed against error: each model's Pareto front in the plane
// (error, ms per frame), and the verdict whether the hybrid model's front
// lies below the plain elastic model's.
#include <optional>
#include <string>
#include <vector>

namespace crumple::bench {

struct ParetoPoint {
  double error = 0.0;  // the error measure (lower is better)
  double ms = 0.0;     // ms per frame (lower is better)
  std::string label;   // the configuration, e.g. "elastic 0.50 cm x2"
};

// The points no other point dominates (error <= and ms <= it, one of them
// strictly), by increasing error (so by decreasing ms). Points with a
// non-finite or negative coordinate are dropped; of equal points one is kept.
std::vector<ParetoPoint> paretoFront(std::vector<ParetoPoint> points);

// At one error level of the elastic front: that elastic point, the cheapest
// hybrid point at that error or better (none when the hybrid model never gets
// that low), and the speed ratio elastic ms / hybrid ms.
struct VerdictLevel {
  ParetoPoint elastic;
  std::optional<ParetoPoint> hybrid;
  double ratio = 0.0;  // 0 without a hybrid point
};
struct ParetoVerdict {
  std::vector<VerdictLevel> levels;
  // Below: at every level there is a hybrid point, and it is faster (ratio > 1).
  bool below = false;
};
ParetoVerdict paretoVerdict(const std::vector<ParetoPoint>& hybrid,
                            const std::vector<ParetoPoint>& elastic);

}  // namespace crumple::bench
