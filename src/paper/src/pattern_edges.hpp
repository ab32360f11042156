#pragma once
// What the isometry projection (paper Sec. 6.3, isometry.cpp) and the
// Shape-Up projection it is compared with (shape_up.cpp, paper Table III)
// share: the pattern's edge graph with its rest lengths, the edge-fit
// least-squares solve with the handles eliminated (eq. (7)), and the
// c_mean / d_m measures of paper Table III.
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <array>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::paper::detail {

// The undirected edges of a triangle mesh with their pattern lengths and the
// triangle-edge incidence. Validates the topology; every message starts with
// `who` (e.g. "isometry"). Throws std::invalid_argument on an index out of
// range, a repeated vertex, a non-finite pattern coordinate, a fixed vertex
// out of range or a zero-length pattern edge.
struct PatternEdges {
  int n = 0;
  std::vector<int> fixed;                       // sorted, unique
  std::vector<std::array<int, 2>> edges;        // (i, j), i < j, sorted
  std::vector<double> restLength;               // lbar_e (m)
  std::vector<std::array<int, 3>> triEdges;     // edges ab, bc, ca of each triangle
  std::vector<std::array<double, 3>> triSigns;  // +1 when the triangle walks the edge i -> j

  PatternEdges(const std::vector<Vec2>& pattern, const std::vector<std::array<int, 3>>& triangles,
               std::vector<int> fixedVertices, const char* who);

  // Throws NumericalError (stage) on a position count other than n or a
  // non-finite position (naming the vertex).
  void checkPositions(const std::vector<Vec3>& positions, const char* stage) const;
  // c_mean and max over edges of |l - lbar| / lbar (paper Table III).
  void lengthErrors(const std::vector<Vec3>& p, double& mean, double& max) const;
};

// d_m: the mean distance between a and b (paper Table III).
double meanDisplacement(const std::vector<Vec3>& a, const std::vector<Vec3>& b);

// min 1/2 sum_e w_e |(p_j - p_i) - t_e|^2 over the free vertices (paper eq.
// (7) with w_e = 1; Shape-Up's global step): the normal equations are the
// w-weighted graph Laplacian on the free vertices, handles moved to the
// right-hand side; it depends on the topology only and is factored once
// (SimplicialLLT). A connected component without a fixed vertex pins its
// lowest vertex and is translated back to its input centroid after the solve.
class EdgeFitSolver {
 public:
  // `weights`: one per edge, > 0; empty means all 1. Error messages name
  // `stage` and start with `label` (e.g. "Phase II"). Throws NumericalError
  // when the factorisation fails.
  EdgeFitSolver(const PatternEdges& graph, std::vector<double> weights, const char* stage,
                const char* label);
  // `weightedTargets`: w_e t_e per edge. Pinned vertices keep their `input`
  // positions. Throws NumericalError on a failed solve or a non-finite result.
  std::vector<Vec3> solve(const std::vector<Vec3>& input,
                          const std::vector<Vec3>& weightedTargets) const;

 private:
  int n_ = 0;
  std::vector<std::array<int, 2>> edges_;
  const char* stage_;
  const char* label_;
  std::vector<double> weights_;
  std::vector<int> freeIndex_;  // -1 for a pinned vertex (fixed or component anchor)
  std::vector<std::vector<int>> floatingComponents_;  // components without a fixed vertex
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> factor_;
  int freeCount_ = 0;
};

}  // namespace crumple::paper::detail
