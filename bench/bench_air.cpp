// What the air costs (docs/AIR.md "Cost"):
//
//   bench_air [SAMPLE ...] [--runs 3] [--json FILE]
//
// Simulates each sample (default: drape, wiggle, cylinder-fold, crumple,
// slide-on-table: the handles drive them, so still air changes their motion
// little and the difference is the air's work) on one thread, without
// rendering, `runs` times with `[air]` (still air, the defaults) and `runs`
// times without, interleaved, and prints the medians of the simulation step
// per frame, their ratio, (with - without) / with, and the air's own terms
// timed inside the step with it (set-up, energy, gradient, Hessian) and
// their share of it. The difference also holds what the air changes in the
// motion (a sheet the air holds back may buckle more, and Newton work
// more); the own terms are what the air computes.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "crumple/core/parallel.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"
#include "shot_bench.hpp"

namespace {

using namespace crumple;

struct Row {
  std::string sample;
  int frames = 0;
  double withMs = 0.0, withoutMs = 0.0, share = 0.0;
  double airMs = 0.0, airShare = 0.0;  // the air's own terms, timed inside the step
};

}  // namespace

int main(int argc, char** argv) {
  const auto parsed = bench::parseShotBenchArgs(
      argc, argv, "bench_air", {"drape", "wiggle", "cylinder-fold", "crumple", "slide-on-table"});
  if (!parsed) return 0;
  const bench::ShotBenchArgs& args = *parsed;
  setThreadCount(1);
  const bench::ScratchDir scratch("crumple-bench-air");
  std::vector<Row> rows;
  for (const std::string& name : args.samples) {
    io::SceneSpec without = bench::sampleScene(name);
    io::SceneSpec with = without;
    if (without.sim.air) {
      without.sim.air.reset();
    } else {
      with.sim.air.emplace();
    }
    std::vector<double> withMs, withoutMs, airMs, airShare;
    Row row;
    row.sample = name;
    for (int r = 0; r < args.runs; ++r)
      for (const bool air : {true, false}) {
        const pipeline::ShotReport report =
            bench::simulateQuietly(air ? with : without, scratch / name);
        const double frames = std::max(1, report.framesSimulated - 1);
        (air ? withMs : withoutMs).push_back(bench::stepTotalMs(report) / frames);
        if (air) {
          airMs.push_back(report.airMs / frames);
          airShare.push_back(report.airShareOfStep());
        }
        row.frames = report.framesSimulated;
      }
    row.withMs = bench::median(withMs);
    row.withoutMs = bench::median(withoutMs);
    row.share = (row.withMs - row.withoutMs) / row.withMs;
    row.airMs = bench::median(airMs);
    row.airShare = bench::median(airShare);
    rows.push_back(row);
    std::printf(
        "%-16s %3d frames  step %8.2f ms/frame with [air], %8.2f without  ratio %.3f  "
        "(with - without) / with %+5.1f %%  the air's own terms %6.2f ms/frame, %4.1f %% of "
        "the step\n",
        row.sample.c_str(), row.frames, row.withMs, row.withoutMs, row.withMs / row.withoutMs,
        100.0 * row.share, row.airMs, 100.0 * row.airShare);
    std::fflush(stdout);
  }
  const auto toJson = [](const Row& r) {
    return bench::format(
        "{\"sample\": \"%s\", \"frames\": %d, \"step_ms_per_frame_with_air\": %.6g, "
        "\"step_ms_per_frame_without_air\": %.6g, \"difference_share\": %.6g, "
        "\"air_ms_per_frame\": %.6g, \"air_share_of_step\": %.6g}",
        r.sample.c_str(), r.frames, r.withMs, r.withoutMs, r.share, r.airMs, r.airShare);
  };
  if (!bench::writeSampleRows(args, "bench_air", rows, toJson)) return 1;
  return 0;
}
