#include "crumple/mesh/sheet_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "crumple/core/index.hpp"

namespace crumple::mesh {

namespace {

// Index of the point nearest to p (lowest index on ties; -1 for none).
template <typename Point>
int nearestPoint(const std::vector<Point>& points, const Point& p) {
  int best = -1;
  double bestD = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = (points[i] - p).squaredNorm();
    if (d < bestD) {
      bestD = d;
      best = static_cast<int>(i);
    }
  }
  return best;
}

}  // namespace

std::vector<MeshEdge> buildEdges(const SheetMesh& mesh) {
  struct HalfEdge {
    int a, b, tri, opp;
  };
  std::vector<HalfEdge> halves;
  halves.reserve(mesh.triangles.size() * 3);
  for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t) {
    const auto& tri = mesh.triangles[idx(t)];
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = tri[k];
      const int b = tri[(k + 1) % 3];
      const int opp = tri[(k + 2) % 3];
      halves.push_back({std::min(a, b), std::max(a, b), t, opp});
    }
  }
  std::sort(halves.begin(), halves.end(), [](const HalfEdge& x, const HalfEdge& y) {
    if (x.a != y.a) return x.a < y.a;
    if (x.b != y.b) return x.b < y.b;
    return x.tri < y.tri;
  });
  std::vector<MeshEdge> edges;
  edges.reserve(halves.size() / 2 + 1);
  for (std::size_t i = 0; i < halves.size();) {
    std::size_t j = i + 1;
    while (j < halves.size() && halves[j].a == halves[i].a && halves[j].b == halves[i].b) ++j;
    if (j - i > 2)
      throw std::invalid_argument("non-manifold edge (" + std::to_string(halves[i].a) + ", " +
                                  std::to_string(halves[i].b) + ")");
    MeshEdge e;
    e.v = {halves[i].a, halves[i].b};
    e.triangles = {halves[i].tri, j - i == 2 ? halves[i + 1].tri : -1};
    e.opposite = {halves[i].opp, j - i == 2 ? halves[i + 1].opp : -1};
    edges.push_back(e);
    i = j;
  }
  return edges;
}

SheetMesh makeRectangleSheet(double width, double height, double maxEdge) {
  if (!(width > 0.0) || !(height > 0.0) || !(maxEdge > 0.0) || !std::isfinite(width) ||
      !std::isfinite(height) || !std::isfinite(maxEdge))
    throw std::invalid_argument("rectangle sheet needs positive finite width, height and edge");
  const int nx = std::max(1, static_cast<int>(std::ceil(width / maxEdge - 1e-9)));
  const int ny = std::max(1, static_cast<int>(std::ceil(height / maxEdge - 1e-9)));
  SheetMesh m;
  const int corners = (nx + 1) * (ny + 1);
  m.pattern.reserve(idx(corners + nx * ny));
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.pattern.emplace_back(width * i / nx, height * j / ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      m.pattern.emplace_back(width * (i + 0.5) / nx, height * (j + 0.5) / ny);
  auto corner = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int c = corners + j * nx + i;
      const int a = corner(i, j), b = corner(i + 1, j), d = corner(i + 1, j + 1),
                e = corner(i, j + 1);
      m.triangles.push_back({a, b, c});
      m.triangles.push_back({b, d, c});
      m.triangles.push_back({d, e, c});
      m.triangles.push_back({e, a, c});
    }
  }
  m.positions.resize(m.pattern.size(), Vec3::Zero());
  m.regionOfTriangle.assign(m.triangles.size(), 0);
  m.regionTypes = {RegionType::Flat};
  placePattern(m, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
  return m;
}

void placePattern(SheetMesh& mesh, const Vec3& origin, const Vec3& uAxis, const Vec3& vAxis) {
  mesh.positions.resize(mesh.pattern.size());
  for (std::size_t i = 0; i < mesh.pattern.size(); ++i)
    mesh.positions[i] = origin + mesh.pattern[i].x() * uAxis + mesh.pattern[i].y() * vAxis;
}

int nearestPatternVertex(const SheetMesh& mesh, const Vec2& p) {
  return nearestPoint(mesh.pattern, p);
}

PatternLocation locatePattern(const SheetMesh& mesh, const Vec2& p) {
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& T = mesh.triangles[t];
    const Vec2 a = mesh.pattern[idx(T[0])];
    Mat2 d;
    d << mesh.pattern[idx(T[1])] - a, mesh.pattern[idx(T[2])] - a;
    if (!(std::abs(d.determinant()) > 0.0)) continue;
    const Vec2 l = d.inverse() * (p - a);
    constexpr double kOnBorder = 1e-12;  // relative: p on an edge is inside
    if (l(0) >= -kOnBorder && l(1) >= -kOnBorder && l(0) + l(1) <= 1.0 + kOnBorder)
      return {static_cast<int>(t), Vec3(1.0 - l(0) - l(1), l(0), l(1))};
  }
  return {};
}

