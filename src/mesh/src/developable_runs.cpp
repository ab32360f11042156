// The S_G faces of the curved regions, the sheet's boundary curves and the
// runs of faces the refinement folds (developable.hpp).
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "crumple/core/index.hpp"
#include "developable_detail.hpp"

namespace crumple::mesh {

std::string validate(const DevelopableStructure& structure, const SheetMesh& mesh) {
  const auto nv = static_cast<int>(mesh.vertexCount());
  for (std::size_t r = 0; r < structure.regions.size(); ++r) {
    const CurvedRegion& region = structure.regions[r];
    const std::string where = "curved region " + std::to_string(r);
    if (!inRange(mesh.regionTypes, region.region))
      return where + ": region id " + std::to_string(region.region) + " out of range";
    if (mesh.regionTypes[idx(region.region)] != RegionType::Curved)
      return where + ": region " + std::to_string(region.region) + " is not curved";
    if (region.apex < -1 || region.apex >= nv) return where + ": apex out of range";
    if (region.rulings.size() < 2) return where + ": fewer than two rulings";
    for (const auto& [a, b] : region.rulings) {
      if (a < 0 || a >= nv || b < 0 || b >= nv) return where + ": a ruling end out of range";
      if (a == b) return where + ": a ruling from a vertex to itself";
    }
  }
  return "";
}

namespace developable {

namespace {

double cross2(const Vec2& u, const Vec2& v) { return u.x() * v.y() - u.y() * v.x(); }

// Signed pattern area of a polygon (> 0 counter-clockwise).
double polygonArea(std::span<const Vec2> p) {
  double a = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) a += cross2(p[i], p[(i + 1) % p.size()]);
  return 0.5 * a;
}

// Whether q lies inside the convex polygon p of the given orientation.
bool insideConvex(std::span<const Vec2> p, double orientation, const Vec2& q) {
  for (std::size_t i = 0; i < p.size(); ++i)
    if (orientation * cross2(p[(i + 1) % p.size()] - p[i], q - p[i]) <= 0.0) return false;
  return true;
}

}  // namespace

std::vector<std::vector<int>> trianglesOfVertices(const SheetMesh& sheet) {
  std::vector<std::vector<int>> out(sheet.vertexCount());
  for (std::size_t t = 0; t < sheet.triangles.size(); ++t)
    for (int v : sheet.triangles[t]) out[idx(v)].push_back(static_cast<int>(t));
  return out;
}

// Each boundary loop (boundaryLoops: the sheet on its left) sampled at its
// vertices in its pattern arc length, breaks (C0) at the outline's corners,
// where the region beside it changes and at `breakVertex` (paper Sec. 6.2;
// the corners as the crumpling model's own boundary curve has them). A
// boundary that is not a set of simple loops (two loops touching at a
// vertex) gets no curves: every side stays straight.
BoundaryCurves::BoundaryCurves(const SheetMesh& sheet, std::span<const char> breakVertex) {
  std::vector<std::vector<int>> loops;
  try {
    loops = boundaryLoops(sheet);
  } catch (const std::invalid_argument&) {
    return;
  }
  std::map<std::pair<int, int>, int> regionOf;  // directed edge -> region of its triangle
  for (std::size_t t = 0; t < sheet.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      regionOf[{sheet.triangles[t][idx(k)], sheet.triangles[t][idx((k + 1) % 3)]}] =
          sheet.regionOfTriangle[t];
  for (const std::vector<int>& loop : loops) {
    const std::size_t n = loop.size();
    if (n < 3) continue;
    std::vector<BoundarySample> samples;
    std::vector<double> breaks;
    double s = 0.0;
    const int id = static_cast<int>(curves_.size());
    std::vector<std::pair<std::pair<int, int>, EdgeOnLoop>> edges;
    for (std::size_t i = 0; i < n; ++i) {
      const int v = loop[i], w = loop[(i + 1) % n], u = loop[(i + n - 1) % n];
      const Vec2 din = sheet.pattern[idx(v)] - sheet.pattern[idx(u)];
      const Vec2 dout = sheet.pattern[idx(w)] - sheet.pattern[idx(v)];
      const double turn = std::atan2(cross2(din, dout), din.dot(dout));
      if (std::abs(turn) > 1e-6 || breakVertex[idx(v)] != 0 || regionOf[{u, v}] != regionOf[{v, w}])
        breaks.push_back(s);
      samples.push_back({s, sheet.positions[idx(v)]});
      const double length = dout.norm();
      edges.push_back({{v, w}, {id, s, length}});
      s += length;
    }
    if (!(s > 0.0)) continue;
    curves_.emplace_back(std::move(samples), s, breaks);
    edges_.insert(edges.begin(), edges.end());
  }
}

bool BoundaryCurves::isBoundaryEdge(int a, int b) const {
  return edges_.contains({a, b}) || edges_.contains({b, a});
}

Vec3 BoundaryCurves::sidePoint(const SheetMesh& sheet, int a, int b, double t) const {
  const Vec3& xa = sheet.positions[idx(a)];
  const Vec3& xb = sheet.positions[idx(b)];
  if (t <= 0.0) return xa;
  if (t >= 1.0) return xb;
  if (auto it = edges_.find({a, b}); it != edges_.end() && it->second.loop < std::ssize(curves_))
    return curves_[idx(it->second.loop)].evaluate(it->second.s0 + t * it->second.length);
  if (auto it = edges_.find({b, a}); it != edges_.end() && it->second.loop < std::ssize(curves_))
    return curves_[idx(it->second.loop)].evaluate(it->second.s0 + (1.0 - t) * it->second.length);
  return (1.0 - t) * xa + t * xb;
}

namespace {

// The source triangles of face f among its region's: those whose pattern
// centroid lies in the face. A quad must hold S_P's four triangles around
// its barycentre vertex, a fan its one triangle (paper Sec. 4, "curved-region
// quads are split at their barycenter").
bool findTriangles(const SheetMesh& sheet, const std::vector<int>& regionTriangles,
                   std::span<const Vec2> polygon, std::span<const int> corners, Face& f) {
  for (int t : regionTriangles) {
    const auto& tri = sheet.triangles[idx(t)];
    const Vec2 c =
        (sheet.pattern[idx(tri[0])] + sheet.pattern[idx(tri[1])] + sheet.pattern[idx(tri[2])]) /
        3.0;
    if (insideConvex(polygon, f.orientation, c)) f.triangles.push_back(t);
  }
  const auto isCorner = [&](int v) { return std::ranges::find(corners, v) != corners.end(); };
  if (corners.size() == 3) {
    if (f.triangles.size() != 1) return false;
    return std::ranges::all_of(sheet.triangles[idx(f.triangles[0])], isCorner);
  }
  if (f.triangles.size() != 4) return false;
  int centre = -1;
  for (int t : f.triangles)
    for (int v : sheet.triangles[idx(t)]) {
      if (isCorner(v)) continue;
      if (centre >= 0 && centre != v) return false;
      centre = v;
    }
  return centre >= 0;
}

}  // namespace

std::vector<Face> regionFaces(const SheetMesh& sheet, const CurvedRegion& region,
                              const std::vector<int>& regionTriangles,
                              const BoundaryCurves& boundary,
                              std::span<const char> lockedTriangle) {
  std::vector<Face> faces;
  for (std::size_t k = 0; k + 1 < region.rulings.size(); ++k) {
    Face f;
    f.r0 = region.rulings[k];
    f.r1 = region.rulings[k + 1];
    const auto [a0, b0] = f.r0;
    const auto [a1, b1] = f.r1;
    if (a0 == a1 && b0 == b1) {
      faces.push_back(f);  // two equal rulings: no face, a border
      continue;
    }
    f.fanSide = a0 == a1 ? 0 : b0 == b1 ? 1 : -1;
    std::vector<int> corners;
    for (int v : {a0, a1, b1, b0})
      if (std::ranges::find(corners, v) == corners.end()) corners.push_back(v);
    std::vector<Vec2> polygon;
    for (int v : corners) polygon.push_back(sheet.pattern[idx(v)]);
    const double area = polygonArea(polygon);
    // A quad whose sides cross, or a corner shared across the face, is no S_G face.
    const bool shapeOk = corners.size() == (f.fanSide < 0 ? 4u : 3u) && std::abs(area) > 1e-14;
    f.orientation = area >= 0.0 ? 1.0 : -1.0;
    if (!shapeOk || !findTriangles(sheet, regionTriangles, polygon, corners, f)) {
      faces.push_back(f);
      continue;
    }
    const bool sideA = f.fanSide == 0 || boundary.isBoundaryEdge(a0, a1);
    const bool sideB = f.fanSide == 1 || boundary.isBoundaryEdge(b0, b1);
    const bool locked =
        std::ranges::any_of(f.triangles, [&](int t) { return lockedTriangle[idx(t)] != 0; });
    f.refinable = sideA && sideB && !locked;
    faces.push_back(std::move(f));
  }
  return faces;
}

std::vector<Run> regionRuns(const std::vector<Face>& faces,
                            const std::vector<std::vector<int>>& trianglesOfVertex,
                            std::span<const char> pinnedVertex) {
  // Whether ruling k (between faces k - 1 and k) may move: both faces
  // refinable and of one kind, its free ends used by those faces only.
  const auto movable = [&](std::size_t k) {
    const Face& before = faces[k - 1];
    const Face& after = faces[k];
    if (!before.refinable || !after.refinable || before.fanSide != after.fanSide) return false;
    for (int side = 0; side < 2; ++side) {
      if (side == before.fanSide) continue;  // the apex stays where it is
      const int v = after.r0[idx(side)];
      if (pinnedVertex[idx(v)] != 0) return false;
      for (int t : trianglesOfVertex[idx(v)])
        if (std::ranges::find(before.triangles, t) == before.triangles.end() &&
            std::ranges::find(after.triangles, t) == after.triangles.end())
          return false;
    }
    return true;
  };
  std::vector<Run> runs;
  Run current;
  const auto close = [&] {
    if (current.faces.size() >= 2) runs.push_back(std::move(current));
    current = Run{};
  };
  for (std::size_t k = 0; k < faces.size(); ++k) {
    if (!faces[k].refinable) {
      close();
      continue;
    }
    if (k > 0 && !current.faces.empty() && !movable(k)) close();
    current.faces.push_back(faces[k]);
  }
  close();
  return runs;
}

}  // namespace developable
}  // namespace crumple::mesh
