#pragma once
// Isometry projection of S_P onto its pattern (paper Sec. 6.3, "Preserving
// length with respect to the pattern", eqs. (3)-(7); docs/ARCHITECTURE.md "One shot, end to end").
//
// Phase I (eqs. (3)-(6)). One direction u_e per undirected edge, oriented
// from the lower to the higher vertex index; a triangle's closure sum takes
// each edge with the sign of its walk (+1 along i -> j). Starting at u0_e,
// the current normalised edge directions, it drives the paper's two scalar
// constraints C_unit = sum_e (u_e.u_e - 1)^2 (eq. (4)) and C_closed =
// sum_t |lbar_ij u_ij + lbar_jk u_jk + lbar_ki u_ki|^2 (eq. (3)) to zero with
// two Lagrange multipliers and H = I, i.e. one 2x2 system per iteration
// (eq. (6)), capped at `maxIterations` (the paper's 200). Closure is
// evaluated with lbar in units of the mean pattern edge so the tolerance is
// scale-free. It stops when both RMS violations (per edge of |u|^2 - 1, per
// triangle of the closure residual) are below `tolerance`.
// Phase II (eq. (7)). min 1/2 sum_e |(p_j - p_i) - lbar_e u_e|^2 over the
// free vertices: the normal equations are the (unweighted) graph Laplacian
// restricted to the free vertices, handles moved to the right-hand side; it
// depends on the topology only, so it is factored once (SimplicialLLT) in
// the constructor and x, y, z are three solves per call.
//
// DEVIATIONS from the paper. Figures are measured by tests/paper/
// test_isometry.cpp on a 10 x 6 cm sheet (180 triangles) rolled onto a
// developable 3 cm cylinder with 1 % seeded noise and handles at two corners
// (c_mean 7.0e-3 before), unless stated otherwise.
//  1. Recentred objective (the default). With E = 1/2 sum |u - u0|^2
//     anchored at the start directions (the paper's reading, available as
//     PhaseOneObjective::Anchored), eq. (6) gives u_{k+1} = u0 - L_k
//     lambda': every iterate is u0 plus a combination of just two vectors
//     (the constraint gradients), while closure imposes ~3 conditions per
//     triangle. So it cannot reach the constraints: RMS closure stalls and
//     oscillates near its start value (1.2e-2 -> ~9e-3 over 200 iterations)
//     while the multipliers grow, as the paper warns. Measured c_mean after:
//     3.0e-3, no better than Phase II alone with u = u0 (3.3e-3); this
//     ~2x is the same ratio as the paper's own Table III (c_m / c_init
//     0.5-0.9). We therefore measure E from the current iterate (grad E = 0
//     in b_x; H = I becomes the proximal term of a minimum-norm SQP step):
//     the same 2x2 system of eq. (6) with the same two multipliers, each step
//     the smallest change of u that zeroes the linearised C_unit and
//     C_closed. Since the steps start at u0 and lie in the span of the
//     constraint gradients, the iteration still tends to the minimiser of the
//     paper's E under the (linear) closure constraint. Measured: c_mean
//     1.6e-4 (45x lower), mean displacement 7.8e-5 m for a mean input noise
//     of 8.9e-5 m, mean distance to the clean sheet 8.9e-5 -> 4.3e-5 m. A
//     flat sheet compressed by 2 % in x: 9.6e-3 -> 8e-8 (Anchored: 1.9e-3).
//  2. u is renormalised between Phase I and Phase II, so Phase II targets
//     edge vectors of length exactly lbar (Anchored on a noisy smooth roll,
//     112 triangles: 3.8e-3 -> 3.4e-3; a few % with the default). An edge
//     whose |u| left [0.5, 2] (never seen) keeps u0.
//  3. A constraint already met (RMS below `tolerance`) is left out of the
//     2x2 system: its gradient is then rounding noise (C_unit at u = u0) and
//     only constrained the step in a random direction (c_mean 1.8e-4 ->
//     1.6e-4).
//  4. Numerical guards on eq. (6): we solve for lambda' = lambda + dlambda
//     directly (L^T L lambda' = C - L^T grad E, dx = -grad E - L lambda',
//     algebraically eq. (6)), so the diverging multipliers never cancel
//     inside b_x; the 2x2 system is Jacobi scaled; parallel gradients
//     (1 - cos^2 < 1e-10) take the minimum-norm rank-one solution; the loop
//     stops when both gradients vanish or a multiplier is not finite, keeping
//     the last finite iterate; a step moving any u_e by more than 0.5 is
//     scaled down (a safety net never reached in the tests, including
//     noise of 200 % of the edge length).
//  5. IsometryOptions::rounds repeats Phase I + Phase II (u0 taken from the
//     Phase II result). Default 1, the paper's cost; 2 rounds: 1.6e-4 ->
//     9.6e-5 at twice the time.
//  6. A connected component without a fixed vertex (the Laplacian is
//     singular there) pins its lowest-index vertex for the solve and is then
//     translated so its vertex centroid equals the input's. Vertices in no
//     triangle are left where they are.
//  7. Gauss-Seidel length sweeps (IsometryOptions::lengthSweeps; 0 here,
//     300 in HybridSheet, a scene's `[model] isometry_length_sweeps`): after the last Phase II
//     every edge in turn is projected onto its pattern length, its free ends moved equally along
//     it, fixed vertices immobile (the distance projection of position-based
//     dynamics). Phase I + II is a global step that stalls where the coarse
//     S_P of the crumpling samples meets its handles; the sweeps remove the
//     local residue: the noisy roll above 1.6e-4 -> 1.5e-5 with 300 sweeps;
//     first-singularity, whole shot, worst frame 1.0 % -> 0.16 % (with the
//     handles alone fixed, docs/CRUMPLING.md). Every sweep walks the edges
//     in their sorted order (S_G's low-index vertices, handles first):
//     alternating forward and backward sweeps converged less (cylinder-fold
//     frame 60: 1.4e-3 against 6.1e-4), over-relaxation (1.5, 1.8) did not
//     help and broke the moebius band at 1.8.
// Known limit (as in the paper): Phase I does not see the handles, so Phase
// II absorbs the mismatch between the integrated edge vectors and the fixed
// vertices in the edges next to the handles (max error 1.6e-3 there, 3.9e-4
// on the same sheet without handles).
//
// Cost: ~0.37 ms per call for 120 triangles and ~1.2 ms for 400 (200
// iterations, Release, one core), plus ~0.3 ms for 300 length sweeps on
// 120 triangles; the paper's Table III reports 97-196 ms.
#include <array>
#include <memory>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::paper {

