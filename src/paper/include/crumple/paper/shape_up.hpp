#pragma once
// Shape-Up projection of S_P onto isometry with its pattern, with hard
// constraints: the method the paper compares its isometry projection with
// (paper Sec. 7.2 "Comparison with ... Shape-Up", Table III, Fig. 20;
// Bouaziz, Deuss, Schwartzburg, Weise, Pauly 2012, "Shape-Up: Shaping
// Discrete Geometry with Projections").
//
// Local step (Shape-Up's projection operator P_t): each triangle is projected
// onto the nearest rigid image of its pattern triangle, R_t qbar with R_t a
// 3x2 matrix with orthonormal columns, best fit in the least-squares sense of
// the centred vertices: R_t = U V^T from the SVD of the 3x2 cross-covariance
// sum_k (x_k - x_c)(q_k - q_c)^T (the polar factor; a 2D pattern in 3D has no
// reflection to exclude). Global step: min sum_t sum_{edges (i,j) of t}
// |(p_j - p_i) - R_t (q_j - q_i)|^2 over the free vertices -- Shape-Up's
// mean-centred triangle constraint is exactly 1/3 of this edge sum -- i.e.
// the graph Laplacian weighted by each edge's triangle count, the handles
// eliminated (hard), factored once per topology (SimplicialLLT, shared with
// the isometry projection's Phase II, paper eq. (7)).
//
// "Hard constraints" (the paper's modification): Shape-Up's closeness term to
// the input is dropped (weight 0) and the local/global iteration runs until
// every triangle is within `tolerance` of its rigid projection (relative
// residual sqrt(sum_k |e_k - R_t ebar_k|^2 / sum_k |ebar_k|^2) over its three
// edges), c_mean is within `meanLengthTolerance` (when set) or `maxIterations`
// is reached; the energy never increases, so the
// loop also stops when an iteration lowers it by less than `stallTolerance`
// (relative), which is what happens when the handles make the constraints
// incompatible.
#include <array>
#include <memory>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::paper {

struct ShapeUpStats {
  int iterations = 0;      // local/global iterations run
  bool converged = false;  // every triangle within tolerance, or c_mean within meanLengthTolerance
  double maxTriangleResidual = 0.0;    // the largest relative residual at the end
  double meanLengthErrorBefore = 0.0;  // c_mean: mean over edges of |l - lbar|/lbar (fraction)
  double meanLengthErrorAfter = 0.0;
  double maxLengthErrorAfter = 0.0;
  double meanDisplacement = 0.0;  // d_m: mean vertex displacement (m)
};

struct ShapeUpOptions {
  int maxIterations = 1000;      // local/global iterations per project() call (>= 0)
  double tolerance = 1e-6;       // largest relative triangle residual to stop at (> 0)
  double stallTolerance = 1e-9;  // relative energy decrease to stop at (>= 0)
  // Also stop once c_mean (mean over edges of |l - lbar| / lbar) is at most
  // this (0: off); e.g. another projection's c_mean, to time Shape-Up to the
  // same error.
  double meanLengthTolerance = 0.0;
};

// c_mean of paper Table III: the mean over the mesh's edges of
// |l - lbar| / lbar (fraction). Throws std::invalid_argument on a topology
// ShapeUpProjector rejects, NumericalError (stage "c_mean") on positions it
// rejects.
double meanLengthError(const std::vector<Vec2>& pattern,
                       const std::vector<std::array<int, 3>>& triangles,
                       const std::vector<Vec3>& positions);

class ShapeUpProjector {
 public:
  // The mesh topology: pattern (rest) positions, triangles, vertices held
  // fixed (handles). Factors the global-step matrix once. Throws
  // std::invalid_argument on an index out of range, a triangle with a
  // repeated vertex, a non-finite pattern coordinate, a zero-length pattern
  // edge or an invalid option.
  ShapeUpProjector(std::vector<Vec2> pattern, std::vector<std::array<int, 3>> triangles,
                   std::vector<int> fixedVertices, ShapeUpOptions options = {});
  ~ShapeUpProjector();
  ShapeUpProjector(ShapeUpProjector&&) noexcept;
  ShapeUpProjector& operator=(ShapeUpProjector&&) noexcept;
  ShapeUpProjector(const ShapeUpProjector&) = delete;
  ShapeUpProjector& operator=(const ShapeUpProjector&) = delete;

  // Projects `positions` (in/out) towards isometry with the pattern by
  // Shape-Up's local/global iteration. Fixed vertices keep their input
  // positions exactly. Throws NumericalError (stage "shape-up") on a
  // position count that does not match, a non-finite position or a failed
  // solve, and then leaves `positions` unchanged. meanDisplacement is over
  // all vertices, handles included.
  ShapeUpStats project(std::vector<Vec3>& positions) const;

  int vertexCount() const;
  int edgeCount() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crumple::paper
