#include "region_tools.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "crumple/core/index.hpp"
#include "crumple/mesh/delaunay.hpp"

namespace crumple::paper::detail {

EdgeMap edgeMap(const GeometricMesh& g) {
  const std::vector<GeometricEdge> edges = buildEdges(g);  // sorted by (v0, v1)
  std::vector<EdgeMap::value_type> entries;
  entries.reserve(edges.size());
  for (const GeometricEdge& e : edges) entries.emplace_back(EdgeMap::Key{e.v[0], e.v[1]}, e.faces);
  return EdgeMap(std::move(entries));
}

int otherFace(const EdgeMap& edges, int a, int b, int face) {
  const auto it = edges.find({std::min(a, b), std::max(a, b)});
  if (it == edges.end()) return -1;
  return it->second[0] == face ? it->second[1] : it->second[0];
}

std::optional<Loop> regionLoop(const GeometricMesh& g, int region, const EdgeMap& edges) {
  std::map<int, std::pair<int, int>> out;  // start -> (end, face across)
  std::size_t count = 0;
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    const GeometricFace& face = g.faces[f];
    if (face.region != region) continue;
    const int n = face.size();
    for (int k = 0; k < n; ++k) {
      const int a = face.v[k];
      const int b = face.v[(k + 1) % n];
      const int o = otherFace(edges, a, b, static_cast<int>(f));
      if (o >= 0 && g.faces[idx(o)].region == region) continue;
      if (out.contains(a)) return std::nullopt;  // pinched region
      out[a] = {b, o};
      ++count;
    }
  }
  if (out.empty()) return std::nullopt;
  Loop loop;
  int v = out.begin()->first;
  for (std::size_t k = 0; k < count; ++k) {
    const auto it = out.find(v);
    if (it == out.end()) return std::nullopt;
    loop.v.push_back(v);
    loop.across.push_back(it->second.second);
    v = it->second.first;
    if (v == loop.v.front()) break;
  }
  if (loop.v.size() != count) return std::nullopt;  // holes: several loops
  return loop;
}

bool pointInPolygon(const GeometricMesh& g, std::span<const int> polygon, const Vec2& p) {
  bool inside = false;
  const std::size_t n = polygon.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2& a = g.vertices[idx(polygon[k])].pattern;
    const Vec2& b = g.vertices[idx(polygon[(k + 1) % n])].pattern;
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y()) > p.x()) {
      inside = !inside;
    }
  }
  return inside;
}

bool insideLoop(const GeometricMesh& g, const Loop& loop, const Vec2& p) {
  return pointInPolygon(g, loop.v, p);
}

std::vector<int> innerVertices(const GeometricMesh& g, int region, const Loop& loop) {
  std::vector<char> seen(g.vertices.size(), 0);
  for (int v : loop.v) seen[idx(v)] = 1;
  std::vector<int> out;
  for (const GeometricFace& f : g.faces) {
    if (f.region != region) continue;
    for (int k = 0; k < f.size(); ++k) {
      if (!seen[idx(f.v[k])]) {
        seen[idx(f.v[k])] = 1;
        out.push_back(f.v[k]);
      }
    }
  }
  return out;
}

int nearestOutlineSegment(const GeometricMesh& g, const Vec2& p) {
  int best = 0;
  double bestDist = 1e300;
  const std::size_t n = g.outline.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2& a = g.outline[k];
    const Vec2& b = g.outline[(k + 1) % n];
    const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    const double d = (a + t * (b - a) - p).norm();
    if (d < bestDist) {
      bestDist = d;
      best = static_cast<int>(k);
    }
  }
  return best;
}

// Builds flat faces for a polygon (vertex ids, CCW) by constrained Delaunay;
// the `inner` vertices that lie strictly inside it (singular or handle
// vertices of the region) are kept as vertices of the triangulation.
void triangulatePolygon(GeometricMesh& g, const std::vector<int>& polygon, int region,
                        const std::vector<int>& inner) {
  if (polygon.size() < 3) return;
  std::vector<Vec2> points;
  std::vector<int> ids = polygon;
  std::vector<std::array<int, 2>> constraints;
  for (std::size_t k = 0; k < polygon.size(); ++k) {
    points.push_back(g.vertices[idx(polygon[k])].pattern);
    constraints.push_back({static_cast<int>(k), static_cast<int>((k + 1) % polygon.size())});
  }
  for (int v : inner) {
    const Vec2& p = g.vertices[idx(v)].pattern;
    if (!pointInPolygon(g, polygon, p)) continue;
    points.push_back(p);
    ids.push_back(v);
  }
  for (const auto& t : mesh::constrainedDelaunay(points, constraints)) {
    GeometricFace f;
    f.v = {ids[idx(t[0])], ids[idx(t[1])], ids[idx(t[2])], -1};
    f.region = region;
    g.faces.push_back(f);
  }
}

int addRegion(GeometricMesh& g, mesh::RegionType type) {
  Region r;
  r.type = type;
  g.regions.push_back(r);
  return static_cast<int>(g.regions.size()) - 1;
}

// A new vertex on the dS edge (a, b) at pattern point p.
int addBoundaryVertex(GeometricMesh& g, int a, int b, const Vec2& p,
                      const std::function<Vec3(double)>& boundary) {
  const GeometricVertex& va = g.vertices[idx(a)];
  const GeometricVertex& vb = g.vertices[idx(b)];
  const double len = (vb.pattern - va.pattern).norm();
  const double u = std::clamp((p - va.pattern).norm() / len, 0.0, 1.0);
  GeometricVertex v;
  v.pattern = p;
  v.onBoundary = true;
  v.outlineSegment = nearestOutlineSegment(g, p);
  v.pattern = outlinePoint(g, outlineParameter(g, p, v.outlineSegment));
  v.position = boundary ? boundary(outlineParameter(g, v.pattern, v.outlineSegment))
                        : Vec3((1.0 - u) * va.position + u * vb.position);
  v.velocity = (1.0 - u) * va.velocity + u * vb.velocity;
  return addVertex(g, v);
}

}  // namespace crumple::paper::detail
