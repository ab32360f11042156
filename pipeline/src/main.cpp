// The `crumple` command line (DESIGN.md "The command line"). Exit status:
// 0 success, 1 internal failure (including a numerical failure that survived
// substep halving), 2 bad input.
#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>

#include "bench_harness.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/parallel.hpp"
#include "crumple/exporters/exr.hpp"
#include "crumple/exporters/pcache.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/export.hpp"
#include "crumple/pipeline/farm.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/shape_compare.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/pipeline/sound.hpp"
#include "crumple/render/embree_renderer.hpp"
#include "crumple/render/image_compare.hpp"

namespace {

using namespace crumple;

struct Args {
  std::string scene;
  std::string cache;
  std::string out;
  std::string frames;
  std::string seed;  // --seed as typed (parseSeed)
  int threads = 1;
  std::string backend = "osmesa";
  int spp = 16;
  int bounces = 4;
  std::string pass = "beauty";
  bool exr = false;
  bool noPng = false;
  bool contactSheet = false;
  bool movie = false;
  bool json = false;
  bool debugStructure = false;
  int checkpointEvery = 0;
  bool resume = false;
  // compare
  std::string imageA, imageB, metric = "flip", diff;
  double tolerance = 0.05;
  std::optional<double> shapeTolerance;  // caches: m, on every frame's mean distance
  // sound
  std::optional<int> rate, channels;
  std::string format, database;
  std::optional<double> gainDb;
  bool noSpectrogram = false;
  bool listEvents = false;
  // export
  std::string exportFormat;
  // farm
  pipeline::SlurmOptions slurm;
  bool dryRun = false;
  // bench
  bench::BenchOptions bench;
  std::string benchSamples;
  bool noProjection = false;
};

pipeline::RenderSettings renderSettings(const Args& a) {
  pipeline::RenderSettings r;
  if (a.backend == "embree")
    r.backend = pipeline::RenderSettings::Backend::Embree;
  else if (a.backend == "osmesa")
    r.backend = pipeline::RenderSettings::Backend::Osmesa;
  else
    throw InputError("--backend", "'" + a.backend + "' is not a backend (osmesa or embree)");
  r.samplesPerPixel = a.spp;
  r.maxBounces = a.bounces;
  if (a.pass == "albedo")
    r.pass = render::RenderPass::Albedo;
  else if (a.pass != "beauty")
    throw InputError("--pass", "'" + a.pass + "' is not a pass (beauty or albedo)");
  r.exr = a.exr;
  r.png = !a.noPng;
  if (!r.png && !r.exr) throw InputError("--no-png", "needs --exr (otherwise nothing is written)");
  r.contactSheet = a.contactSheet;
  r.movie = a.movie;
  return r;
}

// Options shared by `run` and `render`: how the frames are drawn.
void addRenderOptions(CLI::App* cmd, Args& a) {
  cmd->add_option("--backend", a.backend,
                  "renderer: osmesa (the fast preview rasteriser) or embree (the path tracer)")
      ->capture_default_str();
  cmd->add_option("--spp", a.spp, "embree: samples per pixel")
      ->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  cmd->add_option("--bounces", a.bounces, "embree: diffuse bounces after the first hit")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  cmd->add_option("--pass", a.pass,
                  "beauty (lit) or albedo (the unlit surface colour the two backends agree on)")
      ->capture_default_str();
  cmd->add_flag("--exr", a.exr, "also write NNNN.exr (linear, premultiplied alpha, half floats)");
  cmd->add_flag("--no-png", a.noPng, "do not write NNNN.png (with --exr)");
  cmd->add_flag("--contact-sheet", a.contactSheet,
                "write contact_sheet.png into the shot's folder (beside the cache): a grid of up "
                "to 36 of the rendered frames, evenly spaced, labelled with their numbers");
  cmd->add_flag("--movie", a.movie,
                "write preview.mp4 into the shot's folder (beside the cache) with ffmpeg (H.264), "
                "with the shot's sound.wav muxed in when there is one; says so when ffmpeg is not "
                "installed");
}

// --seed: a whole number in [0, 2^63 - 1], the range the scene file's seed
// takes (TOML integers), not wrapped around.
std::uint64_t parseSeed(const std::string& text) {
  std::uint64_t seed = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), seed);
  if (text.empty() || text[0] == '-' || text[0] == '+' || ec != std::errc() ||
      end != text.data() + text.size() ||
      seed > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
    throw InputError("--seed", "'" + text + "' is not a seed (a whole number from 0 to " +
                                   std::to_string(std::numeric_limits<std::int64_t>::max()) + ")");
  return seed;
}

