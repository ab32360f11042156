// Render-time refinement of the crumpling model's curved regions
// (mesh/developable.hpp) on a cached shot: what it does to every frame and
// what it costs an Embree frame.
//
//   bench_refine CACHE [--resolution WxH] [--refine auto|N] [--spp 64]
//                [--runs 3] [--render F[,F...]] [--threads 2] [--json PATH]
//
// - Every frame with an SGEO block: c_mean (paper Table IV) of S_P and of the
//   refined mesh, the runs refined and those the isometry guard left, the
//   largest fold between sub-cells, the most sub-cells of a face, the closure
//   blended out, and the silhouette turning of the curved regions at the
//   given resolution (pipeline/silhouette.hpp) with and without refinement.
// - --render frames: the Embree path tracer at --spp with and without
//   refinement, --runs times each, interleaved; the median wall times of the
//   whole frame (the view built from the cache, refinement included, then a
//   fresh renderer's render()) and their ratio.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_developable.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/parallel.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/pipeline/silhouette.hpp"
#include "crumple/render/renderer.hpp"

using namespace crumple;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

struct Options {
  std::string cache;
  int width = 1920, height = 1080;
  mesh::RefineOptions refine;
  int spp = 64;
  int runs = 3;
  int threads = 2;
  std::vector<int> renderFrames;
  std::string json;
};

[[noreturn]] void usage(const char* problem) {
  std::fprintf(stderr,
               "bench_refine: %s\nusage: bench_refine CACHE [--resolution WxH] [--refine auto|N] "
               "[--spp 64] [--runs 3] [--render F[,F...]] [--threads 2] [--json PATH]\n",
               problem);
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(("missing value after " + a).c_str());
      return argv[++i];
    };
    if (a == "--resolution") {
      const std::string v = value();
      if (std::sscanf(v.c_str(), "%dx%d", &o.width, &o.height) != 2 || o.width < 1 || o.height < 1)
        usage("--resolution takes WxH");
    } else if (a == "--refine") {
      const std::string v = value();
      if (v != "auto") {
        o.refine.mode = mesh::RefineMode::Fixed;
        o.refine.cells = std::atoi(v.c_str());
        if (o.refine.cells < 1) usage("--refine takes auto or a count >= 1");
      }
    } else if (a == "--spp") {
      o.spp = std::atoi(value().c_str());
    } else if (a == "--runs") {
      o.runs = std::max(1, std::atoi(value().c_str()));
    } else if (a == "--threads") {
      o.threads = std::max(1, std::atoi(value().c_str()));
    } else if (a == "--render") {
      std::string v = value();
      for (std::size_t p = 0; p < v.size();) {
        const std::size_t q = std::min(v.find(',', p), v.size());
        o.renderFrames.push_back(std::atoi(v.substr(p, q - p).c_str()));
        p = q + 1;
      }
    } else if (a == "--json") {
      o.json = value();
    } else if (o.cache.empty() && a[0] != '-') {
      o.cache = a;
    } else {
      usage(("unknown argument " + a).c_str());
    }
  }
  if (o.cache.empty()) usage("no cache given");
  return o;
}

