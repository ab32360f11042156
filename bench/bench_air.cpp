// What the air costs (docs/AIR.md "Cost"):
//
//   bench_air [SAMPLE ...] [--runs 3] [--paths 1] [--json FILE]
//
// Simulates each sample (default: drape, wiggle, cylinder-fold, crumple,
// slide-on-table: the handles drive them) on one thread, without rendering,
// `runs` times each, interleaved: with `[air]` (still air, the defaults),
// with thin air (`[air]` at density 1e-6 kg/m^3: every one of the air's
// terms computed, and the motion that of no air) and without. It prints the
// medians of the simulation step per frame and their ratios, the air's own
// terms timed inside the step with it (set-up, energy, gradient, Hessian,
// corrector) and their share of it, and the Newton iterations per substep.
// With against without also holds what the air changes in the motion (a
// sheet the air holds back may buckle elsewhere, and Newton work more or
// less); thin air against without is the air's work on the same motion.
// --paths N also runs each sample at its substeps + 1 ... + N - 1: the same
// shot along other paths (a buckling sheet's Newton work depends on its
// path more than on anything the air computes), each timed with, in thin
// air and without; the ratios are then the medians of the paths' ratios
// (the step times' medians over every path and run mix substep counts).
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
  int substeps = 0, paths = 1;
  double ratio = 0.0, thinRatio = 0.0;  // with (thin) / without: the paths' ratios' median
  double withMs = 0.0, thinMs = 0.0, withoutMs = 0.0, share = 0.0;
  double airMs = 0.0, airShare = 0.0;            // the air's own terms, timed inside the step
  double newtonWith = 0.0, newtonWithout = 0.0;  // iterations per substep
};

// The three runs of a sample.
enum class Air { Still, Thin, None };

// Air at this density (kg/m^3, the parser's least) does nothing measurable to
// the motion and all of its work.
constexpr double kThinAir = 1e-6;

}  // namespace

int main(int argc, char** argv) {
  // --paths N is this benchmark's own; the rest is the shot benchmarks' line.
  int paths = 1;
  std::vector<char*> rest{argv[0]};
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--paths" && i + 1 < argc)
      paths = std::clamp(std::atoi(argv[++i]), 1, 16);
    else
      rest.push_back(argv[i]);
  }
  const auto parsed =
      bench::parseShotBenchArgs(static_cast<int>(rest.size()), rest.data(), "bench_air",
                                {"drape", "wiggle", "cylinder-fold", "crumple", "slide-on-table"});
  if (!parsed) {
    std::printf("       --paths N: also at the sample's substeps + 1 ... + N - 1\n");
    return 0;
  }
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
    io::SceneSpec thin = with;
    thin.sim.air->density = kThinAir;
    std::vector<double> withMs, thinMs, withoutMs, airMs, airShare, newtonWith, newtonWithout,
        ratios, thinRatios;
    Row row;
    row.sample = name;
    row.substeps = without.substeps;
    row.paths = paths;
    for (int path = 0; path < paths; ++path) {
      std::vector<double> pathWith, pathThin, pathWithout;
      for (int r = 0; r < args.runs; ++r)
        for (const Air air : {Air::Still, Air::Thin, Air::None}) {
          io::SceneSpec scene = air == Air::Still ? with : air == Air::Thin ? thin : without;
          scene.substeps = without.substeps + path;
          const pipeline::ShotReport report = bench::simulateQuietly(scene, scratch / name);
          const double frames = std::max(1, report.framesSimulated - 1);
          const double step = bench::stepTotalMs(report) / frames;
          const double newton = static_cast<double>(report.newtonIterations) /
                                static_cast<double>(std::max(1L, report.substeps));
          if (air == Air::Still) {
            withMs.push_back(step);
            pathWith.push_back(step);
            airMs.push_back(report.airMs / frames);
            airShare.push_back(report.airShareOfStep());
            newtonWith.push_back(newton);
          } else if (air == Air::Thin) {
            thinMs.push_back(step);
            pathThin.push_back(step);
          } else {
            withoutMs.push_back(step);
            pathWithout.push_back(step);
            newtonWithout.push_back(newton);
          }
          row.frames = report.framesSimulated;
        }
      ratios.push_back(bench::median(pathWith) / bench::median(pathWithout));
      thinRatios.push_back(bench::median(pathThin) / bench::median(pathWithout));
      if (paths > 1)
        std::printf(
            "  %-14s substeps %2d: step %8.2f ms/frame with [air], %8.2f in thin air, "
            "%8.2f without, ratio %.3f, thin %.3f\n",
            name.c_str(), without.substeps + path, bench::median(pathWith), bench::median(pathThin),
            bench::median(pathWithout), ratios.back(), thinRatios.back());
    }
    row.withMs = bench::median(withMs);
    row.thinMs = bench::median(thinMs);
    row.withoutMs = bench::median(withoutMs);
    row.ratio = bench::median(ratios);
    row.thinRatio = bench::median(thinRatios);
    row.share = (row.withMs - row.withoutMs) / row.withMs;
    row.airMs = bench::median(airMs);
    row.airShare = bench::median(airShare);
    row.newtonWith = bench::median(newtonWith);
    row.newtonWithout = bench::median(newtonWithout);
    rows.push_back(row);
    std::printf(
        "%-16s %3d frames  step %8.2f ms/frame with [air], %8.2f in thin air, %8.2f without  "
        "ratio %.3f, thin %.3f  the air's own terms %6.2f ms/frame, %4.1f %% of the step  "
        "Newton %.2f / %.2f iterations a substep\n",
        row.sample.c_str(), row.frames, row.withMs, row.thinMs, row.withoutMs, row.ratio,
        row.thinRatio, row.airMs, 100.0 * row.airShare, row.newtonWith, row.newtonWithout);
    std::fflush(stdout);
  }
  const auto toJson = [](const Row& r) {
    return bench::format(
        "{\"sample\": \"%s\", \"frames\": %d, \"substeps\": %d, \"paths\": %d, "
        "\"ratio_with_to_without\": %.6g, \"ratio_thin_to_without\": %.6g, "
        "\"step_ms_per_frame_with_air\": %.6g, "
        "\"step_ms_per_frame_thin_air\": %.6g, \"step_ms_per_frame_without_air\": %.6g, "
        "\"difference_share\": %.6g, \"air_ms_per_frame\": %.6g, \"air_share_of_step\": %.6g, "
        "\"newton_per_substep_with_air\": %.6g, \"newton_per_substep_without_air\": %.6g}",
        r.sample.c_str(), r.frames, r.substeps, r.paths, r.ratio, r.thinRatio, r.withMs, r.thinMs,
        r.withoutMs, r.share, r.airMs, r.airShare, r.newtonWith, r.newtonWithout);
  };
  if (!bench::writeSampleRows(args, "bench_air", rows, toJson)) return 1;
  return 0;
}
