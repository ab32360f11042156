#include "shot_runner.hpp"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "crumple/cache/pcache_contacts.hpp"
#include "crumple/cache/pcache_sound.hpp"
#include "crumple/cache/pcache_structure.hpp"
#include "crumple/cache/pcache_tear.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/machine_speed.hpp"
#include "crumple/core/work_budget.hpp"
#include "shot_detail.hpp"

namespace crumple::pipeline {

namespace {

// The cost guard's clock: the process's CPU time (core/work_budget.hpp).
double cpuSecondsSince(double start) { return processCpuSeconds() - start; }

// A handle further than this from its node lags (strain_limit.hpp).
constexpr double kLagReported = 1e-6;

// Adds one frame's lag of each handle (strain limit: (vertex, lag)) to the
// per-handle record, one entry per handle of the rig in its order.
void noteHandleLags(const model::HandleRig& rig, const std::vector<std::pair<int, double>>& lags,
                    int frame, std::vector<ShotReport::HandleLag>& record) {
  const auto& handles = rig.handles();
  if (record.size() != handles.size()) {
    record.assign(handles.size(), {});
    for (std::size_t h = 0; h < handles.size(); ++h) record[h].name = handles[h].name;
  }
  for (std::size_t h = 0; h < handles.size(); ++h)
    for (const auto& [vertex, lag] : lags) {
      if (vertex != handles[h].vertex || lag <= kLagReported) continue;
      ShotReport::HandleLag& r = record[h];
      if (r.frames++ == 0) r.firstFrame = frame;
      if (lag > r.max) {
        r.max = lag;
        r.maxFrame = frame;
      }
    }
}

// The frames a recovery happened in (the warnings' record).
void noteSpan(int happened, int frame, ShotReport::FrameSpan& span) {
  if (happened <= 0) return;
  if (span.first < 0) span.first = frame;
  span.last = frame;
}

}  // namespace

ShotRunner::ShotRunner(const io::SceneSpec& scene, const ShotOptions& options)
    : scene_(scene),
      plan_(planShot(scene, options)),
      guard_(plan_.frameBudget, plan_.frameBudget ? 1.0 : machineSlowness()) {
  report_.outDir = plan_.outDir;
  if (!scene.animationFile.empty()) {
    animation_ =
        std::make_unique<io::AnimationScene>(io::AnimationScene::load(scene.animationFile));
    io::checkAnimationNodes(scene, *animation_);
  }
  // What a checkpoint records of the files read (docs/CHECKPOINT.md), hashed as they were read.
  if (plan_.checkpointsInputs()) inputs_ = shotInputs(scene);
  // Contacts: none of it runs without colliders and with [contact] self = false.
  colliders_ = std::make_unique<SceneColliders>(scene, animation_.get());
  model::ModelContext context = plan_.model;
  context.contacts = contactOptionsOf(scene, *colliders_);
  context.contactsOn = !colliders_->empty() || context.contacts.self != sim::SelfContactMode::Off;
  report_.contactsOn = context.contactsOn;
  report_.airOn = context.sim.air.has_value();
  report_.selfContactMode = context.contacts.self == sim::SelfContactMode::On    ? "on"
                            : context.contacts.self == sim::SelfContactMode::Off ? "off"
                                                                                 : "auto";
  sheet_ = model::setUpSheet(scene, animation_.get(), std::move(context), time(plan_.firstFrame));
  for (int f = plan_.firstFrame; f <= plan_.lastFrame; ++f)
    (void)detail::cameraAt(scene, animation_.get(), time(f));
  // The look travels in the cache (texture, mesh props), read and checked now.
  lookBlocks_ = lookHeaderBlocks(scene, animation_.get());
  if (auto shutter = detail::shutterBlock(scene)) {
    lookBlocks_.push_back(std::move(*shutter));
    frameVelocities_.emplace();
  }
  // Tearing and sound events run only when the scene asks for them.
  if (plan_.tearing) {
    tearStage_.emplace(*sheet_.model, sheet_.context);
    report_.tearingOn = true;
  }
  if (plan_.sound) {
    soundEvents_.emplace(plan_.soundEvents);
    report_.soundOn = true;
  }
  openOutputs();
  openCache();
}

ShotRunner::~ShotRunner() = default;

void ShotRunner::openOutputs() {
  detail::prepareOutputDir(plan_.outDir, "output");
  outputLock_.emplace(plan_.outDir);  // one writer per folder, until the shot is done
  report_.cachePath = plan_.cachePath;
  if (animation_)
    for (const auto& w : animation_->warnings())
      report_.warnings.push_back(animation_->file() + ": " + w);
  const auto& bindWarnings = sheet_.rig->bindWarnings();
  report_.warnings.insert(report_.warnings.end(), bindWarnings.begin(), bindWarnings.end());
  // Said now as well as in the summary: they often explain a failure that follows.
  if (plan_.log != nullptr)
    for (const auto& w : report_.warnings) std::fprintf(plan_.log, "warning: %s\n", w.c_str());
  report_.summaryPath = plan_.summaryPath;
  if (!plan_.render) return;
  report_.framesDir = plan_.framesDir;
  detail::prepareOutputDir(plan_.framesDir, "frames");
  framesLock_.emplace(plan_.framesDir);
  renderer_ = std::make_unique<detail::FrameRenderer>(
      scene_, lookBlocks_, plan_.framesDir, plan_.debugStructure, plan_.rendering, plan_.seed);
  report_.renderBackend = backendName(plan_.rendering.backend);
}

cache::CacheHeader ShotRunner::cacheHeader() const {
  cache::CacheHeader header;
  header.fps = scene_.fps;
  header.frameStart = plan_.firstFrame;
  header.frameEnd = plan_.lastFrame;
  header.substeps = scene_.substeps;
  header.seed = plan_.seed;
  header.sceneName = scene_.name;
  header.sceneFile = scene_.file;
  header.sceneText = scene_.sourceText;
  const bool rectangle = scene_.sheet.kind == io::SheetSpec::Kind::Rectangle;
  header.sheetWidth = rectangle ? scene_.sheet.width : 0.0;
  header.sheetHeight = rectangle ? scene_.sheet.height : 0.0;
  header.paperName = scene_.paper.material.name;
  header.paperThickness = scene_.paper.material.thickness;
  for (const auto& h : sheet_.rig->handles()) header.handleNames.push_back(h.name);
  header.extensions = lookBlocks_;
  if (sheet_.context->contactsOn)
    header.extensions.push_back(cache::encodeColliders(colliders_->info()));
  if (soundEvents_) {
    const sound::EventParams& p = soundEvents_->params();
    header.extensions.push_back(cache::encodeSoundSetup(
        {p.gridSpacing, p.curvatureThreshold, p.maxDihedral, p.freeBorderRadius, p.minSlideSpeed,
         p.minFreeBorder, p.maxTearGap}));
  }
  return header;
}

void ShotRunner::openCache() {
  const cache::CacheHeader header = cacheHeader();
  // Resume: the checkpoint says which frame the state is at and how many
  // cached frames go with it; the cache keeps those and goes on.
  if (plan_.resume)
    resumed_ = readCheckpoint(plan_.checkpointPath, scene_, inputs_, plan_.seed, plan_.lastFrame);
  writer_ = resumed_ ? cache::CacheWriter::resume(plan_.cachePath, header, resumed_->cachedFrames)
                     : std::make_unique<cache::CacheWriter>(plan_.cachePath, header);
  const mesh::SheetMesh& sheet = sheet_.model->mesh();
  report_.vertices = sheet.vertexCount();
  report_.triangles = sheet.triangleCount();
  progress_ = std::make_unique<Progress>(plan_.render ? "crumple run" : "crumple simulate",
                                         plan_.lastFrame - plan_.firstFrame + 1, plan_.log,
                                         plan_.interactive);
}

ShotReport ShotRunner::run() {
  int firstFrame = plan_.firstFrame + 1;
  if (resumed_) {
    restore();
    firstFrame = resumed_->frame + 1;
  }
  int frame = firstFrame;
  double frameStart = processCpuSeconds();
  try {
    if (!resumed_) recordFrame(plan_.firstFrame);
    for (; frame <= plan_.lastFrame; ++frame) {
      frameStart = processCpuSeconds();
      const long halvingsBefore = report_.halvings;
      const ScopedWorkBudget frameBudget(guard_.budget());
      step(frame);
      if (tearStage_) tear(frame);
      recordFrame(frame);
      if (plan_.checkpointAfter(frame)) checkpoint(frame);
      guard_.frameDone(frame, cpuSecondsSince(frameStart), report_.halvings - halvingsBefore,
                       costCause(frame));
      if (report_.tearHandoverFrame == frame) guard_.newRegime();
    }
  } catch (const NumericalError& caught) {
    fail(caught, std::min(frame, plan_.lastFrame), cpuSecondsSince(frameStart));
  }
  finish();
  return report_;
}

// The model's frame: its substeps (the crumpling model's animation steps,
// paper Fig. 16) and what they cost.
void ShotRunner::step(int frame) {
  const model::HandleRig& rig = *sheet_.rig;
  const sim::PinFunction pins = [&rig](double t, std::vector<sim::Pin>& out) { rig.pins(t, out); };
  const model::FrameStats s = sheet_.model->advance(frame, pins);
  ShotReport& r = report_;
  r.newtonIterations += s.newtonIterations;
  r.halvings += s.halvings;
  noteSpan(s.newtonRetried, frame, r.newtonRetried);
  noteSpan(s.selfContactDropped, frame, r.selfContactDropped);
  r.elasticRetries += s.elasticRetries;
  r.strainLimitRuns += s.strainLimitRuns;
  r.strainLimitCarried += s.strainLimitCarried;
  if (s.elasticHeldStill > 0) {
    r.elasticHeldStill += s.elasticHeldStill;
    if (r.elasticHeldFirst < 0) r.elasticHeldFirst = frame;
    r.elasticHeldLast = frame;
  }
  if (s.lag > kLagReported) ++r.lagFrames;
  if (s.lag > r.maxHandleLag) {
    r.maxHandleLag = s.lag;
    r.maxHandleLagFrame = frame;
    r.maxHandleLagVertex = s.lagVertex;
  }
  if (s.handleLags) noteHandleLags(rig, *s.handleLags, frame, r.handleLags);
  r.substeps += s.substeps;
  r.contactMs += s.contactMs;
  r.selfContactMs += s.selfContactMs;
  r.airMs += s.airMs;
  r.selfContactSteps += s.selfContactSteps;
  for (const auto& [name, ms] : s.stageMs) {
    r.stages[name].totalMs += ms;
    r.stages[name].frames += 1;
  }
  structureBlock_.reset();
  if (s.structure) structureBlock_ = cache::encodeStructureChanges(*s.structure);
}

// The tearing stage (model::TearStage), and the tear textures in the cache.
void ShotRunner::tear(int frame) {
  const StageTimer timer(report_.stages["tear"]);  // the atlas's baking included
  std::vector<tear::TearEvent> earlier;
  earlier.reserve(report_.tearAdvances.size());
  for (const auto& a : report_.tearAdvances) earlier.push_back(a.event);
  model::TearFrame t = tearStage_->run(frame, time(frame), sheet_.model, *sheet_.rig, earlier);
  report_.tearRegionsFlattened += t.regionsFlattened;
  report_.tearGeometricCuts += t.geometricCuts;
  for (auto& note : t.notes) report_.notes.push_back(std::move(note));
  if (t.handedOver) {
    report_.tearHandoverFrame = frame;
    report_.vertices = sheet_.model->mesh().vertexCount();
  }
  for (const auto& e : t.events) {
    report_.tearAdvances.push_back({frame, e});
    if (report_.firstTearFrame < 0) report_.firstTearFrame = frame;
  }
  if (t.atlas) {
    try {
      tearAtlasBlock_ = cache::encodeTearAtlas(*t.atlas);
    } catch (const std::exception& e) {
      throw NumericalError("tear atlas", frame, e.what());
    }
    report_.tearBakeMs += t.bakeMs;
  }
  report_.tearMs += timer.ms();
}

std::vector<ShotRunner::StateSection> ShotRunner::stateSections() {
  return {
      {[this](StateWriter& w) { saveReport(w, report_); },
       [this](StateReader& in) { restoreReport(in, report_, sheet_.rig->handles().size()); }},
      // The model: the crumpling model's layers, or the elastic model on its
      // (possibly torn) mesh.
      {[this](StateWriter& w) { model::saveModel(w, *sheet_.model); },
       [this](StateReader& in) {
         model::restoreModel(in, sheet_.model, sheet_.context, *sheet_.rig);
       }},
      {[this](StateWriter& w) { sheet_.rig->saveState(w); },
       [this](StateReader& in) { sheet_.rig->restoreState(in); }},
      {[this](StateWriter& w) {
         w.boolean(tearStage_.has_value());
         if (!tearStage_) return;
         tearStage_->saveState(w);
         saveTearingReport(w, report_);
         w.boolean(tearAtlasBlock_.has_value());
         if (tearAtlasBlock_) saveBlock(w, *tearAtlasBlock_);
         tearStage_->saveBaked(w);
       },
       [this](StateReader& in) {
         if (in.boolean() != tearStage_.has_value())
           throw InputError(plan_.checkpointPath, "was written with a different [tear] setting");
         if (!tearStage_) return;
         tearStage_->restoreState(in, *sheet_.model);
         restoreTearingReport(in, report_);
         if (in.boolean()) tearAtlasBlock_ = restoreBlock(in);
         tearStage_->restoreBaked(in);
       }},
      {[this](StateWriter& w) {
         w.boolean(soundEvents_.has_value());
         if (soundEvents_) soundEvents_->saveState(w);
       },
       [this](StateReader& in) {
         if (in.boolean() != soundEvents_.has_value())
           throw InputError(plan_.checkpointPath, "was written with a different [sound] setting");
         if (soundEvents_) soundEvents_->restoreState(in);
       }},
  };
}

// The whole state after frame `frame`, written atomically.
void ShotRunner::checkpoint(int frame) {
  const StageTimer timer(report_.stages["checkpoint"]);
  StateWriter w;
  writeCheckpointHead(w, scene_, inputs_, plan_.seed, plan_.lastFrame, frame,
                      writer_->framesWritten());
  for (const auto& section : stateSections()) section.save(w);
  writeCheckpointFile(plan_.checkpointPath, w);
}

void ShotRunner::restore() {
  StateReader& in = *resumed_->state;
  for (const auto& section : stateSections()) section.restore(in);
  if (!in.atEnd()) in.fail("trailing bytes");
  // Motion blur: the next frame's velocities start from the last cached one.
  if (frameVelocities_ && resumed_->cachedFrames > 0)
    frameVelocities_->remember(
        cache::CacheReader(plan_.cachePath).readFrame(resumed_->cachedFrames - 1));
  if (plan_.log != nullptr)
    std::fprintf(plan_.log, "resuming after frame %d (%s)\n", resumed_->frame,
                 plan_.checkpointPath.c_str());
}

std::string ShotRunner::costCause(int frame) const {
  return likelyCostCause(*sheet_.rig, record_.pattern, time(frame), time(frame - 1));
}

// A frame that ran out of its budget in any stage is the cost guard's stop;
// the cache stays valid up to the last good frame.
void ShotRunner::fail(const NumericalError& caught, int frame, double frameSeconds) {
  const double budget = guard_.budget();
  const bool overBudget = budget > 0.0 && frameSeconds >= budget && caught.stage() != "cost guard";
  const NumericalError e =
      overBudget ? guard_.budgetError(frame, caught.stage(), costCause(frame)) : caught;
  progress_->finish();
  report_.error = e.what();
  report_.hybrid = plan_.crumpling;
  if (report_.framesSimulated > 0) report_.meanCMean /= report_.framesSimulated;
  writer_->close();
  addStabilityWarnings();
  writeSummary();
  throw e;
}

}  // namespace crumple::pipeline
