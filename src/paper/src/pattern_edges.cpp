// The pattern's edge graph and the edge-fit solve shared by the isometry
// projection (paper Sec. 6.3, eq. (7)) and the Shape-Up projection (paper
// Table III). See pattern_edges.hpp.
#include "pattern_edges.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

#include "crumple/core/error.hpp"

namespace crumple::paper::detail {

PatternEdges::PatternEdges(const std::vector<Vec2>& pattern,
                           const std::vector<std::array<int, 3>>& triangles,
                           std::vector<int> fixedVertices, const char* who)
    : n(static_cast<int>(pattern.size())), fixed(std::move(fixedVertices)) {
  const std::string prefix = std::string(who) + ": ";
  for (const Vec2& p : pattern) {
    if (!p.allFinite()) throw std::invalid_argument(prefix + "non-finite pattern coordinate");
  }
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      if (t[k] < 0 || t[k] >= n) throw std::invalid_argument(prefix + "vertex index out of range");
    }
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
      throw std::invalid_argument(prefix + "triangle with a repeated vertex");
    }
  }
  std::sort(fixed.begin(), fixed.end());
  fixed.erase(std::unique(fixed.begin(), fixed.end()), fixed.end());
  for (int v : fixed) {
    if (v < 0 || v >= n) throw std::invalid_argument(prefix + "fixed vertex out of range");
  }

  // Undirected edges, each oriented from the lower to the higher index.
  std::vector<std::array<int, 2>> all;
  all.reserve(3 * triangles.size());
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      all.push_back({std::min(a, b), std::max(a, b)});
    }
  }
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  edges = std::move(all);
  auto edgeIndex = [&](int a, int b) {
    const std::array<int, 2> key{std::min(a, b), std::max(a, b)};
    return static_cast<int>(std::lower_bound(edges.begin(), edges.end(), key) - edges.begin());
  };
  restLength.resize(edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e) {
    restLength[e] = (pattern[edges[e][1]] - pattern[edges[e][0]]).norm();
    if (!(restLength[e] > 0.0)) {
      throw std::invalid_argument(prefix + "zero-length pattern edge (" +
                                  std::to_string(edges[e][0]) + ", " + std::to_string(edges[e][1]) +
                                  ")");
    }
  }
  triEdges.resize(triangles.size());
  triSigns.resize(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = triangles[t][k], b = triangles[t][(k + 1) % 3];
      triEdges[t][k] = edgeIndex(a, b);
      triSigns[t][k] = a < b ? 1.0 : -1.0;
    }
  }
}

void PatternEdges::checkPositions(const std::vector<Vec3>& positions, const char* stage) const {
  if (static_cast<int>(positions.size()) != n) {
    throw NumericalError(stage, "expected " + std::to_string(n) + " positions, got " +
                                    std::to_string(positions.size()));
  }
  for (int v = 0; v < n; ++v) {
    if (!positions[v].allFinite()) {
      throw NumericalError(stage, "non-finite input position at vertex " + std::to_string(v));
    }
  }
}

void PatternEdges::lengthErrors(const std::vector<Vec3>& p, double& mean, double& max) const {
  mean = 0.0;
  max = 0.0;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const double l = (p[edges[e][1]] - p[edges[e][0]]).norm();
    const double err = std::abs(l - restLength[e]) / restLength[e];
    mean += err;
    max = std::max(max, err);
  }
  if (!edges.empty()) mean /= static_cast<double>(edges.size());
}

double meanDisplacement(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double disp = 0.0;
  for (std::size_t v = 0; v < a.size(); ++v) disp += (a[v] - b[v]).norm();
  return a.empty() ? 0.0 : disp / static_cast<double>(a.size());
}

