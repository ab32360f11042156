// Whole-shot benchmark of the hybrid crumpling model on the samples:
// per-stage milliseconds per frame (elastic, geometric, cone
// fitting, S_P rebuild, isometry), and the same motions simulated by the
// plain elastic model on fixed meshes of decreasing edge length, with the
// length error (c_mean, paper Table IV) each reaches. Medians of `--runs`
// repetitions measured in one process, so ratios compare like with like.
//
//   build/bench/bench_hybrid [--runs 3] [--frames N] [--edges 1,0.5,0.25] [sample ...]
//
// A sample the model cannot finish is reported up to its last good frame.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"
#include "json_number.hpp"

namespace fs = std::filesystem;
using namespace crumple;

namespace {

struct Run {
  std::map<std::string, double> msPerFrame;  // stage -> ms/frame
  double total = 0.0;                        // simulation ms/frame (no cache, no render)
  double cMean = 0.0;
  double nComp = 0.0;
  int frames = 0;
  int singular = 0;
  std::size_t triangles = 0;
  std::string error;
};

// The figures of a shot that stopped early, from the summary.json it left.
double jsonNumber(const std::string& text, const std::string& key) {
  return bench::jsonNumber(text, key, 0.0);
}

Run fromSummary(const std::string& outDir, const std::string& error) {
  std::ifstream in(fs::path(outDir) / "summary.json");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Run run;
  run.error = error;
  for (const char* stage : {"elastic", "geometric", "cones", "rebuild", "isometry", "strain limit",
                            "contacts", "contact check", "tear", "sound events"}) {
    const double ms = jsonNumber(text, stage);
    if (ms > 0.0) run.msPerFrame[stage] = ms, run.total += ms;
  }
  run.cMean = jsonNumber(text, "c_mean_mean");
  run.nComp = jsonNumber(text, "n_comp_max");
  run.frames = static_cast<int>(jsonNumber(text, "frames_simulated"));
  run.singular = static_cast<int>(jsonNumber(text, "singular_vertices"));
  run.triangles = static_cast<std::size_t>(jsonNumber(text, "max_triangles"));
  return run;
}

Run runOnce(const io::SceneSpec& scene, int lastFrame, const std::string& outDir) {
  pipeline::ShotOptions options;
  options.outDir = outDir;
  options.render = false;
  options.log = nullptr;  // quiet
  options.interactive = 0;
  if (lastFrame >= 0)
    options.frames = pipeline::FrameRange{scene.frameStart, std::min(lastFrame, scene.frameEnd)};
  Run run;
  pipeline::ShotReport report;
  try {
    report = pipeline::runShot(scene, options);
  } catch (const NumericalError& e) {
    run.error = e.what();
    // The summary of the frames that did run is still written.
  }
  if (!run.error.empty()) return fromSummary(outDir, run.error);
  for (const auto& [name, cost] : report.stages) {
    if (name == "cache" || name == "render") continue;
    run.msPerFrame[name] = cost.msPerFrame();
    run.total += cost.msPerFrame();
  }
  run.cMean = report.meanCMean;
  run.nComp = report.maxNComp;
  run.frames = report.framesSimulated;
  run.singular = report.singularVertices;
  run.triangles = report.maxTriangles > 0 ? report.maxTriangles : report.triangles;
  return run;
}

Run median(std::vector<Run> runs) {
  std::sort(runs.begin(), runs.end(), [](const Run& a, const Run& b) { return a.total < b.total; });
  return runs[runs.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 3;
  int lastFrame = -1;
  std::vector<double> edgesCm = {1.0, 0.5, 0.25};
  std::vector<std::string> samples;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--frames" && i + 1 < argc) {
      lastFrame = std::atoi(argv[++i]);
    } else if (a == "--edges" && i + 1 < argc) {
      // The fixed elastic meshes' edge lengths (cm), comma-separated.
      edgesCm.clear();
      std::string list = argv[++i];
      for (std::size_t at = 0; at <= list.size();) {
        const std::size_t comma = std::min(list.find(',', at), list.size());
        const double edge = std::atof(list.substr(at, comma - at).c_str());
        if (!(edge > 0.0)) {
          std::fprintf(stderr, "bench_hybrid: --edges wants positive lengths in cm, got '%s'\n",
                       list.c_str());
          return 2;
        }
        edgesCm.push_back(edge);
        at = comma + 1;
      }
    } else if (a == "--help" || a == "-h") {
      std::puts(
          "bench_hybrid [--runs 3] [--frames LAST] [--edges 1,0.5,0.25] [sample ...]\n"
          "  (default: cylinder-fold first-singularity moebius unload crumple; the elastic\n"
          "  model on fixed meshes of each --edges length in cm, over the frames the\n"
          "  crumpling model ran)");
      return 0;
    } else {
      samples.push_back(a);
    }
  }
  const fs::path root = CRUMPLE_SOURCE_DIR;
  if (samples.empty())
    samples = {"cylinder-fold", "first-singularity", "moebius", "unload", "crumple"};
  const fs::path tmp = fs::temp_directory_path() / "crumple-bench-hybrid";
  std::printf("%-18s %-22s %7s %6s %9s %9s %7s %8s %8s %8s %8s %8s %9s\n", "sample", "model",
              "frames", "tris", "c_mean%", "n_comp%", "sing", "elastic", "geometr", "cones",
              "rebuild", "isometry", "ms/frame");
  for (const std::string& name : samples) {
    const io::SceneSpec base =
        io::loadScene(io::resolveScenePath((root / "samples" / name).string()));
    std::vector<Run> hybridRuns;
    for (int r = 0; r < runs; ++r)
      hybridRuns.push_back(runOnce(base, lastFrame, (tmp / name / "hybrid").string()));
    const Run h = median(hybridRuns);
    const auto ms = [&](const Run& run, const char* stage) {
      const auto it = run.msPerFrame.find(stage);
      return it == run.msPerFrame.end() ? 0.0 : it->second;
    };
    std::printf("%-18s %-22s %7d %6zu %9.3f %9.2f %7d %8.2f %8.2f %8.2f %8.2f %8.2f %9.2f%s\n",
                name.c_str(), "hybrid", h.frames, h.triangles, 100.0 * h.cMean, 100.0 * h.nComp,
                h.singular, ms(h, "elastic"), ms(h, "geometric"), ms(h, "cones"), ms(h, "rebuild"),
                ms(h, "isometry"), h.total, h.error.empty() ? "" : "  (stopped early)");
    // The plain elastic model on fixed meshes, over the frames the hybrid ran.
    const int frames = base.frameStart + std::max(h.frames, 1) - 1;
    for (const double edgeCm : edgesCm) {
      io::SceneSpec elastic = base;
      elastic.model.type = io::ModelSpec::Type::Elastic;
      elastic.sheet.maxEdge = edgeCm / 100.0;
      std::vector<Run> er;
      for (int r = 0; r < runs; ++r)
        er.push_back(runOnce(elastic, frames, (tmp / name / "elastic").string()));
      const Run e = median(er);
      char label[64];
      std::snprintf(label, sizeof label, "elastic %.2f cm", edgeCm);
      std::printf(
          "%-18s %-22s %7d %6zu %9.3f %9.2f %7s %8.2f %8s %8s %8s %8s %9.2f  ratio %.1fx%s\n", "",
          label, e.frames, e.triangles, 100.0 * e.cMean, 100.0 * e.nComp, "-", ms(e, "elastic"),
          "-", "-", "-", "-", e.total, h.total > 0.0 ? e.total / h.total : 0.0,
          e.error.empty() ? "" : "  (stopped early)");
    }
  }
  std::error_code ec;
  fs::remove_all(tmp, ec);
  return 0;
}