int runOrSimulate(const Args& a, bool render) {
  setThreadCount(a.threads);
  const auto scene = io::loadScene(io::resolveScenePath(a.scene));
  pipeline::ShotOptions options;
  options.outDir = a.out;
  if (!a.frames.empty()) options.frames = pipeline::parseFrameRange(a.frames);
  if (!a.seed.empty()) options.seed = parseSeed(a.seed);
  options.render = render;
  options.debugStructure = a.debugStructure;
  options.checkpointEvery = a.checkpointEvery;
  options.resume = a.resume;
  if (render) options.rendering = renderSettings(a);
  const auto report = pipeline::runShot(scene, options);
  std::fputs(pipeline::summaryText(report).c_str(), stdout);
  return 0;
}

int renderCommand(const Args& a) {
  setThreadCount(a.threads);
  pipeline::RenderOptions options;
  options.rendering = renderSettings(a);
  if (!a.frames.empty()) options.frames = pipeline::parseFrameRange(a.frames);
  options.framesDir = a.out;
  options.debugStructure = a.debugStructure;
  const auto report = pipeline::renderCache(a.cache, options);
  std::printf("%d frames rendered (%s), %.2f ms/frame\n  frames:  %s/\n", report.framesRendered,
              pipeline::backendName(options.rendering.backend), report.cost.msPerFrame(),
              report.framesDir.c_str());
  if (!report.contactSheetPath.empty())
    std::printf("  contact sheet: %s\n", report.contactSheetPath.c_str());
  if (!report.moviePath.empty()) std::printf("  movie:   %s\n", report.moviePath.c_str());
  for (const auto& n : report.notes) std::printf("  note: %s\n", n.c_str());
  return 0;
}

int soundCommand(const Args& a) {
  if (a.listEvents) {
    std::fputs(pipeline::eventTimeline(a.cache).c_str(), stdout);
    return 0;
  }
  pipeline::SoundOptions options;
  options.out = a.out;
  options.sampleRate = a.rate;
  options.channels = a.channels;
  if (!a.format.empty()) {
    if (a.format != "pcm24" && a.format != "float")
      throw InputError("--format", "'" + a.format + "' is not a format (pcm24 or float)");
    options.floatSamples = a.format == "float";
  }
  options.database = a.database;
  options.gainDb = a.gainDb;
  options.spectrogram = !a.noSpectrogram;
  const auto r = pipeline::makeSound(a.cache, options);
  std::printf(
      "soundtrack: %.3f s, %d frames, %d Hz, %s, synthesised in %.1f ms (%.0fx real time)\n"
      "  events:  %ld crumpling (%ld clac, %ld flap resonators), %ld friction (%ld constrained, "
      "%ld free resonators), %ld tearing\n"
      "  level:   gain %+.1f dB, peak %.3f, %lld samples clipped\n"
      "  database: %s\n  wav:     %s\n",
      r.seconds, r.frames, r.sampleRate, r.channels == 1 ? "mono" : "stereo", r.synthesisMs,
      r.synthesisMs > 0.0 ? 1000.0 * r.seconds / r.synthesisMs : 0.0, r.crumplingEvents,
      r.clacResonators, r.flapResonators, r.frictionEvents, r.constrainedFriction, r.freeFriction,
      r.tearingEvents, r.gainDb, r.peak, static_cast<long long>(r.clipped), r.databasePath.c_str(),
      r.wavPath.c_str());
  if (!r.spectrogramPath.empty()) std::printf("  spectrogram: %s\n", r.spectrogramPath.c_str());
  for (const auto& n : r.notes) std::printf("  note: %s\n", n.c_str());
  return 0;
}

// Reads a PNG, or an EXR converted to 8-bit sRGB (straight alpha).
ImageRGBA8 readImage(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".exr" || ext == ".EXR")
    return render::toSrgb8(exporters::readExr(path), Vec3::Zero());
  return exporters::readPng(path);
}

