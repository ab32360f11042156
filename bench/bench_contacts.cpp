// What contacts cost ("contact cost per frame for each sample and
// its share of the step"):
//
//   bench_contacts [SAMPLE ...] [--runs 3] [--json FILE]
//
// Simulates each sample (default: slide-on-table, press-on-sphere,
// fold-over) `runs`
// times on one thread, without rendering, and prints the medians of the
// simulation step per frame, the collider and the self-contact work per
// frame (detection, penalties' setup, failsafe; the Newton iterations the
// penalties add are the elastic solve's), their share of the step, and the
// contact-depth check the pipeline runs at every frame.
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
  double stepMs = 0.0, colliderMs = 0.0, selfMs = 0.0, share = 0.0, checkMs = 0.0, depth = 0.0;
  long selfSubsteps = 0;
};

}  // namespace

int main(int argc, char** argv) {
  const auto parsed = bench::parseShotBenchArgs(argc, argv, "bench_contacts",
                                                {"slide-on-table", "press-on-sphere", "fold-over"});
  if (!parsed) return 0;
  const bench::ShotBenchArgs& args = *parsed;
  setThreadCount(1);
  const bench::ScratchDir scratch("crumple-bench-contacts");
  std::vector<Row> rows;
  for (const std::string& name : args.samples) {
    const io::SceneSpec scene = bench::sampleScene(name);
    std::vector<double> step, collider, self, share, check;
    Row row;
    row.sample = name;
    for (int r = 0; r < args.runs; ++r) {
      const pipeline::ShotReport report = bench::simulateQuietly(scene, scratch / name);
      const double frames = std::max(1, report.framesSimulated - 1);
      const double stepTotal = bench::stepTotalMs(report);
      step.push_back(stepTotal / frames);
      collider.push_back(report.contactMs / frames);
      self.push_back(report.selfContactMs / frames);
      share.push_back(report.contactShareOfStep());
      const auto c = report.stages.find("contact check");
      check.push_back(c != report.stages.end() ? c->second.msPerFrame() : 0.0);
      row.frames = report.framesSimulated;
      row.depth = report.maxContactDepth;
      row.selfSubsteps = report.selfContactSteps;
    }
    row.stepMs = bench::median(step);
    row.colliderMs = bench::median(collider);
    row.selfMs = bench::median(self);
    row.share = bench::median(share);
    row.checkMs = bench::median(check);
    rows.push_back(row);
    std::printf(
        "%-16s %3d frames  step %8.2f ms/frame  colliders %6.2f  self-contact %6.2f ms/frame "
        "(%ld substeps)  share %5.1f %%  depth check %5.2f ms/frame  deepest %.3f thickness\n",
        row.sample.c_str(), row.frames, row.stepMs, row.colliderMs, row.selfMs, row.selfSubsteps,
        100.0 * row.share, row.checkMs, row.depth);
    std::fflush(stdout);
  }
  const auto toJson = [](const Row& r) {
    return bench::format(
        "{\"sample\": \"%s\", \"frames\": %d, \"step_ms_per_frame\": %.6g, "
        "\"collider_ms_per_frame\": %.6g, \"self_contact_ms_per_frame\": %.6g, "
        "\"share_of_step\": %.6g, \"depth_check_ms_per_frame\": %.6g, "
        "\"max_depth_thicknesses\": %.6g}",
        r.sample.c_str(), r.frames, r.stepMs, r.colliderMs, r.selfMs, r.share, r.checkMs, r.depth);
  };
  if (!bench::writeSampleRows(args, "bench_contacts", rows, toJson)) return 1;
  return 0;
}