int nearestVertex(const SheetMesh& mesh, const Vec3& p) { return nearestPoint(mesh.positions, p); }

std::vector<int> vertexNeighbours(const SheetMesh& mesh, int v) {
  std::vector<int> out;
  for (const auto& t : mesh.triangles) {
    for (std::size_t k = 0; k < 3; ++k) {
      if (t[k] != v) continue;
      out.push_back(t[(k + 1) % 3]);
      out.push_back(t[(k + 2) % 3]);
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::string validate(const SheetMesh& mesh) {
  const auto n = static_cast<int>(mesh.pattern.size());
  if (mesh.positions.size() != mesh.pattern.size()) return "positions and pattern sizes differ";
  if (mesh.regionOfTriangle.size() != mesh.triangles.size())
    return "region ids and triangle counts differ";
  for (std::size_t i = 0; i < mesh.pattern.size(); ++i)
    if (!mesh.pattern[i].allFinite() || !mesh.positions[i].allFinite())
      return "vertex " + std::to_string(i) + " is not finite";
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (int v : tri)
      if (v < 0 || v >= n) return "triangle " + std::to_string(t) + " has an out-of-range vertex";
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      return "triangle " + std::to_string(t) + " repeats a vertex";
    const Vec2 e1 = mesh.pattern[idx(tri[1])] - mesh.pattern[idx(tri[0])];
    const Vec2 e2 = mesh.pattern[idx(tri[2])] - mesh.pattern[idx(tri[0])];
    if (std::abs(e1.x() * e2.y() - e1.y() * e2.x()) <= 1e-18)
      return "triangle " + std::to_string(t) + " is degenerate in the pattern";
    const int r = mesh.regionOfTriangle[t];
    if (r < 0 || r >= static_cast<int>(mesh.regionTypes.size()))
      return "triangle " + std::to_string(t) + " has an unknown region";
  }
  return {};
}

void saveSheetMesh(StateWriter& w, const SheetMesh& m) {
  w.tag("MESH");
  w.vec2s(m.pattern);
  w.vec3s(m.positions);
  w.triangles(m.triangles);
  w.i32s(m.regionOfTriangle);
  w.count(m.regionTypes.size());
  for (auto t : m.regionTypes) w.u8(static_cast<std::uint8_t>(t));
}

SheetMesh restoreSheetMesh(StateReader& in) {
  in.tag("MESH");
  SheetMesh m;
  m.pattern = in.vec2s();
  m.positions = in.vec3s();
  m.triangles = in.triangles();
  m.regionOfTriangle = in.i32s();
  m.regionTypes.resize(in.count(1));
  for (auto& t : m.regionTypes) {
    const std::uint8_t type = in.u8();
    if (type > 1) in.fail("a region type of " + std::to_string(type));
    t = static_cast<RegionType>(type);
  }
  if (m.positions.size() != m.pattern.size())
    in.fail("a mesh's positions do not match its pattern");
  if (!m.regionOfTriangle.empty() && m.regionOfTriangle.size() != m.triangles.size())
    in.fail("a mesh's regions do not match its triangles");
  for (const auto& t : m.triangles)
    for (int v : t)
      if (!inRange(m.pattern, v)) in.fail("a triangle's vertex is out of range");
  return m;
}

std::vector<std::vector<int>> boundaryLoops(const SheetMesh& mesh) {
  // Each boundary edge, oriented as its triangle runs it (counter-clockwise
  // triangles: the sheet on the edge's left).
  std::map<int, int> next;
  for (const MeshEdge& e : buildEdges(mesh)) {
    if (e.interior()) continue;
    const auto& t = mesh.triangles[static_cast<std::size_t>(e.triangles[0])];
    int from = e.v[0], to = e.v[1];
    for (int k = 0; k < 3; ++k)
      if (t[static_cast<std::size_t>(k)] == e.v[1] &&
          t[static_cast<std::size_t>((k + 1) % 3)] == e.v[0])
        std::swap(from, to);
    if (!next.emplace(from, to).second)
      throw std::invalid_argument("boundaryLoops: two boundary loops touch at vertex " +
                                  std::to_string(from));
  }
  std::vector<std::vector<int>> loops;
  while (!next.empty()) {
    std::vector<int> loop;
    int v = next.begin()->first;  // the lowest vertex left
    while (true) {
      const auto it = next.find(v);
      if (it == next.end()) break;
      loop.push_back(v);
      v = it->second;
      next.erase(it);
    }
    if (v != loop.front())
      throw std::invalid_argument("boundaryLoops: a boundary that does not close");
    loops.push_back(std::move(loop));
  }
  return loops;
}

}  // namespace crumple::mesh
