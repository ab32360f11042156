#pragma once
// Strain limiting of S_P after every animation step: paper stays paper.
//
// The isometry projection (paper Sec. 6.3) has no convergence guarantee and
// stalls where the coarse S_P meets its handles (docs/CRUMPLING.md, "Why the
// isometry cannot close"). This stage bounds what it leaves:
//  0. (first) the same with the handles' tangent-plane pins held too, and
//     only the vertices near the edges over the bound free: the stepped
//     sheet is changed only where it breaks the bound.
//  1. LengthProjector: min sum_e r_e^2, r_e = (l_e - L_e) / L_e, over the free
//     vertices by Levenberg-Marquardt (Levenberg 1944, Marquardt 1963; the
//     least-squares form of the length constraints of Goldenthal et al.
//     2007, "Efficient simulation of inextensible cloth"), handles held.
//  2. A carried start: the sheet as it was before the step, moved by the
//     rigid motion that best takes its handles to their new targets (Kabsch
//     1976), is isometric by construction; the projection from there
//     reaches configurations the stepped sheet cannot.
//  3. Lag: when neither start meets the bound with the handles on their
//     targets, each handle is brought as near its target as the bound lets
//     it (LengthProjector::projectTowards, from the carried start), so one
//     handle that cannot follow does not hold the others back. Failing that, the handles are held
//     together on the segment from their carried positions (alpha = 0, lengths exact) to their
//     targets (alpha = 1), at the largest alpha found by bisection that meets the bound. The handle
//     rig pulls them on at the next step. When the contacts given
//     (KeepOut) keep even the carried start over the bound, they are
//     dropped for this step: the bound wins over a contact.
#include <array>
#include <memory>
#include <utility>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/sim/elastic_sheet.hpp"
#include "crumple/sim/self_contact.hpp"

namespace crumple::paper {

// A contact as a constraint of the projection: `vertex` stays on the side
// of the plane through `point` that `normal` (unit) points to. The contact
// failsafe's move of a vertex out of a collider or another layer gives one
// (its new position and direction), linearised where it acted.
struct KeepOut {
  int vertex = -1;
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
};

struct LengthProjectionStats {
  double maxBefore = 0.0, maxAfter = 0.0;    // max |r_e|
  double meanBefore = 0.0, meanAfter = 0.0;  // mean |r_e|
  int iterations = 0;                        // accepted Levenberg-Marquardt steps
};

// Relative edge-length residuals of a triangle mesh against its pattern.
class LengthProjector {
 public:
  LengthProjector(const std::vector<Vec2>& pattern,
                  const std::vector<std::array<int, 3>>& triangles);

  // Max and mean |r_e| of `x`.
  [[nodiscard]] std::pair<double, double> strain(const std::vector<Vec3>& x) const;

  // Levenberg-Marquardt on sum_e r_e^2 with `held` vertices fixed (held[v]
  // != 0). Stops when max |r_e| <= `target`, after `maxIterations` accepted
  // steps, or when a step no longer lowers the cost by 1e-6 of itself.
  // Returns the iterate with the smallest max |r_e| (the given `x` when no
  // step lowers it): the objective is the sum, the bound is on the max.
  LengthProjectionStats project(std::vector<Vec3>& x, const std::vector<char>& held, double target,
                                int maxIterations) const;

  // The handles as soft targets (a finger's grip, not a pin): Levenberg-
  // Marquardt on sum_e r_e^2 + kBoundWeight sum_e max(0, |r_e| - kSoftBound
  // bound)^2 + (kHandleWeight / l^2) sum_h |x_h - t_h|^2 (l the mean rest
  // length), `handles` free unless `held`. Within the bound the handles win
  // over the lengths, beyond it the lengths win: each handle gets as near
  // its target as the bound lets it, so one handle that cannot follow does
  // not stop the others (a penalty form of min sum_h |x_h - t_h|^2 subject
  // to |r_e| <= bound). Runs to convergence; the bound is not guaranteed,
  // the caller checks it.
  LengthProjectionStats projectTowards(std::vector<Vec3>& x, const std::vector<char>& held,
                                       const std::vector<int>& handles,
                                       const std::vector<Vec3>& targets, double bound,
                                       int maxIterations) const;
  static constexpr double kHandleWeight = 1e2;
  static constexpr double kBoundWeight = 1e6;
  static constexpr double kSoftBound = 0.75;

  // held[v] = 1 for every vertex more than `rings` edges away from an edge
  // with |r_e| > `above` (added to `held`): a local projection moves only
  // the neighbourhood of the edges that break a bound.
  void holdAwayFrom(const std::vector<Vec3>& x, double above, int rings,
                    std::vector<char>& held) const;

  [[nodiscard]] std::size_t edgeCount() const { return edges_.size(); }

  // Contacts every projection keeps (a penalty (kHandleWeight / l^2)
  // min(0, n . (x_v - p))^2 per KeepOut, l the mean rest length): the
  // strain limit then works with the contact failsafe, not against it.
  void setKeepOut(std::vector<KeepOut> keepOut) { keepOut_ = std::move(keepOut); }

  // Self-contact as a guard on every projection (`thickness` > 0, the
  // paper's, m; 0 turns it off): a Levenberg-Marquardt step is accepted only
  // when it passes no more edges through another layer than the iterate had
  // (sim::SelfContactDetector::crossings), so a projection never moves the
  // sheet through itself.
  void setCrossingGuard(double thickness);
  // Edges through another layer at x (0 without the guard).
  [[nodiscard]] std::size_t crossings(const std::vector<Vec3>& x) const;

