#include "crumple/paper/initial_sheet.hpp"

#include <cmath>
#include <sstream>

#include "crumple/core/error.hpp"
#include "crumple/core/index.hpp"
#include "crumple/mesh/delaunay.hpp"

namespace crumple::paper {

InitialSheet makeFlatSheet(double width, double height, const std::vector<Vec2>& handlePoints,
                           const Vec3& origin, const Vec3& uAxis, const Vec3& vAxis) {
  InitialSheet out;
  GeometricMesh& g = out.mesh;
  g.outline = {Vec2(0.0, 0.0), Vec2(width, 0.0), Vec2(width, height), Vec2(0.0, height)};
  const double tol = 1e-9 * std::max(width, height);
  const auto place = [&](const Vec2& p) { return Vec3(origin + p.x() * uAxis + p.y() * vAxis); };
  for (int k = 0; k < 4; ++k) {
    GeometricVertex v;
    v.pattern = g.outline[idx(k)];
    v.position = place(v.pattern);
    v.onBoundary = true;
    v.corner = true;
    v.outlineSegment = k;
    addVertex(g, v);
  }
  for (const Vec2& p : handlePoints) {
    if (p.x() < -tol || p.y() < -tol || p.x() > width + tol || p.y() > height + tol) {
      std::ostringstream msg;
      msg << "handle point (" << p.x() << ", " << p.y() << ") m is outside the " << width << " x "
          << height << " m sheet";
      throw InputError(msg.str());
    }
    int found = -1;
    for (std::size_t v = 0; v < g.vertices.size(); ++v) {
      if ((g.vertices[v].pattern - p).norm() <= tol) found = static_cast<int>(v);
    }
    if (found < 0) {
      GeometricVertex v;
      v.pattern = p.cwiseMax(Vec2::Zero()).cwiseMin(Vec2(width, height));
      if (std::abs(v.pattern.y()) <= tol) {
        v.pattern.y() = 0.0, v.outlineSegment = 0;
      } else if (std::abs(v.pattern.x() - width) <= tol) {
        v.pattern.x() = width, v.outlineSegment = 1;
      } else if (std::abs(v.pattern.y() - height) <= tol) {
        v.pattern.y() = height, v.outlineSegment = 2;
      } else if (std::abs(v.pattern.x()) <= tol) {
        v.pattern.x() = 0.0, v.outlineSegment = 3;
      }
      v.onBoundary = v.outlineSegment >= 0;
      v.position = place(v.pattern);
      found = addVertex(g, v);
    }
    g.vertices[idx(found)].handle = true;
    out.handleVertices.push_back(found);
  }
  // One flat region: constrained Delaunay of the outline (split at boundary
  // handle vertices) with the interior handle vertices inside.
  std::vector<Vec2> points;
  for (const GeometricVertex& v : g.vertices) points.push_back(v.pattern);
  std::vector<std::pair<double, int>> boundary;
  for (std::size_t v = 0; v < g.vertices.size(); ++v) {
    if (g.vertices[v].onBoundary) {
      boundary.emplace_back(
          outlineParameter(g, g.vertices[v].pattern, g.vertices[v].outlineSegment),
          static_cast<int>(v));
    }
  }
  std::sort(boundary.begin(), boundary.end());
  std::vector<std::array<int, 2>> constraints;
  for (std::size_t k = 0; k < boundary.size(); ++k) {
    constraints.push_back({boundary[k].second, boundary[(k + 1) % boundary.size()].second});
  }
  Region flat;
  flat.type = mesh::RegionType::Flat;
  g.regions.push_back(flat);
  for (const auto& t : mesh::constrainedDelaunay(points, constraints)) {
    GeometricFace f;
    f.v = {t[0], t[1], t[2], -1};
    f.region = 0;
    g.faces.push_back(f);
  }
  return out;
}

}  // namespace crumple::paper