// `crumple compare A.pcache B.pcache`: the two shots' shapes frame by frame
// (pipeline/shape_compare.hpp).
int compareShapesCommand(const Args& a) {
  if (a.shapeTolerance && !(std::isfinite(*a.shapeTolerance) && *a.shapeTolerance >= 0.0))
    throw InputError("--shape-tolerance", "must be a finite distance >= 0 (m)");
  const cache::CacheReader ra(a.imageA);
  const cache::CacheReader rb(a.imageB);
  std::vector<pipeline::ShapeDistance> d = pipeline::compareShapes(ra, rb);
  if (!a.frames.empty()) {
    const pipeline::FrameRange range = pipeline::parseFrameRange(a.frames);
    std::erase_if(d, [&](const auto& x) { return x.frame < range.first || x.frame > range.last; });
    if (d.empty()) throw InputError("--frames", "'" + a.frames + "': no frame both caches hold");
  }
  double worst = 0.0;
  int worstFrame = d.front().frame;
  for (const auto& x : d)
    if (x.mean > worst) {
      worst = x.mean;
      worstFrame = x.frame;
    }
  const bool ok = !a.shapeTolerance || worst <= *a.shapeTolerance;
  if (a.json) {
    std::printf("{\"frames\": [");
    for (std::size_t i = 0; i < d.size(); ++i)
      std::printf(
          "%s{\"frame\": %d, \"mean\": %.9g, \"max\": %.9g, \"outside\": %zu, "
          "\"singular_vertices\": %zu}",
          i > 0 ? ", " : "", d[i].frame, d[i].mean, d[i].max, d[i].outside, d[i].singularVertices);
    std::printf("], \"worst_mean\": %.9g, \"worst_frame\": %d}\n", worst, worstFrame);
  } else {
    std::printf(" frame    mean[m]     max[m]  outside  singular(A)\n");
    for (const auto& x : d)
      std::printf("%6d %10.4g %10.4g %8zu %12zu\n", x.frame, x.mean, x.max, x.outside,
                  x.singularVertices);
    std::printf("%s largest mean distance %.4g m at frame %d over %zu frames", ok ? "PASS" : "FAIL",
                worst, worstFrame, d.size());
    if (a.shapeTolerance) std::printf(" (tolerance %.4g m)", *a.shapeTolerance);
    std::printf("\n");
  }
  return ok ? 0 : 1;
}

bool isCache(const std::string& path) {
  return std::filesystem::path(path).extension() == ".pcache";
}

int compareCommand(const Args& a) {
  if (isCache(a.imageA) || isCache(a.imageB)) {
    if (!isCache(a.imageA) || !isCache(a.imageB))
      throw InputError(a.imageB, "compare takes two images or two .pcache caches");
    return compareShapesCommand(a);
  }
  render::ImageMetric metric = render::ImageMetric::Flip;
  if (a.metric == "mae")
    metric = render::ImageMetric::Mae;
  else if (a.metric == "psnr")
    metric = render::ImageMetric::Psnr;
  else if (a.metric != "flip")
    throw InputError("--metric", "'" + a.metric + "' is not a metric (mae, psnr or flip)");
  if (!std::isfinite(a.tolerance) || a.tolerance < 0.0)
    throw InputError("--tolerance", "must be a finite number >= 0");
  const ImageRGBA8 ia = readImage(a.imageA);
  const ImageRGBA8 ib = readImage(a.imageB);
  if (ia.width != ib.width || ia.height != ib.height)
    throw InputError(a.imageB, "is " + std::to_string(ib.width) + "x" + std::to_string(ib.height) +
                                   ", " + a.imageA + " is " + std::to_string(ia.width) + "x" +
                                   std::to_string(ia.height));
  const auto c = render::compareImages(ia, ib, metric);
  const std::string diffPath =
      !a.diff.empty() ? a.diff
                      : (std::filesystem::path(a.imageB).parent_path() /
                         (std::filesystem::path(a.imageB).stem().string() + ".diff.png"))
                            .string();
  exporters::writePng(diffPath, c.diff);
  const bool ok = render::passes(c, metric, a.tolerance);
  std::printf(
      "%s %s: %.6g (tolerance %.6g, %s); mean |RGB difference| %.4g/255, alpha IoU %.6f\n"
      "  diff: %s\n",
      ok ? "PASS" : "FAIL", a.metric.c_str(), c.value, a.tolerance,
      metric == render::ImageMetric::Psnr ? "higher is better" : "lower is better", c.maeRgb,
      c.alphaIoU, diffPath.c_str());
  return ok ? 0 : 1;
}

