#pragma once
// The hybrid crumpling model, one animation step at a time (paper Sec. 3.3,
// Figs. 3 and 16; thesis Algorithm 1): an elastic step on S_P, positions to
// S_G, the geometric step (flips, flat-region splits, compression analysis,
// ruling propagation and singular vertices, junction points, generalized
// cones), S_P rebuilt from S_G with fiber damage, and the isometry
// projection of S_P with the handles fixed.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "crumple/paper/enrich.hpp"
#include "crumple/paper/geometric_mesh.hpp"
#include "crumple/paper/geometric_step.hpp"
#include "crumple/paper/isometry.hpp"
#include "crumple/paper/params.hpp"
#include "crumple/paper/strain_limit.hpp"
#include "crumple/paper/tear_remesh.hpp"
#include "crumple/sim/elastic_sheet.hpp"

namespace crumple::paper {

// Milliseconds spent in each stage over one frame (all its animation steps).
struct HybridStageTimes {
  double elastic = 0.0;    // FEM on S_P
  double geometric = 0.0;  // flips, splits, compression, rulings, singular vertices, junctions
  double cones = 0.0;      // generalized-cone fitting (paper Sec. 6.2)
  double rebuild = 0.0;    // S_P from S_G, fiber damage, elastic-model setup
  double isometry = 0.0;   // paper Sec. 6.3
  // The contact failsafe after the isometry: against colliders,
  // and self-contact (with carrying the contact set over to S_P).
  double contacts = 0.0;
  double selfContacts = 0.0;
  double strainLimit = 0.0;  // strain_limit.hpp, after the contacts
};

struct HybridStepStats {
  sim::StepStats elastic;
  GeometricStepStats geometric;
  IsometryStats isometry;
  HybridStageTimes ms;
  int coneSegments = 0;
  bool topologyChanged = false;  // S_P was rebuilt with a new connectivity
  int elasticRetries = 0;        // elastic steps retried with the pins snapped onto their targets
  // Elastic steps the crossing guard held back entirely (not even 1/64 of
  // their move kept S_P from passing through itself), so the sheet stood
  // still and its handles lag (docs/CRUMPLING.md "A crossing that stops the
  // whole sheet").
  int elasticHeldStill = 0;
  // Geometric steps and remeshings the strain bound undid (docs/CRUMPLING.md
  // "The geometric step under the bound"): their structure changes are in
  // `geometric` all the same.
  int undoneByBound = 0;
  // The strain limit of the frame's last animation step, except: `ran`,
  // `carried` and `iterations` count the steps, `lag` is the frame's largest.
  StrainLimitStats strainLimit;
  int strainLimitRuns = 0, strainLimitCarried = 0;
};

// What the isometry projection (paper Sec. 6.3) is handed in one animation
// step, just before it runs: S_P's pattern, triangles and positions, the
// vertices it holds fixed, its options and iteration cap, the frame and
// the time the step ends at. Valid during the call only.
struct ProjectionInput {
  const std::vector<Vec2>& pattern;
  const std::vector<std::array<int, 3>>& triangles;
  const std::vector<int>& fixed;
  // Every vertex the handle rig pins at the step's end (handles and their
  // tangent-plane vertices), sorted; `fixed` is the part the projection holds.
  const std::vector<int>& pinned;
  const std::vector<Vec3>& positions;
  IsometryOptions options;
  int maxIterations = 0;
  int frame = 0;
  double t = 0.0;
};

class HybridSheet {
 public:
  // `sg`: the starting S_G (e.g. makeFlatSheet); its handle vertices are the
  // ones pins refer to, and they keep their indices for the whole run (S_G
  // vertices before them are corners, which are never removed). `seed`
  // seeds the singular-vertex placement (CounterRng per frame).
  HybridSheet(GeometricMesh sg, const sim::Material& material, const sim::SimParams& simParams,
              const CrumpleParams& params, std::uint64_t seed);
  ~HybridSheet();
  HybridSheet(HybridSheet&&) noexcept;
  HybridSheet& operator=(HybridSheet&&) noexcept;

