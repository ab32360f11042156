// The `crumple` commands that run a shot or read a cache: run, simulate,
// render, sound, export, inspect, farm.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <system_error>

#include "cli.hpp"
#include "crumple/cache/pcache.hpp"
#include "crumple/core/debug.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/parallel.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/export.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/refine.hpp"
#include "crumple/pipeline/sound.hpp"
#include "crumple/pipeline/starter.hpp"
#include "crumple/render/aov.hpp"

namespace crumple::cli {

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
  if (!a.aovs.empty()) {
    try {
      r.aovs = render::parseAovList(a.aovs);
    } catch (const std::invalid_argument& e) {
      throw InputError("--aov", e.what());
    }
    if (r.backend != pipeline::RenderSettings::Backend::Embree)
      throw InputError("--aov", "AOVs are computed by the embree backend only (--backend embree)");
    r.exr = true;
  }
  if (!r.png && !r.exr) throw InputError("--no-png", "needs --exr (otherwise nothing is written)");
  if (!a.refine.empty()) r.refine = pipeline::parseRefine(a.refine, "--refine");
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
  cmd->add_flag("--no-png", a.noPng, "do not write NNNN.png (with --exr or --aov)");
  cmd->add_option("--aov", a.aovs,
                  "embree: AOV layers in NNNN.exr beside RGBA (implies --exr), a comma-separated "
                  "list of depth (Z), normal (N.XYZ), albedo (albedo.RGB), position (P.XYZ), "
                  "region (region.RGB: flat, curved, singular-neighbourhood coverage), handle-id "
                  "(IndexHandle.X), object-id (IndexOB.X: 1 sheet, 2 ground, 3+ props); "
                  "docs/RENDERING.md \"AOVs\"");
  cmd->add_option("--refine", a.refine,
                  "the crumpling model's curved regions drawn finer along their rulings, "
                  "isometric to the pattern: auto (folds of at most 1.8 degrees between sub-cells "
                  "and a quarter-pixel chord error on the frame's camera), off (the simulated "
                  "mesh), or N sub-cells per face; default auto for embree, off for osmesa; "
                  "docs/RENDERING.md \"Refinement\"");
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

const char* const kShutterShotHelp =
    "motion blur: OPEN,CLOSE in frames relative to each frame's time, -1 <= OPEN < CLOSE <= 1 "
    "(-0.25,0.25: a centred 180-degree shutter), or S for -S/2,S/2; 0 = none. Overrides the "
    "scene's [camera] shutter: the cache stores the sheet's velocities (12 bytes per vertex per "
    "frame) and `--backend embree` blurs the frames; osmesa draws them sharp";
const char* const kShutterRenderHelp =
    "motion blur: OPEN,CLOSE in frames relative to each frame's time, -1 <= OPEN < CLOSE <= 1, "
    "or S for -S/2,S/2; 0 = none (default: the shutter the cache was simulated with, if any). An "
    "open shutter needs a cache simulated with one ([camera] shutter or simulate --shutter: "
    "its velocities), else exit 2; embree only, osmesa draws every frame sharp";

cache::Shutter parseShutter(const std::string& text) {
  const auto number = [&](const std::string& part) {
    double v = 0.0;
    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (part.empty() || ec != std::errc() || end != part.data() + part.size() || !std::isfinite(v))
      throw InputError("--shutter", "'" + text + "' is not OPEN,CLOSE or S (numbers of frames)");
    return v;
  };
  cache::Shutter s;
  if (const auto comma = text.find(','); comma != std::string::npos) {
    s.open = number(text.substr(0, comma));
    s.close = number(text.substr(comma + 1));
    if (std::abs(s.open) > 1.0 || std::abs(s.close) > 1.0)
      throw InputError("--shutter", "'" + text + "': OPEN and CLOSE must be in [-1, 1] frames");
    if (!(s.open < s.close) && !(s.open == 0.0 && s.close == 0.0))
      throw InputError("--shutter", "'" + text + "': the shutter must open before it closes");
  } else {
    const double length = number(text);
    if (!(length >= 0.0 && length <= 2.0))
      throw InputError("--shutter", "'" + text + "': S must be in [0, 2] frames");
    s = {-0.5 * length, 0.5 * length};
  }
  if (!s.on()) return {};
  return s;
}

int runOrSimulate(const Args& a, bool render) {
  setThreadCount(a.threads);
  setDebugOptions(parseDebugOptions(a.debug));
  auto scene = io::loadScene(io::resolveScenePath(a.scene));
  if (!a.shutter.empty()) {
    // As the scene's [camera] shutter: the cache records it (SHTR) and its velocities.
    const cache::Shutter s = parseShutter(a.shutter);
    scene.camera.shutterOpen = s.open;
    scene.camera.shutterClose = s.close;
  }
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
  if (!a.shutter.empty()) options.rendering.shutter = parseShutter(a.shutter);
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

// `crumple export`: the cached frames as OBJ, PLY, glTF or USDA files.
int exportCommand(const Args& a) {
  pipeline::ExportOptions options;
  options.format = pipeline::parseExportFormat(a.exportFormat);
  options.outDir = a.out;
  if (!a.frames.empty()) options.frames = pipeline::parseFrameRange(a.frames);
  if (!a.refine.empty()) options.refine = pipeline::parseRefine(a.refine, "--refine");
  const auto r = pipeline::exportCache(a.cache, options);
  std::printf("%d frames exported as %s (%zu files) in %.1f ms\n  folder:  %s/\n", r.frames,
              pipeline::exportFormatName(options.format), r.files.size(), r.ms, r.outDir.c_str());
  if (r.tornFrames > 0) std::printf("  tears:   %d frames with a tear texture\n", r.tornFrames);
  if (r.refinedFrames > 0)
    std::printf("  refined: %d frames with curved regions drawn finer (--refine %s)\n",
                r.refinedFrames, pipeline::refineName(options.refine).c_str());
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

// `crumple init`: the starter shot (pipeline/starter.hpp).
int initCommand(const Args& a) {
  pipeline::writeStarterShot(a.scene, a.force);
  std::printf(
      "starter shot written:\n  scene:     %s/scene.toml (commented; docs/SCENE.md has every "
      "key)\n  animation: %s/gather.gltf (the four corner handles)\nrun it with:\n  crumple "
      "run %s\n",
      a.scene.c_str(), a.scene.c_str(), a.scene.c_str());
  return 0;
}

}  // namespace crumple::cli