// `crumple export`: the cached frames as OBJ, PLY, glTF or USDA files.
int exportCommand(const Args& a) {
  pipeline::ExportOptions options;
  options.format = pipeline::parseExportFormat(a.exportFormat);
  options.outDir = a.out;
  if (!a.frames.empty()) options.frames = pipeline::parseFrameRange(a.frames);
  const auto r = pipeline::exportCache(a.cache, options);
  std::printf("%d frames exported as %s (%zu files) in %.1f ms\n  folder:  %s/\n", r.frames,
              pipeline::exportFormatName(options.format), r.files.size(), r.ms, r.outDir.c_str());
  if (r.tornFrames > 0) std::printf("  tears:   %d frames with a tear texture\n", r.tornFrames);
  for (const auto& n : r.notes) std::printf("  note: %s\n", n.c_str());
  return 0;
}

int inspectCommand(const Args& a) {
  const cache::CacheReader reader(a.cache);
  std::fputs((a.json ? pipeline::inspectJson(reader) : pipeline::inspectText(reader)).c_str(),
             stdout);
  return 0;
}

// `crumple farm slurm`: the shot's sbatch scripts, printed (--dry-run) or
// written and submitted; `crumple farm movie`: the finalize job's movie.
int farmCommand(const Args& a, const CLI::App& slurm) {
  if (!slurm.parsed()) {
    std::string note;
    const std::string movie = pipeline::makeShotMovie(a.cache, note);
    std::printf("movie: %s\n", movie.c_str());
    if (!note.empty()) std::printf("  note: %s\n", note.c_str());
    return 0;
  }
  const auto s = pipeline::slurmScripts(io::loadScene(io::resolveScenePath(a.scene)), a.slurm);
  if (a.dryRun) {
    for (const auto& [name, text] :
         {std::pair{"simulate", &s.simulate}, std::pair{"render", &s.render},
          std::pair{"finalize", &s.finalize}})
      std::printf("# ---- %s/%s.sbatch\n%s", s.farmDir.c_str(), name, text->c_str());
    std::printf("# ---- submission (dry run: nothing written, nothing submitted)\n%s",
                pipeline::sbatchCommands(s).c_str());
    return 0;
  }
  const auto jobs = pipeline::submitSlurm(s);
  std::printf(
      "simulate job %s\nrender job %s (array 0-%zu: frames %d-%d in chunks of %d)\nfinalize job "
      "%s\n  scripts: %s/\n  logs:    %s/\n  shot:    %s/\n",
      jobs.simulate.c_str(), jobs.render.c_str(), s.chunks.size() - 1, s.frames.first,
      s.frames.last, a.slurm.chunk, jobs.finalize.c_str(), s.farmDir.c_str(), s.logsDir.c_str(),
      s.outDir.c_str());
  return 0;
}

