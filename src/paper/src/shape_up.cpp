// Shape-Up projection with hard constraints (paper Sec. 7.2, Table III;
// Bouaziz et al. 2012). See shape_up.hpp for the scheme.
#include "crumple/paper/shape_up.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "crumple/core/error.hpp"
#include "pattern_edges.hpp"

namespace crumple::paper {

namespace {

constexpr const char* kStage = "shape-up";

// The polar factor U V^T of a 3x2 matrix M = U S V^T: the 3x2 matrix with
// orthonormal columns nearest to M. Closed form R = M (M^T M)^{-1/2}, the
// 2x2 square root as sqrt(A) = (A + sqrt(det A) I) / sqrt(tr A + 2 sqrt(det
// A)); the SVD when M is (nearly) rank-deficient (a collapsed triangle).
Eigen::Matrix<double, 3, 2> polarFactor(const Eigen::Matrix<double, 3, 2>& m) {
  const Mat2 a = m.transpose() * m;
  const double det = a.determinant(), tr = a.trace();
  if (det > 1e-12 * tr * tr) {
    const double s = std::sqrt(det);
    const Mat2 root = (a + s * Mat2::Identity()) / std::sqrt(tr + 2.0 * s);
    return m * root.inverse();
  }
  const Eigen::JacobiSVD<Eigen::Matrix<double, 3, 2>> svd(
      m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU().leftCols<2>() * svd.matrixV().transpose();
}

}  // namespace

struct ShapeUpProjector::Impl {
  std::vector<Vec2> pattern;
  std::vector<std::array<int, 3>> triangles;
  std::optional<detail::PatternEdges> graph;
  // Per triangle: its pattern vertices centred on their centroid, and the
  // sum of its squared pattern edge lengths (the residual's scale).
  std::vector<std::array<Vec2, 3>> centredPattern;
  std::vector<double> edgeScale;
  // Global step: the edge fit weighted by each edge's triangle count.
  std::optional<detail::EdgeFitSolver> solver;
  ShapeUpOptions options;

  // Shape-Up's local step at `p`: the best-fit rigid image of every pattern
  // triangle, accumulated per edge as the global step's weighted targets.
  // Returns the energy sum_t sum_k |e_k - R_t ebar_k|^2; `maxResidual` gets
  // the largest relative triangle residual.
  double localStep(const std::vector<Vec3>& p, std::vector<Vec3>& targets,
                   double& maxResidual) const;
};

double ShapeUpProjector::Impl::localStep(const std::vector<Vec3>& p, std::vector<Vec3>& targets,
                                         double& maxResidual) const {
  const detail::PatternEdges& g = *graph;
  for (Vec3& t : targets) t.setZero();
  maxResidual = 0.0;
  double energy = 0.0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    const auto& q = centredPattern[t];
    const Vec3 xc = (p[tri[0]] + p[tri[1]] + p[tri[2]]) / 3.0;
    // Cross-covariance of the centred current and pattern vertices; its
    // polar factor U V^T is the nearest 3x2 rotation (Procrustes).
    Eigen::Matrix<double, 3, 2> cov = Eigen::Matrix<double, 3, 2>::Zero();
    for (int k = 0; k < 3; ++k) cov += (p[tri[k]] - xc) * q[k].transpose();
    const Eigen::Matrix<double, 3, 2> rot = polarFactor(cov);
    double residual = 0.0;
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      const Vec3 target = rot * (q[(k + 1) % 3] - q[k]);  // R_t (q_b - q_a)
      residual += ((p[b] - p[a]) - target).squaredNorm();
      // Edges are stored i < j: the target enters with the walk's sign.
      targets[g.triEdges[t][k]] += g.triSigns[t][k] * target;
    }
    energy += residual;
    maxResidual = std::max(maxResidual, std::sqrt(residual / edgeScale[t]));
  }
  return energy;
}

double meanLengthError(const std::vector<Vec2>& pattern,
                       const std::vector<std::array<int, 3>>& triangles,
                       const std::vector<Vec3>& positions) {
  const detail::PatternEdges graph(pattern, triangles, {}, "c_mean");
  graph.checkPositions(positions, "c_mean");
  double mean = 0.0, max = 0.0;
  graph.lengthErrors(positions, mean, max);
  return mean;
}

