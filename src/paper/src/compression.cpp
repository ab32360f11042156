#include "crumple/paper/compression.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>

namespace crumple::paper {

// thesis 2.4.2: F maps pattern edge vectors to 3D edge vectors expressed in
// the triangle's own plane; U = (F^T F)^(1/2) has the principal stretches as
// eigenvalues and the principal directions (in the pattern) as eigenvectors.
TriangleCompression analyzeCompression(const std::array<Vec2, 3>& pattern,
                                       const std::array<Vec3, 3>& position) {
  Eigen::Matrix2d rest;
  rest.col(0) = pattern[1] - pattern[0];
  rest.col(1) = pattern[2] - pattern[0];
  const double det = rest.determinant();
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) {
    throw std::invalid_argument("analyzeCompression: degenerate pattern triangle");
  }
  const Vec3 e0 = position[1] - position[0];
  const Vec3 e1 = position[2] - position[0];
  // F^T F = rest^-T G rest^-1 with the 3D Gram matrix G: no local frame needed.
  Eigen::Matrix2d gram;
  gram << e0.dot(e0), e0.dot(e1), e0.dot(e1), e1.dot(e1);
  const Eigen::Matrix2d restInv = rest.inverse();
  const Eigen::Matrix2d c = restInv.transpose() * gram * restInv;  // right Cauchy-Green F^T F
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(c);
  TriangleCompression out;
  out.lambdaMin = std::sqrt(std::max(eig.eigenvalues()(0), 0.0));
  out.lambdaMax = std::sqrt(std::max(eig.eigenvalues()(1), 0.0));
  out.v = eig.eigenvectors().col(0).normalized();
  // Canonical sign so the result does not depend on the solver's choice.
  if (out.v.x() < 0.0 || (out.v.x() == 0.0 && out.v.y() < 0.0)) out.v = -out.v;
  out.vPerp = Vec2(-out.v.y(), out.v.x());
  return out;
}

double edgeCompression(const Vec2& patternA, const Vec2& patternB, const Vec3& a, const Vec3& b) {
  const double rest = (patternB - patternA).norm();
  return (rest - (b - a).norm()) / rest;
}

}  // namespace crumple::paper
