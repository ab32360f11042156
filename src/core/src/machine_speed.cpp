#include "crumple/core/machine_speed.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "crumple/core/work_budget.hpp"

namespace crumple {
namespace {

constexpr std::size_t kVertices = std::size_t{1} << 15;
constexpr int kSweeps = 12;

// One run of the reference workload: kSweeps sweeps of edge lengths and
// their gradients, scattered to the vertices, over a triangle strip whose
// vertex order is scrambled (a multiplicative permutation), so that the
// gathers miss the cache as a mesh's do. Returns a checksum that keeps the
// work from being optimized away.
double referenceRun() {
  std::vector<std::array<double, 3>> position(kVertices), gradient(kVertices);
  std::vector<std::array<std::uint32_t, 2>> edges;
  edges.reserve(3 * kVertices);
  const auto scrambled = [](std::size_t i) {
    return static_cast<std::uint32_t>((i * 40503u) & (kVertices - 1));  // odd: a permutation
  };
  for (std::size_t i = 0; i < kVertices; ++i) {
    const double u = static_cast<double>(i / 2), v = static_cast<double>(i % 2);
    position[scrambled(i)] = {0.01 * u, 0.01 * v, 0.001 * std::sin(u)};
    for (std::size_t step = 1; step <= 3 && i + step < kVertices; ++step)
      edges.push_back({scrambled(i), scrambled(i + step)});
  }
  double checksum = 0.0;
  for (int sweep = 0; sweep < kSweeps; ++sweep) {
    for (const auto& [a, b] : edges) {
      const std::array<double, 3>& pa = position[a];
      const std::array<double, 3>& pb = position[b];
      const double d[3] = {pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]};
      const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      const double pull = (length - 0.01) / std::max(length, 1e-12);
      for (int k = 0; k < 3; ++k) {
        gradient[a][k] += pull * d[k];
        gradient[b][k] -= pull * d[k];
      }
    }
    for (std::size_t i = 0; i < kVertices; ++i)
      for (int k = 0; k < 3; ++k) {
        position[i][k] -= 1e-3 * gradient[i][k];
        checksum += gradient[i][k];
        gradient[i][k] = 0.0;
      }
  }
  return checksum;
}

double measure() {
  double best = 1e300;
  volatile double sink = 0.0;
  for (int run = 0; run < 3; ++run) {
    const double start = processCpuSeconds();
    sink = sink + referenceRun();
    best = std::min(best, processCpuSeconds() - start);
  }
  return std::max(best, 1e-6);
}

}  // namespace

double referenceWorkSeconds() {
  static const double seconds = measure();
  return seconds;
}

double machineSlowness() { return referenceWorkSeconds() / kReferenceWorkSeconds; }

}  // namespace crumple
