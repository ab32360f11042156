// The shot runner's frame record stage: the frame as the cache keeps it (the
// sheet, its structure, the handles, the camera and the frame's blocks),
// what it touches, its sound events, then the cache, the frame's measures
// and its rendering.
#include <algorithm>

#include "crumple/cache/pcache_contacts.hpp"
#include "crumple/cache/pcache_developable.hpp"
#include "crumple/cache/pcache_sound.hpp"
#include "crumple/core/error.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/sound.hpp"
#include "crumple/render/view.hpp"
#include "shot_detail.hpp"
#include "shot_runner.hpp"

namespace crumple::pipeline {

cache::CameraRecord detail::cameraAt(const io::SceneSpec& scene,
                                     const io::AnimationScene* animation, double t) {
  cache::CameraRecord rec;
  if (!scene.camera.node.empty() && animation != nullptr) {
    const auto cam = animation->camera(scene.camera.node, t);
    if (!cam)
      throw InputError(scene.file, "[camera] node '" + scene.camera.node + "' has no camera in " +
                                       animation->file());
    rec.position = cam->position;
    rec.rotation = cam->rotation;
    rec.yfov = cam->yfov > 0.0 && !scene.camera.fovExplicit ? cam->yfov : scene.camera.yfov;
    return rec;
  }
  const auto c = render::Camera::lookAt(scene.camera.position, scene.camera.lookAt, scene.camera.up,
                                        scene.camera.yfov, scene.camera.width, scene.camera.height);
  rec.position = c.position;
  rec.rotation = c.rotation;
  rec.yfov = c.yfov;
  return rec;
}

void ShotRunner::recordFrame(int frame) {
  record_.frame = frame;
  record_.time = time(frame);
  recordSheet(frame);
  std::vector<cache::ContactRecord> touching;
  if (sheet_.context->contactsOn) recordContacts(frame, touching);
  if (soundEvents_) recordSoundEvents(frame, touching);
  {
    const StageTimer timer(report_.stages["cache"]);
    writer_->append(record_);
  }
  const FrameMetrics m = measureFrame(record_);
  report_.maxHandleError = std::max(report_.maxHandleError, m.handleError);
  report_.maxStrain = std::max(report_.maxStrain, m.maxStrain);
  report_.meanCMean += m.cMean;
  if (m.cMean > report_.maxCMean) report_.maxCMeanFrame = frame;
  report_.maxCMean = std::max(report_.maxCMean, m.cMean);
  report_.maxNComp = std::max(report_.maxNComp, m.nComp);
  ++report_.framesSimulated;
  if (renderer_ && frame >= plan_.renderFirst) {
    const StageTimer timer(report_.stages["render"]);
    renderer_->render(record_);
    ++report_.framesRendered;
  }
  progress_->update(frame - plan_.firstFrame + 1);
}

// The sheet (its topology changes as the crumpling model remeshes and where
// the sheet tears), its structure (paper Fig. 2), the handles, the camera
// and the frame's blocks.
void ShotRunner::recordSheet(int frame) {
  const double t = time(frame);
  const model::SheetModel& sheet = *sheet_.model;
  const mesh::SheetMesh& mesh = sheet.mesh();
  record_.triangles = mesh.triangles;
  record_.regionOfTriangle = mesh.regionOfTriangle;
  record_.regionTypes.clear();
  for (auto type : mesh.regionTypes) record_.regionTypes.push_back(static_cast<std::uint8_t>(type));
  record_.pattern = mesh.pattern;
  record_.positions = mesh.positions;
  model::SheetStructure structure = sheet.structure();
  record_.singularVertices = std::move(structure.singularVertices);
  record_.junctionVertices = std::move(structure.junctionVertices);
  record_.rulings.clear();
  for (const auto& r : structure.rulings) record_.rulings.push_back({r[0], r[1]});
  std::optional<cache::ExtensionBlock> developable;
  if (sheet.crumpling()) {
    std::vector<cache::RegionRulings> regions;
    for (const auto& r : structure.regions)
      regions.push_back({r.region, r.apex, static_cast<std::uint32_t>(r.count)});
    developable = cache::encodeRegionRulings(regions);
  }
  report_.maxTriangles = std::max(report_.maxTriangles, mesh.triangleCount());
  if (const auto counts = sheet.singularCounts()) {
    report_.singularVertices = counts->first;
    report_.interiorSingularVertices = counts->second;
  }
  const model::HandleRig& rig = *sheet_.rig;
  record_.handleVertices.clear();
  record_.handleTargets.clear();
  for (std::size_t h = 0; h < rig.handles().size(); ++h) {
    const auto& bound = rig.handles()[h];
    const bool held = !(bound.releases && t >= bound.releaseTime);
    record_.handleVertices.push_back(held ? bound.vertex : -1);
    record_.handleTargets.push_back(rig.target(h, t));
    // A node beyond the sheet's reach: the handle lags behind it.
    if (const double excess = rig.reachExcess(h, t); excess > 0.0) {
      ShotReport::BeyondReach& span = report_.beyondReach[h];
      if (span.first < 0) span.first = frame;
      span.last = frame;
      span.most = std::max(span.most, excess);
    }
  }
  record_.camera = detail::cameraAt(scene_, animation_.get(), t);
  record_.extensions.clear();
  if (auto motions = propMotionBlock(scene_, animation_.get(), t))
    record_.extensions.push_back(std::move(*motions));
  if (tearAtlasBlock_) record_.extensions.push_back(*tearAtlasBlock_);
  if (structureBlock_) record_.extensions.push_back(*structureBlock_);
  if (developable) record_.extensions.push_back(std::move(*developable));
  if (frameVelocities_) {  // motion blur: the sheet's velocities over the frame
    detail::appendMotionBlocks(scene_, animation_.get(), frame, t,
                               frameVelocities_->of(record_, 1.0 / scene_.fps),
                               record_.positions.size(), record_.extensions);
    frameVelocities_->remember(record_);
  }
  record_.tearCount =
      tearStage_ ? static_cast<std::uint32_t>(tearStage_->tearing().startKinds().size()) : 0;
}

// What the sheet touches at the end of the frame (the sound module's
// input), and how deep any free vertex went.
void ShotRunner::recordContacts(int frame, std::vector<cache::ContactRecord>& touching) {
  const auto& samples = sheet_.model->contacts();
  touching.reserve(samples.size());
  for (const auto& c : samples)
    touching.push_back({c.vertex, c.collider < 0 ? cache::kSelfContact : c.collider,
                        static_cast<float>(c.slideSpeed), static_cast<float>(c.normalForce)});
  if (!touching.empty()) record_.extensions.push_back(cache::encodeContacts(touching));
  report_.contactSamples += static_cast<long>(touching.size());
  double depth = 0.0;
  {
    const StageTimer timer(report_.stages["contact check"]);
    depth = contactDepth(sheet_.context->contacts, record_);
  }
  if (depth > report_.maxContactDepth) {
    report_.maxContactDepth = depth;
    report_.maxContactDepthFrame = frame;
  }
}

// The frame's sound events and their resonators (thesis 4.3.2), in the cache.
void ShotRunner::recordSoundEvents(int frame, const std::vector<cache::ContactRecord>& touching) {
  const StageTimer timer(report_.stages["sound events"]);
  mesh::SheetMesh surface;
  surface.pattern = record_.pattern;
  surface.positions = record_.positions;
  surface.triangles = record_.triangles;
  surface.regionOfTriangle = record_.regionOfTriangle;
  for (auto type : record_.regionTypes)
    surface.regionTypes.push_back(static_cast<mesh::RegionType>(type));
  sound::SheetFrame input;
  input.mesh = &surface;
  input.rulings = record_.rulings;
  input.developableRegions = sheet_.model->crumpling();
  for (int v : record_.handleVertices)
    if (v >= 0) input.heldVertices.push_back(v);
  for (const auto& c : touching) input.contacts.push_back({c.vertex, c.slideSpeed});
  for (const auto& a : report_.tearAdvances)
    if (a.frame == frame) input.tearAdvances.push_back({a.event.tear, a.event.from, a.event.to});
  input.time = time(frame);
  input.frameDuration = 1.0 / scene_.fps;
  std::vector<sound::SoundEvent> events;
  try {
    events = soundEvents_->detect(input);
  } catch (const std::exception& e) {
    throw NumericalError("sound events", frame, e.what());
  }
  if (events.empty()) return;
  for (const auto& e : events) ++report_.soundEvents[static_cast<std::size_t>(e.kind)];
  record_.extensions.push_back(cache::encodeSoundEvents(events));
}

}  // namespace crumple::pipeline
