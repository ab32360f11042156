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
  // The reach: the mean length of the edges at the vertex. The boundary's
  // directions are taken to the first loop vertices at least that far along
  // the loop, so that a short last piece of a tear's lips does not turn its
  // direction.
  double reach = 0.0;
  int edges = 0;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      if (t[static_cast<std::size_t>(k)] == vertex) {
        reach += (mesh.pattern[static_cast<std::size_t>(t[static_cast<std::size_t>((k + 1) % 3)])] -
                  mesh.pattern[static_cast<std::size_t>(vertex)])
                     .norm();
        ++edges;
      }
  reach = edges > 0 ? reach / edges : 0.0;
  for (const auto& loop : boundaryLoops(mesh)) {
    const std::size_t n = loop.size();
    for (std::size_t i = 0; i < n; ++i) {
      if (loop[i] != vertex) continue;
      const Vec2& here = mesh.pattern[static_cast<std::size_t>(vertex)];
      const auto along = [&](int step) {
        double walked = 0.0;
        std::size_t k = i;
        Vec2 at = here;
        for (std::size_t count = 1; count < n; ++count) {
          k = (k + n + static_cast<std::size_t>(step + static_cast<int>(n))) % n;
          const Vec2& next = mesh.pattern[static_cast<std::size_t>(loop[k])];
          walked += (next - at).norm();
          at = next;
          if (walked >= reach && (at - here).norm() > 0.0) break;
        }
        return (at - here).normalized();
      };
      const Vec2 back = along(-1);
      const Vec2 ahead = along(1);
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
  std::vector<Vec2> mapped;
  for (const TriangleForce& f : forces) {
    const auto& tri = mesh.triangles.at(static_cast<std::size_t>(f.triangle));
    if (tri[0] != vertex && tri[1] != vertex && tri[2] != vertex)
      throw std::invalid_argument("tipPulls: triangle " + std::to_string(f.triangle) +
                                  " does not hold the vertex");
    const Vec3& a = mesh.positions[static_cast<std::size_t>(tri[0])];
    normal += (mesh.positions[static_cast<std::size_t>(tri[1])] - a)
                  .cross(mesh.positions[static_cast<std::size_t>(tri[2])] - a);
    const Mat32 F = deformationGradient(mesh, f.triangle);
    direction3 += F * out.tearDirection;
    // Only the forces that draw the point back against the tear direction
    // are pulls (Roman's pulling points lie behind the tip): the material
    // ahead holds the point against them, and in equilibrium the forces of
    // all its triangles sum to zero, which would always make the two
    // clusters opposite (theta = pi, E_r = 0).
    const Vec2 g = (F.transpose() * F).ldlt().solve(F.transpose() * f.force);
    if (g.dot(out.tearDirection) >= 0.0) continue;
    f3.push_back(f.force);
    mapped.push_back(g);
  }
  if (f3.empty()) return out;
  out.clusters = clusterTipForces(f3, normal, direction3);
  // Each force to the pattern through its own triangle, summed by the side
  // the 3D clustering put it on.
  for (std::size_t k = 0; k < mapped.size(); ++k) {
    if (out.clusters.side[k] > 0) out.left += mapped[k];
    if (out.clusters.side[k] < 0) out.right += mapped[k];
  }
  return out;
}

}  // namespace crumple::tear
