#pragma once
// The shot runner (docs/ARCHITECTURE.md "The shot runner"): a ShotPlan's
// frame loop as stages - step, tear, frame record (contacts, sound events,
// cache, measures, render), checkpoint - and the summary. It holds a
// model::SheetModel and never asks which one. Internal to the pipeline.
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "checkpoint.hpp"
#include "cost_guard.hpp"
#include "crumple/cache/pcache.hpp"
#include "crumple/core/progress.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/model/sheet_setup.hpp"
#include "crumple/model/tear_stage.hpp"
#include "crumple/pipeline/contacts.hpp"
#include "crumple/pipeline/output_lock.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/sound/events.hpp"
#include "frame_motion.hpp"
#include "frame_output.hpp"
#include "shot_inputs.hpp"
#include "shot_plan.hpp"

namespace crumple::pipeline {

// Adds the wall time from its construction to its destruction to a stage's
// cost, as one frame of it.
class StageTimer {
 public:
  explicit StageTimer(StageCost& cost) : cost_(cost), start_(Clock::now()) {}
  ~StageTimer() {
    cost_.totalMs += ms();
    cost_.frames += 1;
  }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;
  double ms() const {
    return std::chrono::duration<double, std::milli>(Clock::now() - start_).count();
  }

 private:
  using Clock = std::chrono::steady_clock;
  StageCost& cost_;
  Clock::time_point start_;
};

class ShotRunner {
 public:
  // Sets the shot up: everything that can be wrong with the input is
  // checked here, before any output is written (InputError).
  ShotRunner(const io::SceneSpec& scene, const ShotOptions& options);
  ~ShotRunner();
  ShotRunner(const ShotRunner&) = delete;
  ShotRunner& operator=(const ShotRunner&) = delete;

  // Runs the frames and writes the summary; see runShot.
  ShotReport run();

 private:
  // Set-up, once.
  void openOutputs();
  void openCache();
  cache::CacheHeader cacheHeader() const;
  // The frame's stages.
  void step(int frame);
  void tear(int frame);
  void recordFrame(int frame);
  void recordSheet(int frame);
  void recordContacts(int frame, std::vector<cache::ContactRecord>& touching);
  void recordSoundEvents(int frame, const std::vector<cache::ContactRecord>& touching);
  void checkpoint(int frame);
  // Checkpoint and resume: the state's sections, in the one order both
  // visit (docs/CHECKPOINT.md).
  struct StateSection {
    std::function<void(StateWriter&)> save;
    std::function<void(StateReader&)> restore;
  };
  std::vector<StateSection> stateSections();
  void restore();
  // The end: the summary's warnings, the summary.
  void finish();
  [[noreturn]] void fail(const NumericalError& caught, int frame, double frameSeconds);
  void addStabilityWarnings();
  void writeSummary() const;
  std::string costCause(int frame) const;
  double time(int frame) const { return scene_.frameTime(frame); }

  const io::SceneSpec& scene_;
  const ShotPlan plan_;
  std::unique_ptr<io::AnimationScene> animation_;
  std::vector<ShotInput> inputs_;  // what a checkpoint records of the files read
  std::unique_ptr<SceneColliders> colliders_;
  model::ShotSheet sheet_;  // the models' context, the handle rig and the model
  std::optional<model::TearStage> tearStage_;
  std::optional<sound::EventDetector> soundEvents_;
  std::vector<cache::ExtensionBlock> lookBlocks_;  // texture, props (the cache header)
  std::optional<OutputLock> outputLock_, framesLock_;
  std::unique_ptr<detail::FrameRenderer> renderer_;
  std::optional<Checkpoint> resumed_;
  std::unique_ptr<cache::CacheWriter> writer_;
  cache::FrameRecord record_;
  // The baked tear textures (TEAR block) of the current mesh, and the
  // crumpling model's structure changes of the frame being recorded.
  std::optional<cache::ExtensionBlock> tearAtlasBlock_, structureBlock_;
  // Motion blur ([camera] shutter): the sheet's velocities over each frame.
  std::optional<detail::FrameVelocities> frameVelocities_;
  std::unique_ptr<Progress> progress_;
  CostGuard guard_;
  ShotReport report_;
};

}  // namespace crumple::pipeline