 private:
  LengthProjectionStats solve(std::vector<Vec3>& x, const std::vector<char>& held,
                              const std::vector<int>& handles, const std::vector<Vec3>& targets,
                              double target, double bound, int maxIterations) const;
  std::vector<std::array<int, 2>> edges_;
  std::vector<double> rest_;
  std::vector<int> used_;  // vertices in some triangle
  std::vector<KeepOut> keepOut_;
  std::size_t vertexCount_ = 0;
  std::vector<std::array<int, 3>> triangles_;
  std::vector<Vec2> pattern_;
  std::shared_ptr<sim::SelfContactDetector> crossingGuard_;  // refitted per call
};

// The rigid motion (R, t) minimising sum_i |R a_i + t - b_i|^2 (Kabsch 1976).
// One point: a translation. Two points, or collinear ones: the smallest
// rotation that aligns the lines, about the centroid. Three or more: the SVD
// solution with det R = +1.
struct RigidMotion {
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();
  [[nodiscard]] Vec3 apply(const Vec3& p) const { return rotation * p + translation; }
};
RigidMotion fitRigidMotion(const std::vector<Vec3>& from, const std::vector<Vec3>& to);

// Positions for the vertices of a new S_P (`pattern`) interpolated from an
// old S_P on the same pattern (`oldPattern`, `oldTriangles`, `oldPositions`):
// each pattern point located in the old triangle containing it (or the
// nearest one) and placed barycentrically. Used for the carried start when
// S_P was rebuilt with a new connectivity.
std::vector<Vec3> transferByPattern(const std::vector<Vec2>& oldPattern,
                                    const std::vector<std::array<int, 3>>& oldTriangles,
                                    const std::vector<Vec3>& oldPositions,
                                    const std::vector<Vec2>& pattern);

// One strain-limit stage over an animation step (the steps 1-3 above).
struct StrainLimitInput {
  // S_P at the step's end (after the isometry and the contact failsafe).
  const std::vector<Vec2>& pattern;
  const std::vector<std::array<int, 3>>& triangles;
  // S_P at the step's start; `sameMesh` when its pattern and triangles are
  // the ones above (no rebuild with a new connectivity in between).
  const std::vector<Vec2>& beforePattern;
  const std::vector<std::array<int, 3>>& beforeTriangles;
  const std::vector<Vec3>& beforePositions;
  bool sameMesh = false;
  // The handle vertices (indices valid in both meshes) and their targets.
  const std::vector<int>& handles;
  const std::vector<Vec3>& targets;
  // More vertices held where they are in a first attempt from the stepped
  // sheet (the handles' tangent-plane pins, so the elastic step's tangent
  // control is kept when the bound allows it).
  const std::vector<int>& pins;
  double bound = 0.02;  // max |r_e| accepted
  int iterations = 30;  // Levenberg-Marquardt steps per projection
  // Contacts the projections keep (LengthProjector::setKeepOut); the
  // positions given are already out of them.
  std::vector<KeepOut> keepOut = {};
  // The paper's thickness when self-contact is on (LengthProjector::
  // setCrossingGuard), else 0.
  double crossingGuard = 0.0;
};

struct StrainLimitStats {
  double maxBefore = 0.0;  // max |r_e| as the isometry and contacts left S_P
  double maxAfter = 0.0;   // after this stage
  double meanAfter = 0.0;
  int iterations = 0;    // accepted Levenberg-Marquardt steps, every attempt
  bool ran = false;      // maxBefore was above the bound
  bool carried = false;  // the carried start gave the result
  // The contacts (KeepOut) could not be kept within the bound from the
  // carried start and were dropped for the lag (steps 3a-3b).
  bool droppedKeepOut = false;
  double lag = 0.0;    // the largest distance of a handle from its target (m)
  int lagVertex = -1;  // that handle's vertex, or -1
  // Every handle's distance from its target (m), in StrainLimitInput order:
  // (vertex, lag).
  std::vector<std::pair<int, double>> handleLags;
};

// Each handle's larger lag of `from` and `into`, into `into` (handles of
// `from` that `into` lacks are appended): a frame's lags over its steps.
void mergeHandleLags(const std::vector<std::pair<int, double>>& from,
                     std::vector<std::pair<int, double>>& into);

// The contact failsafe (sim::projectOutOfContacts) on `x`, as the
// constraints it imposed: each vertex it moved, at its new position, with
// the direction it moved in. `held` vertices stay (the handles and pins).
std::vector<KeepOut> keepOutOfContacts(const sim::ContactOptions& options,
                                       const std::vector<std::array<int, 3>>& triangles,
                                       const std::vector<Vec2>& pattern,
                                       const std::vector<char>& held, std::vector<Vec3>& x,
                                       double* collidersMs, double* selfMs);

// Leaves `positions` within `bound` whenever the step's start was, holding
// the handles on their targets if some start allows it and lagging them
// otherwise; never raises the max strain it was given. With a crossing
// guard it takes no candidate that passes more edges through another layer
// than `positions` did, unless none meets the bound that way (the bound
// first).
StrainLimitStats limitStrain(const StrainLimitInput& in, std::vector<Vec3>& positions);

}  // namespace crumple::paper
