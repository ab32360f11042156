#pragma once
// The state of paper::HybridSheet (its pimpl), shared by the files that
// implement it: hybrid_sheet.cpp (the animation step, paper Fig. 16) and
// hybrid_strain_limit.cpp (paper stays paper after it).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <sstream>
#include <utility>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/core/geometry2d.hpp"
#include "crumple/core/index.hpp"
#include "crumple/paper/boundary_curve.hpp"
#include "crumple/paper/damage.hpp"
#include "crumple/paper/hybrid_sheet.hpp"
#include "crumple/sim/colliders.hpp"
#include "crumple/sim/self_contact.hpp"
#include "region_tools.hpp"
#include "step_trace.hpp"

namespace crumple::paper {

namespace detail {

using Clock = std::chrono::steady_clock;

inline double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

inline bool allFinite(const std::vector<Vec3>& v) {
  return std::all_of(v.begin(), v.end(), [](const Vec3& x) { return x.allFinite(); });
}

}  // namespace detail

struct HybridSheet::Impl {
  GeometricMesh sg;
  PhysicalMesh sp;
  sim::Material material;
  sim::SimParams simParams;
  CrumpleParams params;
  std::uint64_t seed = 1;
  std::optional<sim::ElasticSheet> elastic;
  std::optional<IsometryProjector> isometry;
  std::vector<Vec3> spVelocities;
  double paperLength = 0.0;
  std::function<void(const mesh::SheetMesh&, double)> onRebuild;
  sim::GripFunction grips;  // fingers as contact patches (setGrips)
  std::function<void(const ProjectionInput&)> onProjection;  // paper Table III inputs
  // The isometry projection's options from the parameters (paper Sec. 6.3).
  IsometryOptions isometryOptions() const {
    IsometryOptions iso;
    iso.rounds = params.isometryRounds;
    iso.lengthSweeps = params.isometryLengthSweeps;
    iso.lengthTolerance = params.isometryLengthTolerance;
    return iso;
  }
  double time = 0.0;            // time S_G and S_P are at
  sim::ContactOptions contact;  // docs/CONTACTS.md "The crumpling model"
  std::vector<sim::ContactSample> contacts;
  bool contactsOn() const {
    return (contact.colliders != nullptr && contact.colliders->size() > 0) ||
           contact.self != sim::SelfContactMode::Off;
  }
  // The paper's thickness while self-contact runs for S_P as it is (On, or
  // Auto and folded: sim::sheetIsFolded), else 0: no stage may then move
  // S_P through itself (keepElasticStepOutOfItself, the isometry's guard,
  // LengthProjector::setCrossingGuard).
  double crossingGuard() const {
    const bool on = contact.self == sim::SelfContactMode::On ||
                    (contact.self == sim::SelfContactMode::Auto &&
                     sim::sheetIsFolded(sp.mesh.triangles, sp.mesh.positions, contact.foldSpread));
    return on ? contact.distance : 0.0;
  }
  // Where compression was treated in the last remeshCooldown steps, and how
  // many more steps each point blocks remeshing of the region holding it.
  std::vector<std::pair<Vec2, int>> recentCuts;

  // Whether face f holds a recent cut (at one of its vertices or inside it).
  bool holdsRecentCut(const GeometricFace& f) const {
    const std::span<const int> corners(f.v.data(), idx(f.size()));
    for (const auto& [p, left] : recentCuts) {
      for (int v : corners) {
        if ((sg.vertices[idx(v)].pattern - p).norm() < 1e-9) return true;
      }
      if (detail::pointInPolygon(sg, corners, p)) return true;
    }
    return false;
  }

  // S_P from S_G (paper Sec. 4, Fig. 16 (g)) with fiber damage (thesis 2.3.3).
  // Returns true when the connectivity or pattern changed.
  bool rebuildPhysical() {
    PhysicalMesh next = buildPhysicalMesh(sg, params);
    updateSamples(next, sg, &spVelocities);
    const bool same = elastic.has_value() && next.mesh.triangles == sp.mesh.triangles &&
                      next.mesh.pattern == sp.mesh.pattern;
    sp = std::move(next);
    if (!same) {
      elastic.emplace(sp.mesh, material, simParams);
      elastic->setContacts(contact);
    } else {
      elastic->setPositions(sp.mesh.positions);
    }
    elastic->setVelocities(spVelocities);
    // Damage: rest angles and weakened bending around singular vertices.
    std::vector<char> singular(sp.mesh.vertexCount(), 0);
    for (std::size_t v = 0; v < sg.vertices.size(); ++v)
      singular[v] = sg.vertices[v].singular ? 1 : 0;
    const auto& hinges = elastic->hinges();
    std::vector<double> angles(hinges.size());
    for (std::size_t h = 0; h < hinges.size(); ++h) angles[h] = elastic->hingeAngle(h);
    const auto damage = fiberDamage(sp.mesh, hinges, singular, angles, params);
    const std::vector<double> sliver = sliverHingeFactors(sp.mesh, hinges, params.sliverHingeRatio);
    for (std::size_t h = 0; h < hinges.size(); ++h) {
      elastic->setHingeRestAngle(h, damage[h].restAngle);
      elastic->setHingeStiffnessFactor(h, damage[h].stiffnessFactor * sliver[h]);
    }
    if (onRebuild) onRebuild(sp.mesh, time);
    return !same;
  }

  // Developer trace (CRUMPLE_DEBUG_GEOMETRY, step_trace.hpp) and the largest
  // S_P hinge angle after the elastic step, the rebuild and the isometry.
  int traceLevel = detail::stepTraceLevel();
  std::array<double, 3> traceHinge{};