double median(std::vector<double> v) {
  std::ranges::sort(v);
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// CPU time of this process so far (user + system, every thread), ms: far
// less disturbed than wall time by other processes on a shared machine.
double cpuMs() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return 1e3 * (u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-3 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

constexpr double kDeg = 180.0 / std::numbers::pi;

int run(const Options& o) {
  setThreadCount(o.threads);
  const cache::CacheReader reader(o.cache);
  const auto& header = reader.header();
  io::SceneSpec scene =
      io::parseScene(header.sceneText, header.sceneFile + " (in " + o.cache + ")",
                     fs::path(header.sceneFile).parent_path().string(), /*checkFiles=*/false);
  scene.camera.width = o.width;
  scene.camera.height = o.height;
  const pipeline::FrameViewBuilder plain(scene, header.extensions);
  const pipeline::FrameViewBuilder refined(scene, header.extensions, o.refine);
  std::printf("%s at %dx%d, refine %s\n", o.cache.c_str(), o.width, o.height,
              o.refine.mode == mesh::RefineMode::Auto
                  ? "auto"
                  : ("fixed " + std::to_string(o.refine.cells)).c_str());
  std::printf(
      "frame  cmean_SP  cmean_ref  delta    runs guard  fold_deg cells closure_mm  "
      "sil_SP_deg sil_ref_deg border_ref_deg  tris\n");
  std::string rows;
  double worstDelta = -1.0, worstFold = 0.0, worstSilhouette = 0.0;
  int frames = 0, guarded = 0, over = 0;
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    const cache::FrameRecord record = reader.readFrame(i);
    const auto structure = cache::decodeDevelopable(record);
    if (!structure || structure->regions.empty()) continue;
    const pipeline::FrameView a = plain.build(record);
    const pipeline::FrameView b = refined.build(record);
    if (!b.refined) continue;
    const mesh::RefineStats& s = *b.refined;
    const auto silA = pipeline::silhouetteTurning(a.sheet, a.scene.camera);
    const auto silB = pipeline::silhouetteTurning(b.sheet, b.scene.camera);
    const double delta = s.lengthErrorRefined - s.lengthErrorSource;
    std::printf(
        "%5d  %.6f  %.6f  %+.1e  %2d/%-2d %2d  %7.3f  %4d  %8.4f  %9.3f  %9.3f  %9.3f  %zu\n",
        record.frame, s.lengthErrorSource, s.lengthErrorRefined, delta, s.refinedRuns, s.runs,
        s.guardedRuns + s.roughRuns, s.largestFold * kDeg, s.largestCells, s.largestClosure * 1e3,
        silA.curved * kDeg, silB.curved * kDeg, silB.border * kDeg, b.sheet.triangleCount());
    ++frames;
    worstDelta = std::max(worstDelta, delta);
    worstFold = std::max(worstFold, s.largestFold);
    worstSilhouette = std::max(worstSilhouette, silB.curved);
    guarded += s.guardedRuns;
    over += delta > o.refine.lengthBudget ? 1 : 0;
    char row[400];
    std::snprintf(row, sizeof row,
                  "%s{\"frame\":%d,\"cmean_sp\":%.9g,\"cmean_refined\":%.9g,\"runs\":%d,"
                  "\"refined_runs\":%d,\"guarded_runs\":%d,\"largest_fold_deg\":%.6g,"
                  "\"largest_cells\":%d,\"closure_m\":%.6g,\"silhouette_sp_deg\":%.6g,"
                  "\"silhouette_refined_deg\":%.6g,\"border_refined_deg\":%.6g}",
                  rows.empty() ? "" : ",", record.frame, s.lengthErrorSource, s.lengthErrorRefined,
                  s.runs, s.refinedRuns, s.guardedRuns, s.largestFold * kDeg, s.largestCells,
                  s.largestClosure, silA.curved * kDeg, silB.curved * kDeg, silB.border * kDeg);
    rows += row;
  }
  std::printf(
      "%d frames refined: largest c_mean increase %.2e (budget %.0e, %d over), "
      "largest fold %.3f deg, largest curved silhouette turn %.3f deg, %d runs guarded\n",
      frames, worstDelta, o.refine.lengthBudget, over, worstFold * kDeg, worstSilhouette * kDeg,
      guarded);

  std::string renders;
  for (int f : o.renderFrames) {
    std::size_t index = reader.frameCount();
    for (std::size_t i = 0; i < reader.frameCount(); ++i)
      if (reader.frameNumber(i) == f) index = i;
    if (index == reader.frameCount()) throw InputError(o.cache, "no frame " + std::to_string(f));
    const cache::FrameRecord record = reader.readFrame(index);
    render::RendererOptions ro;
    ro.width = o.width;
    ro.height = o.height;
    ro.samplesPerPixel = o.spp;
    std::vector<double> plainMs, refinedMs, refineOnlyMs, plainCpu, refinedCpu;
    for (int r = 0; r < o.runs; ++r) {
      for (const pipeline::FrameViewBuilder* builder : {&plain, &refined}) {
        const auto t0 = Clock::now();
        const double cpu0 = cpuMs();
        const pipeline::FrameView fv = builder->build(record);
        const double buildMs = msSince(t0);
        const auto renderer = render::makeRenderer(render::Backend::Embree, ro);
        render::FrameSettings settings;
        settings.frame = f;
        (void)renderer->render(fv.scene, fv.sheet, settings, render::RenderPass::Beauty);
        (builder == &plain ? plainMs : refinedMs).push_back(msSince(t0));
        (builder == &plain ? plainCpu : refinedCpu).push_back(cpuMs() - cpu0);
        if (builder == &refined) refineOnlyMs.push_back(buildMs);
      }
    }
    const double p = median(plainMs), q = median(refinedMs);
    const double pc = median(plainCpu), qc = median(refinedCpu);
    std::printf(
        "frame %d at %d spp: %.0f ms plain, %.0f ms refined (of which building the view %.1f "
        "ms): x%.3f wall, x%.3f CPU (%.0f / %.0f ms) (%d runs, medians)\n",
        f, o.spp, p, q, median(refineOnlyMs), q / p, qc / pc, pc, qc, o.runs);
    char row[240];
    std::snprintf(row, sizeof row,
                  "%s{\"frame\":%d,\"spp\":%d,\"plain_ms\":%.3f,\"refined_ms\":%.3f,"
                  "\"ratio\":%.4f,\"cpu_ratio\":%.4f}",
                  renders.empty() ? "" : ",", f, o.spp, p, q, q / p, qc / pc);
    renders += row;
  }
  if (!o.json.empty()) {
    std::ofstream out(o.json);
    out << "{\"cache\":\"" << o.cache << "\",\"width\":" << o.width << ",\"height\":" << o.height
        << ",\"frames\":[" << rows << "],\"renders\":[" << renders << "]}\n";
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_refine: %s\n", e.what());
    return 1;
  }
}
