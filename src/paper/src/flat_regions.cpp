// Edge flips and coplanarity splits of flat regions (thesis 2.4.1; paper Sec. 5.1).
#include <algorithm>
#include <map>
#include <numeric>
#include <vector>

#include "crumple/core/geometry2d.hpp"
#include "crumple/core/index.hpp"
#include "crumple/paper/compression.hpp"
#include "crumple/paper/geometric_step.hpp"

namespace crumple::paper {

namespace {

int oppositeVertex(const GeometricFace& f, int a, int b) {
  for (int k = 0; k < 3; ++k) {
    if (f.v[k] != a && f.v[k] != b) return f.v[k];
  }
  return -1;
}

bool isFlatTriangle(const GeometricMesh& g, const GeometricFace& f) {
  return f.size() == 3 && g.regions[idx(f.region)].type == mesh::RegionType::Flat;
}

}  // namespace

// thesis 2.4.1: "We flip an edge e1 between two triangles of the same flat
// region when e1 is compressed and the alternative edge e2 is not."
int flipCompressedEdges(GeometricMesh& g, const CrumpleParams& params) {
  int flips = 0;
  // One pass over the edges as they are at the start; an edge touched by a
  // flip is not reconsidered in the same pass (deterministic, terminates).
  const std::vector<GeometricEdge> edges = buildEdges(g);
  std::vector<char> touched(g.faces.size(), 0);
  for (const GeometricEdge& e : edges) {
    if (!e.interior()) continue;
    const int f0 = e.faces[0];
    const int f1 = e.faces[1];
    if (touched[idx(f0)] || touched[idx(f1)]) continue;
    GeometricFace& t0 = g.faces[idx(f0)];
    GeometricFace& t1 = g.faces[idx(f1)];
    if (t0.region != t1.region || !isFlatTriangle(g, t0) || !isFlatTriangle(g, t1)) continue;
    const int a = e.v[0];
    const int b = e.v[1];
    const int c = oppositeVertex(t0, a, b);
    const int d = oppositeVertex(t1, a, b);
    const auto& V = g.vertices;
    const auto P = [&](int v) -> const Vec2& { return V[idx(v)].pattern; };
    const auto X = [&](int v) -> const Vec3& { return V[idx(v)].position; };
    const double ce1 = edgeCompression(P(a), P(b), X(a), X(b));
    const double ce2 = edgeCompression(P(c), P(d), X(c), X(d));
    if (!(ce1 > params.epsC) || ce2 > params.epsC) continue;
    // The quad (a, d, b, c) must be strictly convex in the pattern: c and d on
    // opposite sides of (a, b) and a and b on opposite sides of (c, d).
    const double sc = cross2(P(b) - P(a), P(c) - P(a));
    const double sd = cross2(P(b) - P(a), P(d) - P(a));
    const double sa = cross2(P(d) - P(c), P(a) - P(c));
    const double sb = cross2(P(d) - P(c), P(b) - P(c));
    if (!(sc * sd < 0.0) || !(sa * sb < 0.0)) continue;
    // ...and not nearly degenerate: both new triangles keep a fair share of the quad.
    const double quad = std::abs(sc) + std::abs(sd);
    if (std::min(std::abs(sa), std::abs(sb)) < 1e-3 * quad) continue;
    // New triangles (c, a, d) and (d, b, c), oriented counter-clockwise.
    const int region = t0.region;
    std::array<int, 3> n0{c, a, d};
    std::array<int, 3> n1{d, b, c};
    for (auto* tri : {&n0, &n1}) {
      auto& t = *tri;
      if (cross2(P(t[1]) - P(t[0]), P(t[2]) - P(t[0])) < 0.0) std::swap(t[1], t[2]);
    }
    t0.v = {n0[0], n0[1], n0[2], -1};
    t1.v = {n1[0], n1[1], n1[2], -1};
    t0.region = t1.region = region;
    touched[idx(f0)] = touched[idx(f1)] = 1;
    ++flips;
  }
  return flips;
}

// paper Sec. 5.1: flat regions are the maximal connected sets of pairwise
// coplanar flat faces (dihedral <= theta_0), so regions are split where a
// fold appears and merged where neighbouring flat regions became coplanar.
// Components are numbered by their smallest face; returns how many regions
// were split (the number of components beyond one per previous region).
int splitFlatRegions(GeometricMesh& g, const CrumpleParams& params) {
  const std::vector<GeometricEdge> edges = buildEdges(g);
  std::vector<int> parent(g.faces.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int f) {
    while (parent[idx(f)] != f) {
      parent[idx(f)] = parent[idx(parent[idx(f)])];
      f = parent[idx(f)];
    }
    return f;
  };
  const auto isFlat = [&](int f) {
    return g.regions[idx(g.faces[idx(f)].region)].type == mesh::RegionType::Flat;
  };
  for (const GeometricEdge& e : edges) {
    if (!e.interior() || !isFlat(e.faces[0]) || !isFlat(e.faces[1])) continue;
    if (dihedralAngle(g, e.faces[0], e.faces[1]) > params.theta0) continue;
    // Two singular vertices joined by an edge make a crease (Appendix B,
    // Fig. 24 c): it stays a border between flat regions.
    if (g.vertices[idx(e.v[0])].singular && g.vertices[idx(e.v[1])].singular) {
      continue;
    }
    const int ra = find(e.faces[0]);
    const int rb = find(e.faces[1]);
    if (ra != rb) parent[idx(std::max(ra, rb))] = std::min(ra, rb);
  }
  int before = 0;
  for (const Region& r : g.regions) before += r.type == mesh::RegionType::Flat ? 1 : 0;
  std::map<int, int> regionOfRoot;
  std::vector<int> usedOld(g.regions.size(), 0);
  int components = 0;
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    if (!isFlat(static_cast<int>(f))) continue;
    const int root = find(static_cast<int>(f));
    auto it = regionOfRoot.find(root);
    if (it == regionOfRoot.end()) {
      ++components;
      // Reuse the face's old region id the first time it is seen, else a new one.
      const int old = g.faces[f].region;
      int id = old;
      if (usedOld[idx(old)]) {
        Region region;
        region.type = mesh::RegionType::Flat;
        g.regions.push_back(region);
        usedOld.push_back(1);
        id = static_cast<int>(g.regions.size()) - 1;
      }
      usedOld[idx(id)] = 1;
      it = regionOfRoot.emplace(root, id).first;
    }
    g.faces[f].region = it->second;
  }
  compact(g);
  return std::max(0, components - before);
}

}  // namespace crumple::paper
