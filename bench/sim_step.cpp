// One elastic substep (paper Sec. 4: backward Euler, Newton + CHOLMOD) of an
// A4 office sheet hung by its two top corners, at ~100, ~1 000 and ~10 000
// triangles. The sheet is released 0.3 rad out of the vertical and simulated
// for a few substeps first, so the timed step starts from a slightly deformed,
// moving state; every iteration restarts from that same state.
//
//   bench_sim --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>

#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/sim/elastic_sheet.hpp"

namespace {

using namespace crumple;

void BM_ElasticSubstep(benchmark::State& state) {
  const double width = 0.21, height = 0.297, tilt = 0.3;
  const double maxEdge = static_cast<double>(state.range(0)) * 1e-6;  // micrometres
  mesh::SheetMesh m = mesh::makeRectangleSheet(width, height, maxEdge);
  const Vec3 vAxis(0.0, std::cos(tilt), std::sin(tilt));
  mesh::placePattern(m, -height * vAxis, Vec3::UnitX(), vAxis);

  sim::Material paper;  // 70 g/m^2 office preset (the Material defaults)
  paper.name = "office";
  sim::ElasticSheet sheet(m, paper, sim::SimParams{});
  const int a = mesh::nearestPatternVertex(m, Vec2(0.0, height));
  const int b = mesh::nearestPatternVertex(m, Vec2(width, height));
  const Vec3 pa = m.positions[static_cast<std::size_t>(a)];
  const Vec3 pb = m.positions[static_cast<std::size_t>(b)];
  const sim::PinFunction pins = [&](double, std::vector<sim::Pin>& out) {
    out.push_back({a, pa});
    out.push_back({b, pb});
  };

  const double dt = 1.0 / 96.0 / 4.0;
  const int warmup = 16;
  for (int i = 0; i < warmup; ++i) sheet.advance(i * dt, dt, pins);
  const std::vector<Vec3> x0 = sheet.positions(), v0 = sheet.velocities();

  long newton = 0, steps = 0;
  for (auto _ : state) {
    state.PauseTiming();
    sheet.setPositions(x0);
    sheet.setVelocities(v0);
    state.ResumeTiming();
    const sim::StepStats s = sheet.advance(warmup * dt, dt, pins);
    newton += s.newtonIterations;
    ++steps;
    benchmark::DoNotOptimize(sheet.positions().data());
  }
  state.counters["triangles"] = static_cast<double>(m.triangleCount());
  state.counters["newton_iters"] = steps > 0 ? static_cast<double>(newton) / steps : 0.0;
}

// maxEdge 52.5 mm -> 96 triangles, 16 mm -> 1 064, 5 mm -> 10 080.
BENCHMARK(BM_ElasticSubstep)->Arg(52500)->Arg(16000)->Arg(5000)->Unit(benchmark::kMillisecond);

}  // namespace
