// makePolygonSheet: a pattern of any simple outline, meshed like a flat
// region of S_P (boundary samples, a hexagonal interior lattice,
// constrained Delaunay; thesis 2.3.2).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "crumple/core/geometry2d.hpp"
#include "crumple/mesh/delaunay.hpp"
#include "crumple/mesh/sheet_mesh.hpp"

namespace crumple::mesh {

namespace {

bool insidePolygon(const Vec2& p, const std::vector<Vec2>& poly) {
  bool inside = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2 &a = poly[i], &b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

}  // namespace

SheetMesh makePolygonSheet(const std::vector<Vec2>& outline, double maxEdge) {
  if (outline.size() < 3) throw std::invalid_argument("makePolygonSheet: fewer than 3 points");
  if (!(maxEdge > 0.0)) throw std::invalid_argument("makePolygonSheet: maxEdge must be > 0");
  double area = 0.0;
  const std::size_t n = outline.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 &a = outline[i], &b = outline[(i + 1) % n];
    area += a.x() * b.y() - a.y() * b.x();
  }
  if (!(area > 0.0))
    throw std::invalid_argument("makePolygonSheet: the outline is not counter-clockwise");

  std::vector<Vec2> points;
  std::vector<std::array<int, 2>> constraints;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 &a = outline[i], &b = outline[(i + 1) % n];
    const int pieces = std::max(1, static_cast<int>(std::ceil((b - a).norm() / maxEdge - 1e-9)));
    for (int k = 0; k < pieces; ++k)
      points.push_back(a + (b - a) * (static_cast<double>(k) / pieces));
  }
  const int boundaryCount = static_cast<int>(points.size());
  for (int k = 0; k < boundaryCount; ++k) constraints.push_back({k, (k + 1) % boundaryCount});
  // The interior lattice: rows maxEdge * sqrt(3) / 2 apart, every other row
  // shifted by half a spacing; kept maxEdge / 2 from the outline.
  Vec2 lo = outline.front(), hi = outline.front();
  for (const Vec2& p : outline) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double row = maxEdge * std::sqrt(3.0) / 2.0;
  const int rows = static_cast<int>(std::ceil((hi.y() - lo.y()) / row));
  const int cols = static_cast<int>(std::ceil((hi.x() - lo.x()) / maxEdge)) + 1;
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i <= cols; ++i) {
      const Vec2 p(lo.x() + (i + (j % 2 == 1 ? 0.5 : 0.0)) * maxEdge, lo.y() + j * row);
      if (!insidePolygon(p, outline)) continue;
      double d = std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < n; ++k)
        d = std::min(d, distanceToSegment(p, outline[k], outline[(k + 1) % n]));
      if (d >= 0.5 * maxEdge) points.push_back(p);
    }
  SheetMesh m;
  m.pattern = points;
  m.positions.reserve(points.size());
  for (const Vec2& p : points) m.positions.emplace_back(p.x(), p.y(), 0.0);
  m.triangles = constrainedDelaunay(points, constraints);
  m.regionOfTriangle.assign(m.triangles.size(), 0);
  m.regionTypes = {RegionType::Flat};
  return m;
}

}  // namespace crumple::mesh
