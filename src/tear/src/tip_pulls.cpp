#include "crumple/tear/tip_pulls.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "crumple/tear/candidates.hpp"

namespace crumple::tear {

namespace {

using Mat32 = Eigen::Matrix<double, 3, 2>;

// The deformation gradient of triangle t: dx = F dX.
Mat32 deformationGradient(const mesh::SheetMesh& m, int t) {
  const auto& tri = m.triangles[static_cast<std::size_t>(t)];
  const auto p = [&](int k) {
    return m.pattern[static_cast<std::size_t>(tri[static_cast<std::size_t>(k)])];
  };
  const auto x = [&](int k) {
    return m.positions[static_cast<std::size_t>(tri[static_cast<std::size_t>(k)])];
  };
  Mat2 dX;
  dX.col(0) = p(1) - p(0);
  dX.col(1) = p(2) - p(0);
  Mat32 dx;
  dx.col(0) = x(1) - x(0);
  dx.col(1) = x(2) - x(0);
  return dx * dX.inverse();
}

}  // namespace

Vec2 boundaryBisector(const mesh::SheetMesh& mesh, int vertex) {
  for (const auto& loop : boundaryLoops(mesh)) {
    const std::size_t n = loop.size();
    for (std::size_t i = 0; i < n; ++i) {
      if (loop[i] != vertex) continue;
      const Vec2& here = mesh.pattern[static_cast<std::size_t>(vertex)];
      const Vec2 back =
          (mesh.pattern[static_cast<std::size_t>(loop[(i + n - 1) % n])] - here).normalized();
      const Vec2 ahead =
          (mesh.pattern[static_cast<std::size_t>(loop[(i + 1) % n])] - here).normalized();
      // The sheet lies left of the loop: between `ahead` and `back`, turning
      // counter-clockwise from `ahead`.
      double angle = std::atan2(ahead.x() * back.y() - ahead.y() * back.x(), ahead.dot(back));
      if (angle <= 0.0) angle += 2.0 * std::numbers::pi;
      const double half = 0.5 * angle;
      return Vec2(std::cos(half) * ahead.x() - std::sin(half) * ahead.y(),
                  std::sin(half) * ahead.x() + std::cos(half) * ahead.y());
    }
  }
  throw std::invalid_argument("boundaryBisector: vertex " + std::to_string(vertex) +
                              " is not on the boundary");
}

TipPulls tipPulls(const mesh::SheetMesh& mesh, int vertex, const std::vector<TriangleForce>& forces,
                  const Vec2& tearDirection) {
  if (forces.empty()) throw std::invalid_argument("tipPulls: no forces");
  if (!(tearDirection.norm() > 0.0)) throw std::invalid_argument("tipPulls: zero tear direction");
  TipPulls out;
  out.tearDirection = tearDirection.normalized();
  Vec3 normal = Vec3::Zero(), direction3 = Vec3::Zero();
  std::vector<Vec3> f3;
  for (const TriangleForce& f : forces) {
    const auto& tri = mesh.triangles.at(static_cast<std::size_t>(f.triangle));
    if (tri[0] != vertex && tri[1] != vertex && tri[2] != vertex)
      throw std::invalid_argument("tipPulls: triangle " + std::to_string(f.triangle) +
                                  " does not hold the vertex");
    const Vec3& a = mesh.positions[static_cast<std::size_t>(tri[0])];
    normal += (mesh.positions[static_cast<std::size_t>(tri[1])] - a)
                  .cross(mesh.positions[static_cast<std::size_t>(tri[2])] - a);
    direction3 += deformationGradient(mesh, f.triangle) * out.tearDirection;
    f3.push_back(f.force);
  }
  out.clusters = clusterTipForces(f3, normal, direction3);
  // Each force to the pattern through its own triangle, summed by the side
  // the 3D clustering put it on.
  for (std::size_t k = 0; k < forces.size(); ++k) {
    const Mat32 F = deformationGradient(mesh, forces[k].triangle);
    const Vec2 mapped = (F.transpose() * F).ldlt().solve(F.transpose() * forces[k].force);
    if (out.clusters.side[k] > 0) out.left += mapped;
    if (out.clusters.side[k] < 0) out.right += mapped;
  }
  return out;
}

}  // namespace crumple::tear
