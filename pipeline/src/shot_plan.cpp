#include "shot_plan.hpp"

#include <filesystem>

#include "crumple/core/error.hpp"

namespace crumple::pipeline {
namespace fs = std::filesystem;

ShotPlan planShot(const io::SceneSpec& scene, const ShotOptions& options) {
  ShotPlan plan;
  plan.outDir = !options.outDir.empty()     ? options.outDir
                : !scene.output.dir.empty() ? scene.output.dir
                                            : (fs::path("out") / scene.name).string();
  plan.cachePath = (fs::path(plan.outDir) / "cache.pcache").string();
  plan.summaryPath = (fs::path(plan.outDir) / "summary.json").string();
  plan.checkpointPath = (fs::path(plan.outDir) / "checkpoint.bin").string();
  plan.firstFrame = scene.frameStart;
  plan.lastFrame = scene.frameEnd;
  plan.renderFirst = scene.frameStart;
  if (options.frames) {
    const FrameRange& r = *options.frames;
    if (r.first < scene.frameStart || r.last > scene.frameEnd)
      throw InputError(scene.file, "--frames " + std::to_string(r.first) + "-" +
                                       std::to_string(r.last) + " is outside the scene's frames " +
                                       std::to_string(scene.frameStart) + "-" +
                                       std::to_string(scene.frameEnd));
    plan.renderFirst = r.first;
    plan.lastFrame = r.last;
  }
  if (options.checkpointEvery < 0)
    throw InputError("--checkpoint-every", "must be a number of frames >= 1");
  plan.fps = scene.fps;
  plan.substeps = scene.substeps;
  plan.seed = options.seed.value_or(scene.seed);
  plan.crumpling = scene.model.type == io::ModelSpec::Type::Hybrid;
  plan.tearing = scene.tearEnabled;
  plan.sound = scene.soundEnabled;
  plan.render = options.render && scene.output.frames;
  if (plan.render) plan.framesDir = (fs::path(plan.outDir) / "frames").string();
  plan.debugStructure = options.debugStructure;
  plan.rendering = options.rendering;
  plan.checkpointEvery = options.checkpointEvery;
  plan.resume = options.resume;
  plan.frameBudget = scene.frameBudget;
  plan.log = options.log;
  plan.interactive = options.interactive;

  model::ModelContext& m = plan.model;
  m.material = scene.paper.material;
  m.sim = scene.sim;
  m.sim.recoverFailedSteps = true;  // before a shot stops on a failed step (docs/STABILITY.md)
  m.fps = scene.fps;
  m.substeps = scene.substeps;
  m.seed = plan.seed;
  // The gusts are drawn from the shot's seed (--seed overrides the scene's).
  if (m.sim.air) m.sim.air->gusts.seed = plan.seed;
  m.tearing = scene.tearing;
  m.projectionProbe = options.projectionProbe;
  plan.soundEvents = scene.soundEvents;
  return plan;
}

}  // namespace crumple::pipeline