ShapeUpProjector::ShapeUpProjector(std::vector<Vec2> pattern,
                                   std::vector<std::array<int, 3>> triangles,
                                   std::vector<int> fixedVertices, ShapeUpOptions options)
    : impl_(std::make_unique<Impl>()) {
  Impl& im = *impl_;
  if (options.maxIterations < 0) throw std::invalid_argument("shape-up: negative maxIterations");
  if (!(options.tolerance > 0.0)) throw std::invalid_argument("shape-up: tolerance must be > 0");
  if (!(options.stallTolerance >= 0.0))
    throw std::invalid_argument("shape-up: stallTolerance must be >= 0");
  if (!(options.meanLengthTolerance >= 0.0))
    throw std::invalid_argument("shape-up: meanLengthTolerance must be >= 0");
  im.options = options;
  im.pattern = std::move(pattern);
  im.triangles = std::move(triangles);
  im.graph.emplace(im.pattern, im.triangles, std::move(fixedVertices), kStage);
  im.centredPattern.resize(im.triangles.size());
  im.edgeScale.resize(im.triangles.size());
  std::vector<double> weights(im.graph->edges.size(), 0.0);
  for (std::size_t t = 0; t < im.triangles.size(); ++t) {
    const auto& tri = im.triangles[t];
    const Vec2 c = (im.pattern[tri[0]] + im.pattern[tri[1]] + im.pattern[tri[2]]) / 3.0;
    double scale = 0.0;
    for (int k = 0; k < 3; ++k) {
      im.centredPattern[t][k] = im.pattern[tri[k]] - c;
      scale += (im.pattern[tri[(k + 1) % 3]] - im.pattern[tri[k]]).squaredNorm();
      weights[im.graph->triEdges[t][k]] += 1.0;
    }
    im.edgeScale[t] = scale;
  }
  im.solver.emplace(*im.graph, std::move(weights), kStage, "global step");
}

ShapeUpProjector::~ShapeUpProjector() = default;
ShapeUpProjector::ShapeUpProjector(ShapeUpProjector&&) noexcept = default;
ShapeUpProjector& ShapeUpProjector::operator=(ShapeUpProjector&&) noexcept = default;

int ShapeUpProjector::vertexCount() const { return impl_->graph->n; }
int ShapeUpProjector::edgeCount() const { return static_cast<int>(impl_->graph->edges.size()); }

// Shape-Up's local/global iteration without the closeness term: local step
// (rigid projection of every triangle), global step (edge fit, handles hard),
// until every triangle is within tolerance (or c_mean within meanLengthTolerance),
// the energy stalls or the cap.
ShapeUpStats ShapeUpProjector::project(std::vector<Vec3>& positions) const {
  const Impl& im = *impl_;
  const detail::PatternEdges& g = *im.graph;
  g.checkPositions(positions, kStage);
  ShapeUpStats stats;
  double dummy = 0.0;
  g.lengthErrors(positions, stats.meanLengthErrorBefore, dummy);

  std::vector<Vec3> current = positions;
  std::vector<Vec3> targets(g.edges.size(), Vec3::Zero());
  double previousEnergy = 0.0;
  for (;;) {
    const double energy = im.localStep(current, targets, stats.maxTriangleResidual);
    if (!std::isfinite(energy))
      throw NumericalError(
          kStage, "non-finite energy after " + std::to_string(stats.iterations) + " iterations");
    if (stats.maxTriangleResidual < im.options.tolerance) {
      stats.converged = true;
      break;
    }
    if (im.options.meanLengthTolerance > 0.0) {
      g.lengthErrors(current, stats.meanLengthErrorAfter, stats.maxLengthErrorAfter);
      if (stats.meanLengthErrorAfter <= im.options.meanLengthTolerance) {
        stats.converged = true;
        break;
      }
    }
    if (stats.iterations > 0 &&
        previousEnergy - energy <= im.options.stallTolerance * previousEnergy)
      break;
    if (stats.iterations >= im.options.maxIterations) break;
    previousEnergy = energy;
    current = im.solver->solve(current, targets);
    ++stats.iterations;
  }

  g.lengthErrors(current, stats.meanLengthErrorAfter, stats.maxLengthErrorAfter);
  stats.meanDisplacement = detail::meanDisplacement(current, positions);
  positions = std::move(current);
  return stats;
}

}  // namespace crumple::paper