// `crumple bench`: speed against error (docs/BENCH.md).
int benchCommand(Args& a, int argc, char** argv) {
  if (!a.benchSamples.empty()) {
    std::string name;
    for (std::istringstream in(a.benchSamples); std::getline(in, name, ',');)
      if (!name.empty()) a.bench.samples.push_back(name);
  }
  a.bench.projection = !a.noProjection;
  a.bench.commandLine = "crumple";
  for (int i = 1; i < argc; ++i) a.bench.commandLine += std::string(" ") + argv[i];
  bench::runBench(a.bench, std::cerr);
  std::printf("report: %s/report.md\n  csv:   %s/bench.csv\n  plot:  %s/pareto.png\n",
              a.bench.outDir.c_str(), a.bench.outDir.c_str(), a.bench.outDir.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "crumple: paper animation -- simulate a sheet from keyframed handles, cache it, render it, "
      "make its sound.\n"
      "Exit status: 0 success, 1 internal failure, 2 bad input."};
  app.set_version_flag("--version", "crumple 0.1.0");
  app.require_subcommand(1);
  Args a;

  auto* run = app.add_subcommand(
      "run",
      "Simulate a shot, write its cache and render its frames (and, for a scene with [sound], "
      "write its soundtrack sound.wav).");
  auto* simulate = app.add_subcommand(
      "simulate",
      "Simulate a shot and write its cache only (with the sound events of a scene with [sound]).");
  for (auto* cmd : {run, simulate}) {
    cmd->add_option("SCENE", a.scene, "scene.toml, or a folder holding one")->required();
    cmd->add_option("--out", a.out,
                    "output folder (default: the scene's [output] dir, else out/<scene name>); "
                    "one crumple writes into a folder at a time (DIR/.crumple.lock): another "
                    "one writing there makes this exit 2");
    cmd->add_option(
        "--frames", a.frames,
        "A-B: simulate from the scene's first frame to B, render A-B (default: the scene's range)");
    cmd->add_option(
        "--seed", a.seed,
        "override the scene's seed, 0 ... 2^63 - 1 (it places the crumpling model's singular "
        "vertices; the elastic model draws no random numbers)");
    cmd->add_option("--threads", a.threads, "worker threads; results are identical for any count")
        ->check(CLI::Range(1, 256));
    cmd->add_option("--checkpoint-every", a.checkpointEvery,
                    "N: write the whole simulation state to DIR/checkpoint.bin every N frames "
                    "(atomically)")
        ->check(CLI::Range(1, 1 << 30));
    cmd->add_flag("--resume", a.resume,
                  "go on from DIR/checkpoint.bin after an interruption: the cache and the "
                  "summary end as an uninterrupted run's (the cache byte-identical); exit 2 when "
                  "the scene file, its animation file, paper preset or texture changed since");
  }
  addRenderOptions(run, a);
  run->add_flag(
      "--debug-structure", a.debugStructure,
      "draw the crumpling model's structure: flat regions green, curved regions magenta "
      "with their rulings, singular vertices red, junction vertices yellow, handles black");
  auto* render =
      app.add_subcommand("render", "Render frames of a cache (frame-parallel farm work).");
  render->add_flag("--debug-structure", a.debugStructure,
                   "draw the crumpling model's structure (see `run --help`)");
  render->add_option("CACHE", a.cache, "a .pcache file")->required();
  render->add_option("--frames", a.frames, "A-B: frames to render (default: every cached frame)");
  addRenderOptions(render, a);
  render->add_option("--out", a.out,
                     "frames folder (default: frames/ beside the cache); locked while rendering "
                     "(exit 2 when another crumple writes there), shared by renders of a "
                     "--frames range (a farm's array tasks)");
  render
      ->add_option("--threads", a.threads,
                   "embree: worker threads (the images are identical for any count); osmesa: "
                   "the rasteriser sizes its own threads (LP_NUM_THREADS), identical images too")
      ->check(CLI::Range(1, 256));
  auto* soundCmd = app.add_subcommand(
      "sound",
      "Make the soundtrack of a cache whose scene has [sound]: crumpling, friction and tearing "
      "sounds from the events the simulation stored, heard from the camera; a WAV lasting "
      "exactly frame_count / fps, and its spectrogram PNG beside it.");
  soundCmd->add_option("CACHE", a.cache, "a .pcache file")->required();
  soundCmd->add_option("--out", a.out,
                       "the WAV file, or a folder to write sound.wav into (default: sound.wav "
                       "beside the cache); its folder is locked while writing (exit 2 when "
                       "another crumple writes there)");
  soundCmd
      ->add_option("--rate", a.rate, "sample rate: 48000 or 44100 (default: the scene's, 48000)")
      ->check(CLI::IsMember({48000, 44100}));
  soundCmd->add_option("--format", a.format,
                       "pcm24 (24-bit PCM) or float (32-bit float) (default: the scene's, pcm24)");
  soundCmd->add_option("--channels", a.channels, "1 (mono) or 2 (stereo) (default: the scene's, 2)")
      ->check(CLI::IsMember({1, 2}));
  soundCmd->add_option("--database", a.database,
                       "sound database folder (default: the scene's [sound] database, else "
                       "assets/sound/default)");
  soundCmd->add_option("--gain-db", a.gainDb,
                       "a fixed gain in dB, -200 ... 200 (default: the mix's peak normalised to "
                       "-1 dBFS)");
  soundCmd->add_flag("--no-spectrogram", a.noSpectrogram, "do not write the PNG");
  soundCmd->add_flag("--events", a.listEvents,
                     "print the cache's sound events, one line each, and make no sound");
  auto* compare = app.add_subcommand(
      "compare",
      "Compare two images (PNG, or EXR as sRGB) for golden-image tests, writing a diff image; "
      "or two caches (.pcache) by their shapes: per shared frame, the mean and largest distance "
      "between the sheets' points at the same pattern position, whatever their meshes "
      "(docs/CRUMPLING.md). Exit 0 when within the tolerance, 1 when not, 2 on bad input.");
  compare->add_option("A", a.imageA, "reference image or cache")->required();
  compare->add_option("B", a.imageB, "image or cache under test")->required();
  compare->add_option("--shape-tolerance", a.shapeTolerance,
                      "caches: pass when every frame's mean distance is at most this (m)");
  compare->add_option("--frames", a.frames,
                      "caches: A-B, the frames to compare (default: all shared)");
  compare->add_flag("--json", a.json, "caches: one JSON object for scripts");
  compare
      ->add_option("--metric", a.metric,
                   "mae: mean |difference| over RGBA in 8-bit units; psnr: dB over RGBA; flip: "
                   "mean LDR-FLIP error in [0, 1] (Andersson et al. 2020) of the images over grey")
      ->capture_default_str();
  compare
      ->add_option("--tolerance", a.tolerance,
                   "pass when mae/flip <= tolerance, or psnr >= tolerance")
      ->capture_default_str();
  compare->add_option("--diff", a.diff, "diff image path (default: B's folder, <B>.diff.png)");
  auto* inspect = app.add_subcommand(
      "inspect",
      "Print per-frame sizes, strain, sharpest fold, handle error and popping (the sheet's jump "
      "against its handles' motion, docs/CRUMPLING.md) of a cache.");
  inspect->add_option("CACHE", a.cache, "a .pcache file")->required();
  inspect->add_flag("--json", a.json,
                    "one JSON object for scripts; per frame also how far the sheet passes into "
                    "itself (self_depth in thicknesses, self_crossings) and the crumpling "
                    "model's structure changes (structure_changes)");
  auto* exportCmd = app.add_subcommand(
      "export",
      "Export cached frames for DCC tools (docs/EXPORT.md): obj (NNNN.obj + .mtl, UVs = the "
      "pattern, torn frames cut by NNNN_tears.png), ply (binary NNNN.ply, UVs, region per face), "
      "gltf (NNNN.glb, and shot.glb with every frame as a node shown only on its frame) or usda "
      "(shot.usda, a time-varying Mesh). Needs only the cache.");
  exportCmd->add_option("CACHE", a.cache, "a .pcache file")->required();
  exportCmd->add_option("--format", a.exportFormat, "obj, ply, gltf or usda")->required();
  exportCmd->add_option("--out", a.out,
                        "output folder (default: export/<format>/ beside the cache); locked while "
                        "writing (exit 2 when another crumple writes there), shared by exports "
                        "of a --frames range");
  exportCmd->add_option("--frames", a.frames,
                        "A-B: frames to export (default: every cached frame)");
  auto* farm = app.add_subcommand("farm", "Run a shot on a render farm (docs/FARM.md).");
  farm->require_subcommand(1);
  auto* farmSlurm = farm->add_subcommand(
      "slurm",
      "Write a shot's sbatch scripts into DIR/farm/ and submit them: a simulate job, a render "
      "job array over frame chunks after it (afterok), a finalize job (soundtrack, movie) after "
      "the whole array; prints the job ids.");
  farmSlurm->add_option("SCENE", a.scene, "scene.toml, or a folder holding one")->required();
  farmSlurm->add_option("--out", a.slurm.outDir,
                        "the shot folder (default: the scene's [output] dir, else "
                        "out/<scene name>)");
  farmSlurm->add_option("--chunk", a.slurm.chunk, "frames per render array task")
      ->capture_default_str();
  farmSlurm->add_option("--partition", a.slurm.partition, "sbatch --partition of every job");
  farmSlurm->add_option("--time", a.slurm.time, "sbatch --time of every job (e.g. 1:00:00)");
  farmSlurm
      ->add_option("--cpus-per-task", a.slurm.cpusPerTask,
                   "sbatch --cpus-per-task of every job, and its crumple --threads")
      ->check(CLI::PositiveNumber);
  farmSlurm->add_option("--mem", a.slurm.mem, "sbatch --mem of every job (e.g. 4G)");
  farmSlurm->add_option("--render-args", a.slurm.renderArgs,
                        "more `crumple render` arguments for every array task, as one word: "
                        "--render-args=\"--backend embree --spp 64\"");
  farmSlurm->add_option("--crumple", a.slurm.crumple,
                        "the crumple binary the jobs run (default: this one)");
  farmSlurm->add_flag("--no-movie{false}", a.slurm.movie,
                      "finalize makes no preview.mp4 (it makes it by default, with ffmpeg)");
  farmSlurm->add_flag("--dry-run", a.dryRun,
                      "print the scripts and the sbatch command lines; write and submit nothing");
  auto* farmMovie = farm->add_subcommand(
      "movie",
      "The finalize job's movie: preview.mp4 beside the cache from the frames already in "
      "frames/ (with sound.wav when there is one), through ffmpeg; renders nothing.");
  farmMovie->add_option("CACHE", a.cache, "a .pcache file")->required();
  auto* benchCmd = app.add_subcommand(
      "bench",
      "Speed against error (docs/BENCH.md): every sample at its own settings, and on the "
      "paper's examples (cylinder-fold, first-singularity, unload, moebius) the "
      "hybrid model at 1, 2, 4, 8 substeps, and at 1 and 2 with 1000, 3000, 10000 and 30000 "
      "isometry length sweeps, against the elastic model on fixed 2 and 1 cm "
      "meshes at 1, 2, 4 substeps, 0.5 cm at 2 and 4, and on first-singularity (Table II) "
      "0.25 cm at 2; ms per frame by "
      "stage beside c_mean, n_comp, angle defect, handle error and the tear errors. One "
      "thread. Writes DIR/bench.csv, DIR/pareto.png (gnuplot) with each model's Pareto "
      "front, DIR/report.md beside the paper's Tables II-V (and DIR/table3.csv). About 20 "
      "minutes with the defaults (30 at most).");
  benchCmd->add_option("--out", a.bench.outDir, "output folder")->capture_default_str();
  benchCmd->add_option("--samples", a.benchSamples,
                       "a,b,...: sample names under samples/ (paper-types/eps-0.5.toml for a "
                       "variant; default: every sample)");
  benchCmd
      ->add_option("--runs", a.bench.runs,
                   "timed runs per configuration, the median reported (a run over 10 s is "
                   "timed once)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  benchCmd->add_option("--frames", a.bench.lastFrame,
                       "LAST: simulate every configuration up to frame LAST at most");
  benchCmd->add_flag("--quick", a.bench.quick,
                     "a small subset for tests: first-singularity and drape up to frame 24 (or "
                     "--frames), one run, the hybrid model at 1 and 2 substeps, elastic 2 and "
                     "1 cm meshes at 2");
  benchCmd->add_flag("--no-projection", a.noProjection,
                     "skip paper Table III (the isometry projection against Shape-Up)");
  benchCmd->add_option("--source", a.bench.sourceDir,
                       "the source tree whose samples/ are run (default: this build's)");

  // A first word that is neither an option nor a command is named, with the commands.
  if (argc > 1 && argv[1][0] != '-') {
    std::string names;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands({})) {
      known = known || sub->get_name() == argv[1];
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::fprintf(stderr, "crumple: error: '%s' is not a command (one of: %s; see --help)\n",
                   argv[1], names.c_str());
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }

  try {
    if (*run) return runOrSimulate(a, true);
    if (*simulate) return runOrSimulate(a, false);
    if (*render) return renderCommand(a);
    if (*inspect) return inspectCommand(a);
    if (*soundCmd) return soundCommand(a);
    if (*compare) return compareCommand(a);
    if (*exportCmd) return exportCommand(a);
    if (*farm) return farmCommand(a, *farmSlurm);
    if (*benchCmd) return benchCommand(a, argc, argv);
  } catch (const InputError& e) {
    std::fprintf(stderr, "crumple: error: %s\n", e.what());
    return 2;
  } catch (const NumericalError& e) {
    std::fprintf(stderr, "crumple: numerical failure: %s\n", e.what());
    return 1;
  } catch (const CorruptDataError& e) {
    std::fprintf(stderr, "crumple: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crumple: internal error: %s\n", e.what());
    return 1;
  }
  return 1;
}