  // Frame `frame`, from t to t + dt, as `substeps` animation steps of
  // dt / substeps, each an elastic step, the geometric step, cone fitting,
  // S_P rebuild and isometry (at most maxSingularPerFrame new singular
  // vertices over them; the stats are summed, the isometry's are the last
  // step's). Pins refer to S_G vertex indices. Throws NumericalError naming
  // the frame and stage on failure, leaving the sheet as it was before the
  // call.
  HybridStepStats advance(double t, double dt, int substeps, const sim::PinFunction& pins,
                          int frame);

  // Called with the new S_P and the time it is at, every time S_P is
  // rebuilt, before pins are asked for again (the handle rig re-chooses its
  // tangent-plane vertices there).
  void setRebuildCallback(std::function<void(const mesh::SheetMesh&, double t)> callback);

  // Fingers as contact patches (sim::Grip; [[handles]] patch_radius):
  // every elastic step holds the grips `grips` gives on the current S_P
  // (asked again after each rebuild, like the pins), each moved with its
  // anchor handle when that lags behind its node. Unset by default.
  void setGrips(sim::GripFunction grips);

  // Called with every projection's input (paper Table III compares
  // projections on them, bench/harness/projection_comparison.cpp). Unset by
  // default (no cost).
  void setProjectionCallback(std::function<void(const ProjectionInput&)> callback);

  // Contacts: the elastic step of every animation step takes them
  // (sim::ElasticSheet::setContacts), and after the isometry projection a
  // failsafe moves free S_P vertices nearer than 0.95 distance to a collider
  // or to another layer of the sheet back out to the distance. Off by
  // default.
  void setContacts(sim::ContactOptions options);
  // The contacts at the end of the last animation step, on the current S_P
  // (the elastic step's contacts carried over to the rebuilt S_P by their
  // pattern coordinates), sorted by (vertex, collider).
  const std::vector<sim::ContactSample>& contacts() const;

  // Moves pinned vertices (S_G or S_P indices) to the given positions before
  // the first step (handles snapping onto their tracks) and re-interpolates
  // S_P from S_G.
  void placeVertices(const std::vector<sim::Pin>& pins);
  // The time the sheet is at before the first step (s).
  void setTime(double t);

  // One advance of a tear (thesis 3.3.3), in the pattern: from s_t (on the
  // outline) to s_{t+1}; `previousDirection`: the tear's last advance's
  // direction when s_t is its tip.
  struct TearAdvance {
    Vec2 from = Vec2::Zero();
    Vec2 to = Vec2::Zero();
    std::optional<Vec2> previousDirection;
  };
  // Tears the sheet (thesis 3.3.3 "Remeshing"): S_G takes the
  // current positions and velocities of S_P, each advance cuts it in turn
  // (cutGeometricMesh), and S_P is rebuilt from it; the model goes on
  // crumpling the torn sheet. All or nothing: std::nullopt, the sheet as it
  // was, when an advance would tear S_G in two (cutGeometricMesh); the
  // exceptions of cutGeometricMesh likewise leave it as it was.
  std::optional<std::vector<GeometricCutResult>> tear(const std::vector<TearAdvance>& advances,
                                                      const GeometricCutOptions& options);

  // The elastic model on the current S_P, at the end of the last step: S_P's
  // positions and velocities, its hinges' rest angles and stiffness factors
  // (fiber damage), the membrane forces on a vertex (what a tear tip feels,
  // thesis 3.3.3), and the state a torn sheet carries over to a plain
  // sim::ElasticSheet.
  const sim::ElasticSheet& elastic() const;
  const GeometricMesh& geometric() const;  // S_G
  const PhysicalMesh& physical() const;    // S_P (the displayed mesh)
  const CrumpleParams& params() const;
  int singularVertexCount() const;
  int interiorSingularVertexCount() const;

  // Checkpoint and resume: S_G, S_P with its samples, the
  // velocities, the time, the contacts, the remeshing cooldowns and the
  // elastic model's state, written for a sheet built again from the same
  // scene (same material, parameters and seed). restoreState rebuilds the
  // elastic model on the restored S_P; it throws CorruptDataError for a
  // malformed state.
  void saveState(StateWriter& out) const;
  void restoreState(StateReader& in);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crumple::paper