// Connected components, the free-vertex numbering and the w-weighted graph
// Laplacian on the free vertices (the normal equations of eq. (7)).
EdgeFitSolver::EdgeFitSolver(const PatternEdges& graph, std::vector<double> weights,
                             const char* stage, const char* label)
    : n_(graph.n), edges_(graph.edges), stage_(stage), label_(label), weights_(std::move(weights)) {
  const int n = n_;
  // Connected components (union-find, deterministic: the root is the lowest index).
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const auto& e : edges_) {
    const int ra = find(e[0]), rb = find(e[1]);
    if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
  }
  std::vector<char> anchored(n, 0);
  for (int v : graph.fixed) anchored[find(v)] = 1;
  freeIndex_.assign(n, 0);
  for (int v : graph.fixed) freeIndex_[v] = -1;
  std::vector<int> componentSlot(n, -1);
  for (int v = 0; v < n; ++v) {
    const int r = find(v);
    if (anchored[r]) continue;
    if (r == v) {
      // The lowest vertex of a component without a fixed vertex is pinned;
      // solve() then translates the component back to its input centroid.
      freeIndex_[v] = -1;
      componentSlot[v] = static_cast<int>(floatingComponents_.size());
      floatingComponents_.emplace_back();
    }
    floatingComponents_[componentSlot[r]].push_back(v);
  }
  freeCount_ = 0;
  for (int v = 0; v < n; ++v) {
    if (freeIndex_[v] >= 0) freeIndex_[v] = freeCount_++;
  }

  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(4 * edges_.size());
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    const double w = weights_.empty() ? 1.0 : weights_[e];
    const int fa = freeIndex_[edges_[e][0]], fb = freeIndex_[edges_[e][1]];
    if (fa >= 0) trip.emplace_back(fa, fa, w);
    if (fb >= 0) trip.emplace_back(fb, fb, w);
    if (fa >= 0 && fb >= 0) {
      trip.emplace_back(fa, fb, -w);
      trip.emplace_back(fb, fa, -w);
    }
  }
  Eigen::SparseMatrix<double> laplacian(freeCount_, freeCount_);
  laplacian.setFromTriplets(trip.begin(), trip.end());
  if (freeCount_ > 0) {
    factor_.compute(laplacian);
    if (factor_.info() != Eigen::Success) {
      throw NumericalError(stage_, std::string(label_) + " Laplacian factorisation failed");
    }
  }
}

// min 1/2 sum_e w_e |(p_j - p_i) - t_e|^2 over the free vertices; fixed and
// anchor vertices keep their `input` positions and move to the right-hand
// side. x, y, z share the factor.
std::vector<Vec3> EdgeFitSolver::solve(const std::vector<Vec3>& input,
                                       const std::vector<Vec3>& weightedTargets) const {
  std::vector<Vec3> out = input;
  if (freeCount_ > 0) {
    Eigen::MatrixX3d rhs = Eigen::MatrixX3d::Zero(freeCount_, 3);
    for (std::size_t e = 0; e < edges_.size(); ++e) {
      const int i = edges_[e][0], j = edges_[e][1];
      const Vec3& w = weightedTargets[e];
      const int fi = freeIndex_[i], fj = freeIndex_[j];
      if (fj >= 0) rhs.row(fj) += w.transpose();
      if (fi >= 0) rhs.row(fi) -= w.transpose();
      if (weights_.empty()) {
        if (fi >= 0 && fj < 0) rhs.row(fi) += input[j].transpose();
        if (fj >= 0 && fi < 0) rhs.row(fj) += input[i].transpose();
      } else {
        if (fi >= 0 && fj < 0) rhs.row(fi) += (weights_[e] * input[j]).transpose();
        if (fj >= 0 && fi < 0) rhs.row(fj) += (weights_[e] * input[i]).transpose();
      }
    }
    Eigen::MatrixX3d x(freeCount_, 3);
    for (int c = 0; c < 3; ++c) x.col(c) = factor_.solve(rhs.col(c));
    if (factor_.info() != Eigen::Success)
      throw NumericalError(stage_, std::string(label_) + " solve failed");
    for (int v = 0; v < n_; ++v) {
      if (freeIndex_[v] >= 0) out[v] = x.row(freeIndex_[v]).transpose();
    }
  }
  for (const auto& comp : floatingComponents_) {
    Vec3 shift = Vec3::Zero();
    for (int v : comp) shift += input[v] - out[v];
    shift /= static_cast<double>(comp.size());
    for (int v : comp) out[v] += shift;
  }
  for (int v = 0; v < n_; ++v) {
    if (!out[v].allFinite()) {
      throw NumericalError(
          stage_,
          std::string(label_) + " produced a non-finite position at vertex " + std::to_string(v));
    }
  }
  return out;
}

}  // namespace crumple::paper::detail