struct IsometryStats {
  int phaseOneIterations = 0;
  int lengthSweeps = 0;                // Gauss-Seidel sweeps run after Phase II (deviation 7)
  double meanLengthErrorBefore = 0.0;  // c_mean: mean over edges of |l - lbar|/lbar (fraction)
  double meanLengthErrorAfter = 0.0;
  double maxLengthErrorAfter = 0.0;
  double meanDisplacement = 0.0;  // d_m: mean vertex displacement (m)
};

// Which objective Phase I minimises (see DEVIATIONS above).
enum class PhaseOneObjective {
  Recentred,  // E measured from the current iterate (grad E = 0 in b_x); the default
  Anchored,   // the paper's E = 1/2 sum |u - u0|^2 verbatim; kept to reproduce Table III
};

struct IsometryOptions {
  PhaseOneObjective objective = PhaseOneObjective::Recentred;
  int rounds = 1;            // Phase I + Phase II passes per project() call (>= 1)
  double tolerance = 1e-13;  // Phase I stops when both RMS constraint violations are below
  // Deviation 7: Gauss-Seidel sweeps over the edges after the last Phase II,
  // stopping early once every edge is within lengthTolerance of its pattern
  // length (relative). 0 keeps the paper's projection alone.
  int lengthSweeps = 0;
  double lengthTolerance = 1e-6;
};

class IsometryProjector {
 public:
  // The mesh topology: pattern (rest) positions, triangles, vertices held
  // fixed (handles). Builds the edge list and factors the Phase II matrix
  // once. Throws std::invalid_argument on an index out of range, a triangle
  // with a repeated vertex, a non-finite pattern coordinate or a zero-length
  // pattern edge.
  IsometryProjector(std::vector<Vec2> pattern, std::vector<std::array<int, 3>> triangles,
                    std::vector<int> fixedVertices, IsometryOptions options = {});
  ~IsometryProjector();
  // Movable (a moved-from projector may only be destroyed or assigned to).
  IsometryProjector(IsometryProjector&&) noexcept;
  IsometryProjector& operator=(IsometryProjector&&) noexcept;
  IsometryProjector(const IsometryProjector&) = delete;
  IsometryProjector& operator=(const IsometryProjector&) = delete;

  // True when (triangles, fixed) equal this projector's, so the factorisation
  // can be reused. Triangles must match in order; fixed vertices are compared
  // as sets (order and repeats do not matter).
  bool sameTopology(const std::vector<std::array<int, 3>>& triangles,
                    const std::vector<int>& fixedVertices) const;

  // Projects `positions` (in/out) towards isometry with the pattern: Phase I
  // then Phase II (paper Sec. 6.3). Fixed vertices keep their input
  // positions exactly. `maxIterations` caps Phase I per round (>= 0; 0 runs
  // Phase II alone). Throws NumericalError (stage "isometry") on a position
  // count that does not match, a non-finite position, an edge collapsed to
  // zero length or a failed solve, and then leaves `positions` unchanged.
  // Stats: phaseOneIterations summed over rounds; meanDisplacement over all
  // vertices, handles included.
  IsometryStats project(std::vector<Vec3>& positions, int maxIterations = 200) const;

  int vertexCount() const;
  int edgeCount() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crumple::paper
