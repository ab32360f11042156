#include "elastic_model.hpp"

#include <chrono>
#include <map>
#include <utility>

#include "crumple/core/error.hpp"

namespace crumple::model {

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}
}  // namespace

ElasticModel::ElasticModel(mesh::SheetMesh mesh, std::shared_ptr<const ModelContext> context,
                           HandleRig& rig, std::vector<int> singular)
    : context_(std::move(context)),
      rig_(rig),
      mesh_(std::move(mesh)),
      sheet_(mesh_, context_->material, context_->sim),
      singular_(std::move(singular)) {
  attach();
}

void ElasticModel::attach() {
  sheet_.setContacts(context_->contacts);
  // Fingers that hold patches ([[handles]] patch_radius) grip as firmly as
  // the sheet itself.
  sheet_.setGrips([&rig = rig_, k = sheet_.inPlaneStiffness()](
                      double t, std::vector<sim::Grip>& out) { rig.grips(t, k, out); });
}

FrameStats ElasticModel::advance(int frame, const sim::PinFunction& pins) {
  FrameStats out;
  const int substeps = context_->substeps;
  const double dt = 1.0 / (context_->fps * substeps);
  const auto start = Clock::now();
  for (int s = 0; s < substeps; ++s) {
    // Substep s of frame f starts at ((f - 1) * substeps + s) * dt.
    const double t = static_cast<double>((frame - 1) * substeps + s) * dt;
    try {
      const sim::StepStats stats = sheet_.advance(t, dt, pins);
      out.newtonIterations += stats.newtonIterations;
      out.halvings += stats.halvings;
      out.contactMs += stats.contactMs;
      out.selfContactMs += stats.selfContactMs;
      out.airMs += stats.airMs;
      out.selfContactSteps += stats.selfContactSteps;
      out.newtonRetried += stats.newtonRetried;
      out.selfContactDropped += stats.selfContactDropped;
      ++out.substeps;
    } catch (const NumericalError& e) {
      throw NumericalError(e.stage(), frame, e.problem());
    }
  }
  out.stageMs.emplace_back("elastic", msSince(start));
  carried_.reset();
  mesh_.positions = sheet_.positions();
  return out;
}

const std::vector<sim::ContactSample>& ElasticModel::contacts() const {
  return carried_ ? *carried_ : sheet_.contacts();
}

// The elastic model on the cut mesh (thesis 3.3.3): velocities carried over
// the cut, each uncut hinge's rest angle and stiffness factor kept.
TearOutcome ElasticModel::cut(TearCut& cut) {
  const tear::TearFrameResult& r = cut.result;
  TearOutcome out;
  out.events = r.events;
  const std::vector<Vec3> velocities =
      tear::blendValues(sheet_.velocities(), r.blends, r.relocated);
  std::map<std::pair<int, int>, std::pair<double, double>> hingeState;
  for (std::size_t h = 0; h < sheet_.hinges().size(); ++h)
    hingeState[{sheet_.hinges()[h].v[0], sheet_.hinges()[h].v[1]}] = {
        sheet_.hingeRestAngle(h), sheet_.hingeStiffnessFactor(h)};
  std::vector<sim::ContactSample> contacts = sheet_.contacts();
  sim::ElasticSheet next(cut.sheet, context_->material, context_->sim);
  next.setVelocities(velocities);
  rig_.rebindPatches(cut.sheet, cut.t);
  sheet_ = std::move(next);
  attach();
  for (std::size_t h = 0; h < sheet_.hinges().size(); ++h) {
    const auto it = hingeState.find({sheet_.hinges()[h].v[0], sheet_.hinges()[h].v[1]});
    if (it == hingeState.end()) continue;
    sheet_.setHingeRestAngle(h, it->second.first);
    sheet_.setHingeStiffnessFactor(h, it->second.second);
  }
  mesh_ = cut.sheet;
  mesh_.positions = sheet_.positions();
  carried_ = std::move(contacts);
  return out;
}

void ElasticModel::settle(double t, int steps, double dt, const std::vector<Vec3>& velocities) {
  const sim::PinFunction pins = [&rig = rig_](double at, std::vector<sim::Pin>& out) {
    rig.pins(at, out);
  };
  for (int k = 0; k < steps; ++k) (void)sheet_.advance(t - dt, dt, pins);
  sheet_.setVelocities(velocities);
  mesh_.positions = sheet_.positions();
}

void ElasticModel::saveState(StateWriter& out) const {
  mesh::saveSheetMesh(out, mesh_);
  sheet_.saveState(out);
  out.i32s(singular_);
}

void ElasticModel::restoreState(StateReader& in) {
  mesh_ = mesh::restoreSheetMesh(in);
  sheet_ = sim::ElasticSheet(mesh_, context_->material, context_->sim);
  attach();
  restoreOnMesh(in);
}

std::unique_ptr<ElasticModel> ElasticModel::restored(StateReader& in,
                                                     std::shared_ptr<const ModelContext> context,
                                                     HandleRig& rig) {
  auto model = std::make_unique<ElasticModel>(mesh::restoreSheetMesh(in), std::move(context), rig);
  model->restoreOnMesh(in);
  return model;
}

void ElasticModel::restoreOnMesh(StateReader& in) {
  sheet_.restoreState(in);
  mesh_.positions = sheet_.positions();
  singular_ = in.i32s();
  carried_.reset();
}

}  // namespace crumple::model
