// The `crumple` command line (DESIGN.md "The command line"). Exit status:
// 0 success, 1 internal failure (including a numerical failure that survived
// substep halving), 2 bad input.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include "crumple/core/error.hpp"
#include "crumple/core/parallel.hpp"
#include "crumple/exporters/pcache.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/shot.hpp"

namespace {

using namespace crumple;

struct Args {
  std::string scene;
  std::string cache;
  std::string out;
  std::string frames;
  std::optional<std::uint64_t> seed;
  int threads = 1;
  std::string backend = "osmesa";
  bool json = false;
  bool debugStructure = false;
};

int runOrSimulate(const Args& a, bool render) {
  setThreadCount(a.threads);
  const auto scene = io::loadScene(io::resolveScenePath(a.scene));
  pipeline::ShotOptions options;
  options.outDir = a.out;
  if (!a.frames.empty()) options.frames = pipeline::parseFrameRange(a.frames);
  options.seed = a.seed;
  options.render = render;
  options.debugStructure = a.debugStructure;
  const auto report = pipeline::runShot(scene, options);
  std::fputs(pipeline::summaryText(report).c_str(), stdout);
  return 0;
}

int renderCommand(const Args& a) {
  setThreadCount(a.threads);
  if (a.backend != "osmesa")
    throw InputError("--backend",
                     "'" + a.backend + "' is not available yet; this build renders with osmesa");
  pipeline::RenderOptions options;
  if (!a.frames.empty()) options.frames = pipeline::parseFrameRange(a.frames);
  options.framesDir = a.out;
  options.debugStructure = a.debugStructure;
  const auto report = pipeline::renderCache(a.cache, options);
  std::printf("%d frames rendered (osmesa), %.2f ms/frame\n  frames:  %s/\n", report.framesRendered,
              report.cost.msPerFrame(), report.framesDir.c_str());
  return 0;
}

int inspectCommand(const Args& a) {
  const cache::CacheReader reader(a.cache);
  std::fputs((a.json ? pipeline::inspectJson(reader) : pipeline::inspectText(reader)).c_str(),
             stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "crumple: paper animation -- simulate a sheet from keyframed handles, cache it, render it.\n"
      "Exit status: 0 success, 1 internal failure, 2 bad input."};
  app.set_version_flag("--version", "crumple 0.1.0");
  app.require_subcommand(1);
  Args a;

  auto* run =
      app.add_subcommand("run", "Simulate a shot, write its cache and render its frames (OSMesa).");
  auto* simulate = app.add_subcommand("simulate", "Simulate a shot and write its cache only.");
  for (auto* cmd : {run, simulate}) {
    cmd->add_option("SCENE", a.scene, "scene.toml, or a folder holding one")->required();
    cmd->add_option("--out", a.out,
                    "output folder (default: the scene's [output] dir, else out/<scene name>)");
    cmd->add_option(
        "--frames", a.frames,
        "A-B: simulate from the scene's first frame to B, render A-B (default: the scene's range)");
    cmd->add_option(
        "--seed", a.seed,
        "override the scene's seed (it places the crumpling model's singular vertices; the "
        "elastic model draws no random numbers)");
    cmd->add_option("--threads", a.threads, "worker threads; results are identical for any count")
        ->check(CLI::Range(1, 256));
  }
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
  render->add_option("--backend", a.backend, "renderer: osmesa (the only backend in this build)")
      ->capture_default_str();
  render->add_option("--out", a.out, "frames folder (default: frames/ beside the cache)");
  render
      ->add_option("--threads", a.threads,
                   "accepted for farm scripts; OSMesa's rasteriser sizes its own threads "
                   "(LP_NUM_THREADS) and the images are identical either way")
      ->check(CLI::Range(1, 256));
  auto* inspect = app.add_subcommand(
      "inspect", "Print per-frame sizes, strain, sharpest fold and handle error of a cache.");
  inspect->add_option("CACHE", a.cache, "a .pcache file")->required();
  inspect->add_flag("--json", a.json, "one JSON object for scripts");

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
