#include "crumpling_model.hpp"

#include <algorithm>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <utility>

#include "crumple/core/error.hpp"
#include "crumple/paper/tear_remesh.hpp"
#include "elastic_model.hpp"

namespace crumple::model {

namespace {

// A torn crumpling-model sheet handed over to the elastic model settles in
// these tiny steps (s) before it moves on.
constexpr int kRelaxSteps = 4;
constexpr double kRelaxDt = 1e-4;
// The crumpling model's tears are slits of this width in S_G's pattern
// (paper::GeometricCutOptions::kerf); their lips are within a few kerfs of
// the tear's cut (the copies of a tip where it turned, a tear's first
// copies on the outline).
constexpr double kTearKerf = 1e-5;
constexpr double kLipTolerance = 12.0 * kTearKerf;
// The crumpling model's tears start at least this far (rad) from the
// outline's direction (tear::TearingParams::minStartAngle): cylinder-fold
// with [tear] started one at 17 degrees along its bottom edge, 0.66 mm in,
// and S_P's sliver triangles there failed the elastic step four frames on.
constexpr double kMinStartAngle = 25.0 * std::numbers::pi / 180.0;

// The STRC block's counts from a frame's animation steps.
StructureChanges structureChangesOf(const paper::HybridStepStats& s) {
  const auto count = [](int n) { return static_cast<std::uint32_t>(std::max(0, n)); };
  const paper::GeometricStepStats& g = s.geometric;
  StructureChanges c;
  c.singularFromFlat = count(g.singularInserted - g.singularInCurved);
  c.singularFromRuling = count(g.singularInCurved);
  c.curvedFromCompression = count(g.curvedCreated - g.curvedBent);
  c.curvedFromFolding = count(g.curvedBent);
  c.creases = count(g.creases);
  c.flatSplits = count(g.flatSplits);
  c.curvedFlattened = count(g.curvedFlattened);
  c.undoneByStretch = count(s.undoneByBound);
  return c;
}

// The crumpling model's sheet at the elastic model's resolution (a torn
// sheet handed over, docs/TEARING.md): the scene's mesh `fine`, the vertex
// nearest each handle's point moved onto it, every vertex placed and given
// a velocity by interpolating S_P (positions x, velocities v) in the pattern.
struct ResampledSheet {
  mesh::SheetMesh mesh;
  std::vector<Vec3> velocities;
  std::vector<int> handleVertices;
};
ResampledSheet resampleSheet(const mesh::SheetMesh& fine, const mesh::SheetMesh& sp,
                             const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                             const std::vector<int>& spHandles) {
  ResampledSheet out;
  out.mesh = fine;
  for (int h : spHandles) {
    const Vec2 p = sp.pattern[static_cast<std::size_t>(h)];
    const int n = mesh::nearestPatternVertex(out.mesh, p);
    if (std::find(out.handleVertices.begin(), out.handleVertices.end(), n) !=
        out.handleVertices.end())
      throw std::invalid_argument(
          "two handles fall on one vertex of the elastic mesh (a finer [sheet] max_edge "
          "separates them)");
    out.mesh.pattern[static_cast<std::size_t>(n)] = p;
    out.handleVertices.push_back(n);
  }
  const auto cross = [](const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); };
  out.velocities.resize(out.mesh.vertexCount());
  for (std::size_t i = 0; i < out.mesh.vertexCount(); ++i) {
    const Vec2 q = out.mesh.pattern[i];
    double bestMin = -std::numeric_limits<double>::infinity();
    Vec3 bx = Vec3::Zero(), bv = Vec3::Zero();
    for (const auto& t : sp.triangles) {
      const Vec2 a = sp.pattern[static_cast<std::size_t>(t[0])];
      const Vec2 b = sp.pattern[static_cast<std::size_t>(t[1])];
      const Vec2 c = sp.pattern[static_cast<std::size_t>(t[2])];
      const double area = cross(b - a, c - a);
      if (!(std::abs(area) > 1e-14)) continue;  // a sliver cannot place anything
      const double wb = cross(q - a, c - a) / area, wc = cross(b - a, q - a) / area;
      const double wa = 1.0 - wb - wc;
      const double least = std::min({wa, wb, wc});
      if (!(least > bestMin)) continue;
      bestMin = least;
      bx = wa * x[static_cast<std::size_t>(t[0])] + wb * x[static_cast<std::size_t>(t[1])] +
           wc * x[static_cast<std::size_t>(t[2])];
      bv = wa * v[static_cast<std::size_t>(t[0])] + wb * v[static_cast<std::size_t>(t[1])] +
           wc * v[static_cast<std::size_t>(t[2])];
    }
    out.mesh.positions[i] = bx;
    out.velocities[i] = bv;
  }
  return out;
}

}  // namespace

CrumplingModel::CrumplingModel(std::unique_ptr<paper::HybridSheet> sheet,
                               std::shared_ptr<const ModelContext> context)
    : sheet_(std::move(sheet)), context_(std::move(context)) {}

