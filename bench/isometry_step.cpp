// Isometry projection (paper Sec. 6.3) per call on a rolled sheet with 1 %
// noise, ~120 and ~400 triangles (the sizes of the crumpling model's S_P).
// Run with --benchmark_repetitions=5 --benchmark_report_aggregates_only=true.
#include <benchmark/benchmark.h>

#include <cmath>

#include "crumple/core/rng.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/paper/isometry.hpp"

namespace {

using namespace crumple;

void BM_IsometryProject(benchmark::State& state) {
  const double maxEdge = state.range(0) / 1000.0;  // mm -> m
  mesh::SheetMesh sheet = mesh::makeRectangleSheet(0.10, 0.075, maxEdge);
  std::vector<Vec3> noisy;
  const CounterRng rng(5, 0, RngPurpose::Generic);
  std::uint64_t draw = 0;
  for (const Vec2& p : sheet.pattern) {
    const double a = p.x() / 0.03;  // rolled onto a 3 cm cylinder
    Vec3 x(0.03 * std::sin(a), p.y(), 0.03 * (1.0 - std::cos(a)));
    for (int c = 0; c < 3; ++c) x[c] += 0.01 * maxEdge * (2.0 * rng.uniform(draw++) - 1.0);
    noisy.push_back(x);
  }
  paper::IsometryProjector projector(sheet.pattern, sheet.triangles,
                                     {0, static_cast<int>(sheet.pattern.size()) - 1});
  paper::IsometryStats stats;
  for (auto _ : state) {
    std::vector<Vec3> p = noisy;
    stats = projector.project(p);
    benchmark::DoNotOptimize(p.data());
  }
  state.counters["triangles"] = static_cast<double>(sheet.triangles.size());
  state.counters["c_mean_before"] = stats.meanLengthErrorBefore;
  state.counters["c_mean_after"] = stats.meanLengthErrorAfter;
}
BENCHMARK(BM_IsometryProject)->Arg(17)->Arg(10)->Unit(benchmark::kMillisecond);

}  // namespace
