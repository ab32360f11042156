// Silhouette turning angles of a drawn sheet (silhouette.hpp).
#include "crumple/pipeline/silhouette.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "crumple/core/index.hpp"

namespace crumple::pipeline {

SilhouetteTurning silhouetteTurning(const mesh::SheetMesh& sheet, const render::Camera& camera,
                                    double minSegmentPx) {
  const Mat3 toCamera = camera.rotation.toRotationMatrix().transpose();
  const double focal = 0.5 * camera.height / std::tan(0.5 * camera.yfov);
  const auto project = [&](int v) {
    const Vec3 c = toCamera * (sheet.positions[idx(v)] - camera.position);
    const double depth = std::max(-c.z(), 1e-9);
    return Vec2(focal * c.x() / depth, -focal * c.y() / depth);
  };
  const auto curved = [&](int t) {
    const int r = sheet.regionOfTriangle[idx(t)];
    return inRange(sheet.regionTypes, r) && sheet.regionTypes[idx(r)] == mesh::RegionType::Curved;
  };
  const auto facing = [&](int t) {
    const auto& tri = sheet.triangles[idx(t)];
    const Vec3& x0 = sheet.positions[idx(tri[0])];
    const Vec3 n = (sheet.positions[idx(tri[1])] - x0).cross(sheet.positions[idx(tri[2])] - x0);
    return n.dot(camera.position - x0) > 0.0;
  };
  std::map<std::pair<int, int>, std::vector<int>> edges;
  for (std::size_t t = 0; t < sheet.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = sheet.triangles[t][idx(k)], b = sheet.triangles[t][idx((k + 1) % 3)];
      edges[{std::min(a, b), std::max(a, b)}].push_back(static_cast<int>(t));
    }
  // Silhouette segments at each vertex: other end, on a curved triangle, a border edge.
  struct Segment {
    int other;
    bool curved, border;
  };
  std::map<int, std::vector<Segment>> at;
  for (const auto& [e, ts] : edges) {
    const bool border = ts.size() == 1;
    const bool contour = ts.size() == 2 && facing(ts[0]) != facing(ts[1]);
    if (!border && !contour) continue;
    const bool onCurved = std::ranges::any_of(ts, curved);
    at[e.first].push_back({e.second, onCurved, border});
    at[e.second].push_back({e.first, onCurved, border});
  }
  SilhouetteTurning out;
  for (const auto& [v, segments] : at) {
    // Ends, crossings, and where a contour meets the border (a corner of
    // the silhouette by nature) are no joints.
    if (segments.size() != 2 || segments[0].border != segments[1].border) continue;
    const auto [u, curvedU, borderU] = segments[0];
    const auto [w, curvedW, borderW] = segments[1];
    if (!curvedU && !curvedW) continue;
    if (borderU) {
      // A corner of the sheet's outline in the pattern is a corner in space too.
      const Vec2 a = sheet.pattern[idx(v)] - sheet.pattern[idx(u)];
      const Vec2 b = sheet.pattern[idx(w)] - sheet.pattern[idx(v)];
      if (std::abs(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b))) > 1e-6) continue;
    }
    if ((project(v) - project(u)).norm() < minSegmentPx ||
        (project(w) - project(v)).norm() < minSegmentPx)
      continue;
    const Vec3 in = sheet.positions[idx(v)] - sheet.positions[idx(u)];
    const Vec3 out3 = sheet.positions[idx(w)] - sheet.positions[idx(v)];
    const double turn = std::atan2(in.cross(out3).norm(), in.dot(out3));
    if (curvedU && curvedW) {
      out.curved = std::max(out.curved, turn);
      ++out.joints;
    } else {
      out.border = std::max(out.border, turn);
    }
  }
  return out;
}

}  // namespace crumple::pipeline