  double traceElasticStrain = 0.0;  // max |r_e| of S_P as the elastic step left it
  void noteHinge(int stage) {
    if (traceLevel > 0) traceHinge[idx(stage)] = detail::maxHingeAngle(*elastic);
  }

  bool undoStretchingGeometry(const mesh::SheetMesh& spBefore, const GeometricMesh& sgBefore,
                              const std::vector<Vec3>& elasticX, const std::vector<Vec3>& elasticV,
                              std::vector<Vec3>& positions, HybridStepStats& stats);
  // The largest fraction of the move from x0 (or, fromRigidMotion, from the
  // rigid motion that best takes x0 to x1) to x1 (S_P's vertices) that
  // passes no more edges through another layer than x0 had; x1 becomes that
  // point of the move (crossingGuard() > 0). Returns the fraction.
  double keepMoveOutOfItself(const std::vector<Vec3>& x0, std::vector<Vec3>& x1,
                             bool fromRigidMotion = false) const;
  // Whether x1 passes more edges through another layer than x0 does (S_P's
  // vertices; false when crossingGuard() is 0).
  bool passesThroughItself(const std::vector<Vec3>& x0, const std::vector<Vec3>& x1) const;
  // The elastic step from x0 over dt, shortened to the largest fraction that
  // passes no more of S_P's edges through another layer than x0 had
  // (crossingGuard() > 0); a sheet not `held` by a handle or grip keeps the
  // rigid part of its move. Returns the fraction (1: the whole step).
  double keepElasticStepOutOfItself(const std::vector<Vec3>& x0, double dt, bool held);
  // The pins of an animation step from t to t + dt, with every handle that
  // lags behind its node (further from it than the node moves over the step)
  // brought on at most params.lagCatchUpSpeed faster than its node, its
  // tangent-plane pins moved with it.
  sim::PinFunction catchUpPins(double t, double dt, const sim::PinFunction& pins) const;
  // The grips of an animation step, each moved by how far catchUpPins puts
  // its anchor handle from the handle's node (`pins` against `nodePins`).
  sim::GripFunction laggingGrips(const sim::PinFunction& pins,
                                 const sim::PinFunction& nodePins) const;
  // stats.lag and handleLags of x against the handles' nodes (the pins of
  // the rig, not catchUpPins').
  void measureLags(const std::vector<sim::Pin>& nodes, const std::vector<Vec3>& x,
                   StrainLimitStats& s) const;
  bool isHandle(int v) const { return inRange(sg.vertices, v) && sg.vertices[idx(v)].handle; }
  void limitStepStrain(const mesh::SheetMesh& spBefore, const GeometricMesh& sgBefore,
                       const std::vector<sim::Pin>& pinned, int frame, std::vector<Vec3>& positions,
                       HybridStepStats& stats);
  // The pinned vertices of S_P (1), which contacts leave where they are.
  std::vector<char> heldBy(const std::vector<sim::Pin>& pinned) const {
    std::vector<char> out(sp.mesh.vertexCount(), 0);
    for (const sim::Pin& p : pinned)
      if (inRange(out, p.vertex)) out[idx(p.vertex)] = 1;
    return out;
  }
  // The stages of animationStep (paper Fig. 16): (a)-(b) the elastic step, (d)-(e) the
  // geometric step, (f) the cone fit, S_G's checks, (h) the isometry projection and the
  // positions it leaves.
  void elasticStep(double t, double dt, const sim::PinFunction& pins,
                   const sim::PinFunction& nodePins, HybridStepStats& stats);
  void geometricStep(const BoundaryCurve& curve, const std::vector<Vec3>& x, int frame,
                     const CrumpleParams& stepParams, std::uint64_t& draw, HybridStepStats& stats);
  void refitCones(const BoundaryCurve& curve, HybridStepStats& stats);
  void checkGeometric(int frame) const;
  std::vector<Vec3> projectIsometry(double t, const std::vector<sim::Pin>& pinned, int frame,
                                    HybridStepStats& stats);
  void commitPositions(const std::vector<Vec3>& positions, const HybridStepStats& stats);
  void animationStep(double t, double dt, const sim::PinFunction& nodePins, int frame,
                     int singularBudget, std::uint64_t& draw, HybridStepStats& stats,
                     const char*& stage);

  // The elastic step's contacts, carried to the current S_P by pattern.
  void carryContacts(const std::vector<sim::ContactSample>& samples,
                     const std::vector<Vec2>& patternBefore);

  void checkInvariants(int frame, const char* stage) const {
    const std::string problem = validate(sg, params.theta0);
    if (!problem.empty()) throw NumericalError(stage, frame, "S_G invariant broken: " + problem);
    if (sp.geometricVertexCount() != sg.vertexCount()) {
      throw NumericalError(stage, frame, "S_P does not hold every S_G vertex");
    }
    const std::string mp = mesh::validate(sp.mesh);
    if (!mp.empty()) throw NumericalError(stage, frame, "S_P invalid: " + mp);
    double area = 0.0;
    for (const auto& t : sp.mesh.triangles) {
      const Vec2 a = sp.mesh.pattern[idx(t[1])] - sp.mesh.pattern[idx(t[0])];
      const Vec2 b = sp.mesh.pattern[idx(t[2])] - sp.mesh.pattern[idx(t[0])];
      area += 0.5 * (a.x() * b.y() - a.y() * b.x());
    }
    const double sheet = outlineArea(sg);
    if (std::abs(area - sheet) > 1e-9 * sheet) {
      std::ostringstream msg;
      msg << "S_P covers " << area << " m^2 of the " << sheet << " m^2 sheet";
      throw NumericalError(stage, frame, msg.str());
    }
  }
};

}  // namespace crumple::paper
