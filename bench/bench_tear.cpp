// What tearing costs ("benchmark the tearing stage's cost per frame
// and quote it"):
//
//   bench_tear [SAMPLE ...] [--runs 3] [--json FILE]
//
// Simulates each sample (default: tear-straight, tear-curved, tear-notch)
// `runs` times on one thread, without rendering, and prints the medians of
// the simulation step per frame, the tearing stage per frame (candidates,
// Griffith tests, cuts, detail paths, the elastic model's rebuild on the cut
// mesh and the tear textures' baking) and, of it, the baking; and the
// tearing stage's share of the step.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "crumple/core/parallel.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"
#include "shot_bench.hpp"

namespace {

using namespace crumple;
namespace fs = std::filesystem;

struct Row {
  std::string sample;
  int frames = 0;
  std::size_t advances = 0;
  double stepMs = 0.0, tearMs = 0.0, bakeMs = 0.0, share = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  const auto parsed = bench::parseShotBenchArgs(argc, argv, "bench_tear",
                                                {"tear-straight", "tear-curved", "tear-notch"});
  if (!parsed) return 0;
  const bench::ShotBenchArgs& args = *parsed;
  setThreadCount(1);
  const bench::ScratchDir scratch("crumple-bench-tear");
  std::vector<Row> rows;
  for (const std::string& name : args.samples) {
    const io::SceneSpec scene = bench::sampleScene(name);
    std::vector<double> step, tear, bake, share;
    Row row;
    row.sample = name;
    for (int r = 0; r < args.runs; ++r) {
      const pipeline::ShotReport report = bench::simulateQuietly(scene, scratch / name);
      const double frames = std::max(1, report.framesSimulated - 1);
      const double stepTotal = bench::stepTotalMs(report);
      step.push_back(stepTotal / frames);
      tear.push_back(report.tearMs / frames);
      bake.push_back(report.tearBakeMs / frames);
      share.push_back(stepTotal > 0.0 ? report.tearMs / stepTotal : 0.0);
      row.frames = report.framesSimulated;
      row.advances = report.tearAdvances.size();
    }
    row.stepMs = bench::median(step);
    row.tearMs = bench::median(tear);
    row.bakeMs = bench::median(bake);
    row.share = bench::median(share);
    rows.push_back(row);
    std::printf(
        "%-14s %3d frames, %2zu tip advances  step %8.2f ms/frame  tearing %6.3f ms/frame (baking "
        "%6.3f)  %5.2f %% of the step\n",
        row.sample.c_str(), row.frames, row.advances, row.stepMs, row.tearMs, row.bakeMs,
        100.0 * row.share);
    std::fflush(stdout);
  }
  const auto toJson = [](const Row& r) {
    return bench::format(
        "{\"sample\": \"%s\", \"frames\": %d, \"tip_advances\": %zu, "
        "\"step_ms_per_frame\": %.6g, \"tear_ms_per_frame\": %.6g, "
        "\"bake_ms_per_frame\": %.6g, \"share_of_step\": %.6g}",
        r.sample.c_str(), r.frames, r.advances, r.stepMs, r.tearMs, r.bakeMs, r.share);
  };
  if (!bench::writeSampleRows(args, "bench_tear", rows, toJson)) return 1;
  return 0;
}
