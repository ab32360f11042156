#include "crumple/model/tear_stage.hpp"

#include <chrono>
#include <cstdio>
#include <utility>

#include "crumple/core/debug.hpp"
#include "crumple/core/error.hpp"
#include "crumple/tear/candidates.hpp"

namespace crumple::model {

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Developer trace (--debug tear, docs/TEARING.md): every candidate's
// Griffith test and every advance that tore but could not be cut.
void traceTests(int frame, const mesh::SheetMesh& sheet, const tear::TearFrameResult& r) {
  if (!debugOptions().tear) return;
  for (const auto& t : r.tests) {
    const Vec2& at = sheet.pattern[static_cast<std::size_t>(t.candidate.vertex)];
    std::fprintf(stderr,
                 "tear: frame %d vertex %d (%s) at [%.5f, %.5f]: E_r %.4g, E_f %.4g, theta "
                 "%.3f, direction [%.3f, %.3f]%s\n",
                 frame, t.candidate.vertex, tear::candidateKindName(t.candidate.kind), at.x(),
                 at.y(), t.propagation.energyRelease, t.fractureEnergy, t.propagation.angle,
                 t.propagation.direction.x(), t.propagation.direction.y(), t.tears ? " tears" : "");
  }
  for (const auto& why : r.skipped)
    std::fprintf(stderr, "tear: frame %d not cut: %s\n", frame, why.c_str());
}
}  // namespace

TearStage::TearStage(const SheetModel& model, std::shared_ptr<const ModelContext> context)
    : context_(std::move(context)) {
  tearing_.emplace(model.mesh(), model.tearingParams(context_->tearing), context_->seed);
}

TearFrame TearStage::run(int frame, double t, std::unique_ptr<SheetModel>& model,
                         const HandleRig& rig, const std::vector<tear::TearEvent>& earlier) {
  TearFrame out;
  // The sheet the frame ended with, and its junction vertices (candidates too).
  mesh::SheetMesh sheet = model->tearMesh();
  const std::vector<int> junctions = model->junctionVertices();
  if (model->remeshes()) {
    // The mesh was rebuilt by the frame's animation steps: its tips and lips again.
    try {
      tearing_->rebind(sheet, model->lipTolerance());
    } catch (const std::exception& e) {
      throw NumericalError("tear", frame, e.what());
    }
  }
  std::vector<char> held(sheet.vertexCount(), 0);
  std::vector<sim::Pin> holding;
  rig.pins(t, holding);
  for (const auto& pin : holding) held[static_cast<std::size_t>(pin.vertex)] = 1;
  // Forces in units of k_s h (tear::TearParams::resistance): E_r is strain-like.
  const double unit = context_->material.stretchStiffness() * tearing_->edgeLength();
  const sim::ElasticSheet& elastic = model->elastic();
  const tear::VertexForces forces = [&](int v) {
    std::vector<tear::TriangleForce> f;
    for (const auto& m : elastic.membraneForcesOn(v)) f.push_back({m.triangle, m.force / unit});
    return f;
  };
  tear::TearFrameResult r;
  try {
    r = tearing_->step(sheet, junctions, held, forces);
  } catch (const std::exception& e) {
    throw NumericalError("tear", frame, e.what());
  }
  traceTests(frame, sheet, r);
  if (r.changed()) {
    TearCut cut{frame, t, r, sheet, *tearing_, earlier};
    TearOutcome taken = model->cut(cut);
    out.events = std::move(taken.events);
    out.notes = std::move(taken.notes);
    out.geometricCuts = taken.geometricCuts;
    out.regionsFlattened = taken.regionsFlattened;
    if (taken.replacement) {
      model = std::move(taken.replacement);
      tearing_ = std::move(taken.replacementTearing);
      out.handedOver = true;
    }
  }
  // The tear textures, baked again whenever the mesh they refer to changed:
  // after a cut, and every frame the model rebuilt its mesh.
  const mesh::SheetMesh& now = model->mesh();
  if (!tearing_->segments().empty() &&
      (r.changed() || now.triangles != baked_.triangles || now.pattern != baked_.pattern)) {
    const auto bakeStart = Clock::now();
    tear::TearAtlasParams atlas;
    atlas.texelSize = tearing_->fibers().texelSize();
    atlas.lipTolerance = model->lipTolerance();
    try {
      out.atlas = tear::bakeTearAtlas(now, tearing_->segments(), atlas);
    } catch (const std::exception& e) {
      throw NumericalError("tear atlas", frame, e.what());
    }
    baked_.triangles = now.triangles;
    baked_.pattern = now.pattern;
    out.bakeMs = msSince(bakeStart);
  }
  return out;
}

void TearStage::restoreState(StateReader& in, const SheetModel& model) {
  // Made again on the mesh the model has now: after a hand-over, with the
  // elastic model's parameters.
  tearing_.emplace(model.mesh(), model.tearingParams(context_->tearing), context_->seed);
  tearing_->restoreState(in);
}

void TearStage::saveBaked(StateWriter& out) const {
  out.triangles(baked_.triangles);
  out.vec2s(baked_.pattern);
}

void TearStage::restoreBaked(StateReader& in) {
  baked_.triangles = in.triangles();
  baked_.pattern = in.vec2s();
}

}  // namespace crumple::model