void CrumplingModel::bind(HandleRig& rig, double t0) {
  rig_ = &rig;
  std::vector<sim::Pin> start;
  rig.pins(t0, start);
  sheet_->placeVertices(start);
  sheet_->setTime(t0);
  // A finger's grip is as firm as the sheet itself (the coarse FEM's).
  sheet_->setGrips([&rig, k = sheet_->elastic().inPlaneStiffness()](
                       double t, std::vector<sim::Grip>& out) { rig.grips(t, k, out); });
  sheet_->setRebuildCallback(
      [&rig](const mesh::SheetMesh& sp, double t) { rig.rebindTangents(sp, t); });
  if (context_->projectionProbe) sheet_->setProjectionCallback(context_->projectionProbe);
  sheet_->setContacts(context_->contacts);
}

// The frame's substeps are the paper's animation steps (Fig. 16): each an
// elastic step, the geometric step, cones, S_P rebuild and isometry.
FrameStats CrumplingModel::advance(int frame, const sim::PinFunction& pins) {
  singularAtStart_ = singularVertices();
  const double t = static_cast<double>(frame - 1) / context_->fps;
  const paper::HybridStepStats stats =
      sheet_->advance(t, 1.0 / context_->fps, context_->substeps, pins, frame);
  FrameStats out;
  out.newtonIterations = stats.elastic.newtonIterations;
  out.halvings = stats.elastic.halvings;
  out.substeps = context_->substeps;
  out.newtonRetried = stats.elastic.newtonRetried;
  out.selfContactDropped = stats.elastic.selfContactDropped;
  out.contactMs = stats.elastic.contactMs + stats.ms.contacts;
  out.selfContactMs = stats.elastic.selfContactMs + stats.ms.selfContacts;
  out.airMs = stats.elastic.airMs;
  out.selfContactSteps = stats.elastic.selfContactSteps;
  out.stageMs = {{"elastic", stats.ms.elastic},   {"geometric", stats.ms.geometric},
                 {"cones", stats.ms.cones},       {"rebuild", stats.ms.rebuild},
                 {"isometry", stats.ms.isometry}, {"strain limit", stats.ms.strainLimit}};
  if (context_->contactsOn)
    out.stageMs.emplace_back("contacts", stats.ms.contacts + stats.ms.selfContacts);
  out.elasticRetries = stats.elasticRetries;
  out.strainLimitRuns = stats.strainLimitRuns;
  out.strainLimitCarried = stats.strainLimitCarried;
  out.elasticHeldStill = stats.elasticHeldStill;
  out.lag = stats.strainLimit.lag;
  out.lagVertex = stats.strainLimit.lagVertex;
  out.handleLags = stats.strainLimit.handleLags;
  out.structure = structureChangesOf(stats);
  return out;
}

std::vector<int> CrumplingModel::singularVertices() const {
  const paper::GeometricMesh& sg = sheet_->geometric();
  std::vector<int> out;
  for (std::size_t i = 0; i < sg.vertices.size(); ++i)
    if (sg.vertices[i].singular) out.push_back(static_cast<int>(i));
  return out;
}

// S_P's structure is S_G's (paper Fig. 2), whose vertices are S_P's first.
SheetStructure CrumplingModel::structure() const {
  SheetStructure s;
  s.singularVertices = singularVertices();
  s.junctionVertices = paper::junctionVertices(sheet_->geometric());
  const auto& regions = sheet_->geometric().regions;
  for (std::size_t i = 0; i < regions.size(); ++i) {
    if (regions[i].rulings.empty()) continue;
    s.regions.push_back(
        {static_cast<int>(i), regions[i].apex, static_cast<int>(regions[i].rulings.size())});
    for (const auto& r : regions[i].rulings) s.rulings.push_back({r.a, r.b});
  }
  return s;
}

// The crumpling model's cuts are S_G's (paper::cutGeometricMesh), S_P only
// finds where they go: over S_P's long curved-region cells the elastic
// model's snap would pull short advances back onto the tip.
tear::TearingParams CrumplingModel::tearingParams(const tear::TearingParams& scene) const {
  tear::TearingParams p = scene;
  p.snap = paper::GeometricCutOptions{}.snap;
  p.minStartAngle = kMinStartAngle;
  p.maxTurn = paper::GeometricCutOptions{}.maxTurn;
  return p;
}

mesh::SheetMesh CrumplingModel::tearMesh() const {
  mesh::SheetMesh sheet = sheet_->physical().mesh;
  sheet.positions = sheet_->elastic().positions();
  return sheet;
}

std::vector<int> CrumplingModel::junctionVertices() const {
  return paper::junctionVertices(sheet_->geometric());  // S_G vertices are S_P's first
}

double CrumplingModel::lipTolerance() const { return kLipTolerance; }

