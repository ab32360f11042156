#pragma once
// A shot's plan (docs/ARCHITECTURE.md "The shot runner"): built once from
// the scene and the command line before anything runs: where it writes,
// which frames, which stages run and with which parameters. Internal to the
// pipeline.
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

#include "crumple/io/scene.hpp"
#include "crumple/model/sheet_model.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/sound/params.hpp"

namespace crumple::pipeline {

struct ShotPlan {
  // Where: DIR and the files in it (docs/ARCHITECTURE.md "The command line").
  std::string outDir, cachePath, summaryPath, checkpointPath;
  std::string framesDir;  // empty: nothing is rendered
  // Which frames: simulated from firstFrame to lastFrame, rendered from
  // renderFirst to lastFrame.
  int firstFrame = 0, lastFrame = 0, renderFirst = 0;
  double fps = 24.0;
  int substeps = 1;
  std::uint64_t seed = 0;
  // Which stages run: the crumpling model (else the elastic one), tearing,
  // sound events, rendering (with these settings), checkpoints.
  bool crumpling = false;
  bool tearing = false;
  bool sound = false;
  bool render = false;
  bool debugStructure = false;
  RenderSettings rendering;
  int checkpointEvery = 0;  // frames, 0: never
  bool resume = false;
  std::optional<double> frameBudget;  // s per frame ([scene] frame_budget_s; CostGuard)
  // With which parameters: the models' (their contacts are the runner's,
  // which owns the colliders) and the sound events'.
  model::ModelContext model;
  sound::EventParams soundEvents;
  // Progress and notes.
  std::FILE* log = stderr;
  int interactive = -1;
  bool checkpointsInputs() const { return checkpointEvery > 0 || resume; }
  bool checkpointAfter(int frame) const {
    return checkpointEvery > 0 && (frame - firstFrame) % checkpointEvery == 0;
  }
};

// Checks the options against the scene (InputError) and plans the shot.
ShotPlan planShot(const io::SceneSpec& scene, const ShotOptions& options);

}  // namespace crumple::pipeline