// The advances cut S_G (thesis 3.3.3 "Remeshing"), S_P is rebuilt from it,
// and the model goes on with the torn sheet; a sheet torn apart (or one S_G
// cannot cut) is handed over to the elastic model.
TearOutcome CrumplingModel::cut(TearCut& cut) {
  const tear::TearFrameResult& r = cut.result;
  TearOutcome out;
  out.events = r.events;
  bool cutInGeometric = false;
  if (std::none_of(r.events.begin(), r.events.end(),
                   [](const tear::TearEvent& e) { return e.separated; })) {
    const auto& segments = cut.tearing.segments();
    const std::size_t first = segments.size() - r.events.size();
    std::vector<paper::HybridSheet::TearAdvance> advances;
    for (std::size_t k = 0; k < r.events.size(); ++k) {
      paper::HybridSheet::TearAdvance a;
      a.from = r.events[k].from;
      a.to = r.events[k].to;
      for (std::size_t j = first + k; !r.events[k].started && j-- > 0;)
        if (segments[j].tear == r.events[k].tear) {
          a.previousDirection = (segments[j].cut.back() - segments[j].cut.front()).normalized();
          break;
        }
      advances.push_back(a);
    }
    std::string why = "it would come apart in pieces";
    try {
      paper::GeometricCutOptions cutOptions;
      cutOptions.kerf = kTearKerf;
      if (const auto cuts = sheet_->tear(advances, cutOptions)) {
        std::vector<std::vector<Vec2>> lines;
        for (const auto& c : *cuts) {
          lines.push_back(c.cut);
          out.regionsFlattened += c.regionsFlattened;
        }
        cut.tearing.recut(lines);
        cut.sheet = sheet_->physical().mesh;
        cut.tearing.rebind(cut.sheet, kLipTolerance);
        for (std::size_t k = 0; k < out.events.size(); ++k) {
          out.events[k].from = lines[k].front();
          out.events[k].to = lines[k].back();
        }
        out.geometricCuts += static_cast<int>(cuts->size());
        cutInGeometric = true;
      }
    } catch (const std::exception& e) {
      why = e.what();
    }
    if (!cutInGeometric)
      out.notes.push_back("frame " + std::to_string(cut.frame) +
                          ": the crumpling model's geometric layer could not take the tear (" +
                          why + ")");
  }
  if (!cutInGeometric) handOver(cut, out);
  return out;
}

// S_G is one piece with one outline (docs/TEARING.md): a sheet torn apart
// goes on as the elastic model on the scene's mesh, placed and moving as
// S_P, all its tears made again on it, its handles on the vertices nearest
// their points.
void CrumplingModel::handOver(TearCut& cut, TearOutcome& out) {
  const tear::TearFrameResult& r = cut.result;
  std::vector<tear::TearEvent> all = cut.earlier;
  all.insert(all.end(), r.events.begin(), r.events.end());
  std::vector<int> spHandles;
  for (const auto& h : rig_->handles()) spHandles.push_back(h.vertex);
  const mesh::SheetMesh& sp = sheet_->physical().mesh;
  const sim::ElasticSheet& elastic = sheet_->elastic();
  std::optional<ResampledSheet> resampled;
  std::optional<tear::Tearing> fresh;
  tear::TearFrameResult replayed;
  try {
    resampled = resampleSheet(context_->elasticMesh(), sp, elastic.positions(),
                              elastic.velocities(), spHandles);
    fresh.emplace(resampled->mesh, context_->tearing, context_->seed);
    std::vector<char> fineHeld(resampled->mesh.vertexCount(), 0);
    for (int v : resampled->handleVertices) fineHeld[static_cast<std::size_t>(v)] = 1;
    replayed = fresh->replay(resampled->mesh, all, fineHeld);
  } catch (const std::exception& e) {
    throw NumericalError("tear handover", cut.frame, e.what());
  }
  // This frame's advances as the fine mesh took them (the earlier ones are
  // recorded already).
  out.events.assign(
      replayed.events.end() - std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(r.events.size()),
                                                       std::ssize(replayed.events)),
      replayed.events.end());
  const std::vector<Vec3> velocities =
      tear::blendValues(resampled->velocities, replayed.blends, replayed.relocated);
  rig_->rebind(resampled->mesh, resampled->handleVertices, cut.t);
  auto next =
      std::make_unique<ElasticModel>(std::move(resampled->mesh), context_, *rig_, singularAtStart_);
  // Interpolating S_P's long thin cells does not keep the fine mesh's edge
  // lengths: it settles first, with its pins where they are, in a few tiny
  // implicit steps, then takes S_P's velocities.
  try {
    next->settle(cut.t, kRelaxSteps, kRelaxDt, velocities);
  } catch (const NumericalError& e) {
    throw NumericalError("tear handover", cut.frame, e.problem());
  }
  out.replacement = std::move(next);
  out.replacementTearing = std::move(fresh);
  out.notes.push_back("frame " + std::to_string(cut.frame) +
                      ": from there on the sheet is simulated by the elastic model on the "
                      "scene's rectangle mesh");
}

void CrumplingModel::restoreState(StateReader& in) {
  sheet_->restoreState(in);
  singularAtStart_.clear();
}

}  // namespace crumple::model
