#include "crumple/tear/cut.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "crumple/tear/candidates.hpp"

namespace crumple::tear {

namespace {

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Angle from a to b, counter-clockwise, in [0, 2 pi).
double ccwAngle(const Vec2& a, const Vec2& b) {
  double angle = std::atan2(cross(a, b), a.dot(b));
  if (angle < 0.0) angle += 2.0 * std::numbers::pi;
  return angle;
}

}  // namespace

VertexBlend makeBlend(std::vector<std::pair<int, double>> terms) {
  std::sort(terms.begin(), terms.end());
  std::vector<std::pair<int, double>> merged;
  for (const auto& [v, w] : terms) {
    if (!merged.empty() && merged.back().first == v) {
      merged.back().second += w;
    } else {
      merged.emplace_back(v, w);
    }
  }
  std::stable_sort(merged.begin(), merged.end(),
                   [](const auto& x, const auto& y) { return x.second > y.second; });
  if (merged.size() > 3) merged.resize(3);
  double sum = 0.0;
  for (const auto& [v, w] : merged) sum += w;
  VertexBlend out;
  for (std::size_t k = 0; k < merged.size(); ++k) {
    out.vertex[k] = merged[k].first;
    out.weight[k] = merged[k].second / sum;
  }
  return out;
}

namespace {

constexpr double kMinRelocatedAngle = 15.0 * std::numbers::pi / 180.0;

struct Cutter {
  mesh::SheetMesh& m;
  double eps;  // pattern length below which points coincide
  std::size_t oldCount;
  std::vector<VertexBlend>& blends;

  Vec2 p(int v) const { return m.pattern[static_cast<std::size_t>(v)]; }

  // The blend of any vertex: a vertex from before the cut is itself.
  std::vector<std::pair<int, VertexBlend>>& relocated;

  VertexBlend blendOf(int v) const {
    if (static_cast<std::size_t>(v) >= oldCount)
      return blends[static_cast<std::size_t>(v) - oldCount];
    for (const auto& [u, b] : relocated)
      if (u == v) return b;
    VertexBlend b;
    b.vertex[0] = v;
    b.weight[0] = 1.0;
    return b;
  }
  // sum_k w[k] blendOf(v[k]), merged by vertex; more than three vertices
  // (a split between two moved vertices) keep the three heaviest,
  // renormalised.
  VertexBlend combine(const std::array<int, 3>& v, const std::array<double, 3>& w) const {
    std::vector<std::pair<int, double>> terms;
    for (int k = 0; k < 3; ++k) {
      if (v[static_cast<std::size_t>(k)] < 0 || w[static_cast<std::size_t>(k)] == 0.0) continue;
      const VertexBlend b = blendOf(v[static_cast<std::size_t>(k)]);
      for (int j = 0; j < 3; ++j)
        if (b.vertex[static_cast<std::size_t>(j)] >= 0)
          terms.emplace_back(
              b.vertex[static_cast<std::size_t>(j)],
              w[static_cast<std::size_t>(k)] * b.weight[static_cast<std::size_t>(j)]);
    }
    return makeBlend(std::move(terms));
  }

  int addVertex(const Vec2& pattern, const Vec3& position, const VertexBlend& blend) {
    m.pattern.push_back(pattern);
    m.positions.push_back(position);
    blends.push_back(blend);
    return static_cast<int>(m.pattern.size()) - 1;
  }
  void addTriangle(const std::array<int, 3>& t, int region) {
    m.triangles.push_back(t);
    m.regionOfTriangle.push_back(region);
  }

  // The triangle around vertex v whose corner at v holds direction d, and
  // the positions (in it) of v's two neighbours; -1 when none does.
  int triangleToward(int v, const Vec2& d, int& a, int& b) const {
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      const auto& tri = m.triangles[t];
      for (int k = 0; k < 3; ++k) {
        if (tri[static_cast<std::size_t>(k)] != v) continue;
        const int na = tri[static_cast<std::size_t>((k + 1) % 3)];
        const int nb = tri[static_cast<std::size_t>((k + 2) % 3)];
        const Vec2 ea = p(na) - p(v), eb = p(nb) - p(v);
        // Counter-clockwise triangles: d lies in the corner's wedge from ea
        // to eb (narrower than pi, so within pi/2 of its bisector).
        if (cross(ea, d) >= -eps * d.norm() && cross(d, eb) >= -eps * d.norm() &&
            (ea.normalized() + eb.normalized()).dot(d) > 0.0) {
          a = na;
          b = nb;
          return static_cast<int>(t);
        }
      }
    }
    return -1;
  }

  // Splits edge (a, b) at parameter s (from a), in every triangle holding
  // it; returns the new vertex.
  int splitEdge(int a, int b, double s) {
    const Vec2 q = (1.0 - s) * p(a) + s * p(b);
    const Vec3 x = (1.0 - s) * m.positions[static_cast<std::size_t>(a)] +
                   s * m.positions[static_cast<std::size_t>(b)];
    const int n = addVertex(q, x, combine({a, b, -1}, {1.0 - s, s, 0.0}));
    const std::size_t count = m.triangles.size();
    for (std::size_t t = 0; t < count; ++t) {
      auto tri = m.triangles[t];
      for (int k = 0; k < 3; ++k) {
        const int u = tri[static_cast<std::size_t>(k)],
                  w = tri[static_cast<std::size_t>((k + 1) % 3)];
        if (!((u == a && w == b) || (u == b && w == a))) continue;
        const int o = tri[static_cast<std::size_t>((k + 2) % 3)];
        m.triangles[t] = {u, n, o};
        addTriangle({n, w, o}, m.regionOfTriangle[t]);
        break;
      }
    }
    return n;
  }

  // The boundary neighbours (prev, next) of boundary vertex v: the sheet is
  // on the left of prev -> v -> next (counter-clockwise triangles: a
  // triangle's edge is on the boundary when no triangle runs it backwards).
  std::array<int, 2> boundaryNeighbours(int v) const {
    const auto runs = [&](int from, int to) {
      for (const auto& t : m.triangles)
        for (int k = 0; k < 3; ++k)
          if (t[static_cast<std::size_t>(k)] == from &&
              t[static_cast<std::size_t>((k + 1) % 3)] == to)
            return true;
      return false;
    };
    std::array<int, 2> out{-1, -1};
    for (const auto& t : m.triangles)
      for (int k = 0; k < 3; ++k) {
        if (t[static_cast<std::size_t>(k)] != v) continue;
        const int n1 = t[static_cast<std::size_t>((k + 1) % 3)],
                  n2 = t[static_cast<std::size_t>((k + 2) % 3)];
        if (!runs(n1, v)) out[1] = n1;
        if (!runs(v, n2)) out[0] = n2;
      }
    if (out[0] < 0 || out[1] < 0)
      throw std::invalid_argument("cutAlong: vertex " + std::to_string(v) +
                                  " is not on the boundary");
    return out;
  }

  // Moves vertex v to pattern point q (and to the 3D point the surface has
  // there) when v may move: not on the boundary, not fixed, q inside one of
  // its triangles, and none of them losing half its area or getting an
  // angle below 15 degrees.
  // Returns whether it moved.
  bool relocate(int v, const Vec2& q, const std::vector<char>& boundary,
                const std::vector<char>* fixed) {
    const auto vi = static_cast<std::size_t>(v);
    if ((vi < boundary.size() && boundary[vi] != 0) ||
        (fixed != nullptr && vi < fixed->size() && (*fixed)[vi] != 0))
      return false;
    if ((q - p(v)).norm() <= eps) return true;
    std::vector<std::size_t> around;
    int holder = -1;
    std::array<double, 3> w{};
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      const auto& tri = m.triangles[t];
      if (tri[0] != v && tri[1] != v && tri[2] != v) continue;
      around.push_back(t);
      const Vec2 a = p(tri[0]), b = p(tri[1]), c = p(tri[2]);
      const double area = cross(b - a, c - a);
      const double wb = cross(q - a, c - a) / area, wc = cross(b - a, q - a) / area;
      if (holder < 0 && wb >= -1e-12 && wc >= -1e-12 && wb + wc <= 1.0 + 1e-12) {
        holder = static_cast<int>(t);
        w = {1.0 - wb - wc, wb, wc};
      }
    }
    if (holder < 0) return false;
    const Vec2 old = p(v);
    std::vector<double> before;
    for (std::size_t t : around) {
      const auto& tri = m.triangles[t];
      before.push_back(cross(p(tri[1]) - p(tri[0]), p(tri[2]) - p(tri[0])));
    }
    m.pattern[vi] = q;
    for (std::size_t k = 0; k < around.size(); ++k) {
      const auto& tri = m.triangles[around[k]];
      double minAngle = std::numbers::pi;
      for (int j = 0; j < 3; ++j) {
        const Vec2 u =
            p(tri[static_cast<std::size_t>((j + 1) % 3)]) - p(tri[static_cast<std::size_t>(j)]);
        const Vec2 w2 =
            p(tri[static_cast<std::size_t>((j + 2) % 3)]) - p(tri[static_cast<std::size_t>(j)]);
        minAngle = std::min(minAngle, std::abs(std::atan2(cross(u, w2), u.dot(w2))));
      }
      if (cross(p(tri[1]) - p(tri[0]), p(tri[2]) - p(tri[0])) < 0.5 * before[k] ||
          minAngle < kMinRelocatedAngle) {
        m.pattern[vi] = old;
        return false;
      }
    }
    const auto& tri = m.triangles[static_cast<std::size_t>(holder)];
    Vec3 x = Vec3::Zero();
    for (int k = 0; k < 3; ++k)
      x += w[static_cast<std::size_t>(k)] *
           m.positions[static_cast<std::size_t>(tri[static_cast<std::size_t>(k)])];
    // The blend over the mesh before the cut (v itself as it was).
    const VertexBlend blend = combine(tri, w);
    m.positions[vi] = x;
    if (vi >= oldCount) {
      blends[vi - oldCount] = blend;
    } else {
      bool found = false;
      for (auto& [u, b] : relocated)
        if (u == v) {
          b = blend;
          found = true;
        }
      if (!found) relocated.emplace_back(v, blend);
    }
    return true;
  }

  // Inserts q inside triangle t (split into three); returns the new vertex.
  int splitTriangle(int t, const Vec2& q) {
    const auto tri = m.triangles[static_cast<std::size_t>(t)];
    const Vec2 a = p(tri[0]), b = p(tri[1]), c = p(tri[2]);
    const double area = cross(b - a, c - a);
    const double wb = cross(q - a, c - a) / area, wc = cross(b - a, q - a) / area;
    const Vec3 x = (1.0 - wb - wc) * m.positions[static_cast<std::size_t>(tri[0])] +
                   wb * m.positions[static_cast<std::size_t>(tri[1])] +
                   wc * m.positions[static_cast<std::size_t>(tri[2])];
    const int n = addVertex(q, x, combine(tri, {1.0 - wb - wc, wb, wc}));
    const int region = m.regionOfTriangle[static_cast<std::size_t>(t)];
    m.triangles[static_cast<std::size_t>(t)] = {tri[0], tri[1], n};
    addTriangle({tri[1], tri[2], n}, region);
    addTriangle({tri[2], tri[0], n}, region);
    return n;
  }
};

}  // namespace

CutResult cutAlong(mesh::SheetMesh& mesh, int from, const Vec2& to, const CutOptions& options) {
  std::vector<char> boundary(mesh.vertexCount(), 0);
  for (const auto& loop : boundaryLoops(mesh))
    for (int v : loop) boundary[static_cast<std::size_t>(v)] = 1;
  if (from < 0 || static_cast<std::size_t>(from) >= mesh.vertexCount() ||
      boundary[static_cast<std::size_t>(from)] == 0)
    throw std::invalid_argument("cutAlong: vertex " + std::to_string(from) +
                                " is not on the boundary");
  if (!(options.snap >= 0.0 && options.snap < 0.5))
    throw std::invalid_argument("cutAlong: snap must be in [0, 0.5)");
  double extent = 0.0;
  for (const Vec2& q : mesh.pattern) extent = std::max(extent, q.cwiseAbs().maxCoeff());
  CutResult out;
  Cutter c{mesh, 1e-12 * std::max(extent, 1e-3), mesh.vertexCount(), out.blends, out.relocated};
  const double snap = std::max(options.snap, 1e-9);
  // A vertex split off a boundary edge is on the boundary too.
  const auto onBoundary = [&](int v) {
    return static_cast<std::size_t>(v) < boundary.size() &&
           boundary[static_cast<std::size_t>(v)] != 0;
  };
  const auto splitsBoundaryEdge = [&](int a, int b) {
    int shared = 0;
    for (const auto& t : mesh.triangles) {
      const bool hasA = t[0] == a || t[1] == a || t[2] == a;
      const bool hasB = t[0] == b || t[1] == b || t[2] == b;
      shared += hasA && hasB ? 1 : 0;
    }
    return shared == 1;
  };
  out.chain.push_back(from);
  int at = from;
  // 1. The segment as a chain of edges, stopping early where it meets the
  // boundary (the sheet is cut through).
  for (int guard = 0; guard < 100000; ++guard) {
    const Vec2 d = to - c.p(at);
    if (d.norm() <= c.eps) break;
    int a = -1, b = -1;
    const int t = c.triangleToward(at, d, a, b);
    if (t < 0) throw std::invalid_argument("cutAlong: the cut leaves the sheet");
    const Vec2 pa = c.p(a), pb = c.p(b), pv = c.p(at);
    // Where the ray from `at` along d meets edge (a, b): at + r d = a + s (b - a).
    const Vec2 e = pb - pa;
    const double denom = cross(d, e);
    const double r = cross(pa - pv, e) / denom;
    const double s = cross(pa - pv, d) / denom;
    bool boundaryEdge = splitsBoundaryEdge(a, b);  // of the edge a split cuts
    bool last = false;
    bool splitEdge = false;  // `at` is new, on edge (a, b)
    if (r >= 1.0 - 1e-12) {  // `to` is in this triangle, or on its far edge
      last = true;
      // Barycentric weights of `to` in (at, a, b): near a corner it is that
      // corner, near the far edge it is on the edge.
      const double area = cross(pa - pv, pb - pv);
      const double wa = cross(to - pv, pb - pv) / area, wb = cross(pa - pv, to - pv) / area;
      const double wv = 1.0 - wa - wb;
      // Within snap times the triangle's mean edge of `at`: the cut ends there.
      const double nearby = snap * ((pa - pv).norm() + (pb - pv).norm() + (pb - pa).norm()) / 3.0;
      if (wa >= 1.0 - snap) {
        at = a;
      } else if (wb >= 1.0 - snap) {
        at = b;
      } else if (wv >= 1.0 - snap || (to - pv).norm() <= nearby) {
        // s_{t+1} is next to where the cut stands: it ends here.
      } else if (wb <= snap || wa <= snap) {
        // On (or next to) an edge from `at`: split that edge.
        const int other = wb <= snap ? a : b;
        const double along =
            (wb <= snap ? wa : wb) / std::max(1.0 - (wb <= snap ? wb : wa), 1e-300);
        splitEdge = true;
        boundaryEdge = splitsBoundaryEdge(at, other);
        at = c.splitEdge(at, other, std::clamp(along, 0.0, 1.0));
      } else if (wv <= snap || r <= 1.0 + 1e-12) {
        const double along = std::clamp(wb / std::max(wa + wb, 1e-300), 0.0, 1.0);
        splitEdge = along > snap && along < 1.0 - snap;
        at = along <= snap ? a : along >= 1.0 - snap ? b : c.splitEdge(a, b, along);
      } else {
        at = c.splitTriangle(t, to);
      }
      // Snapped onto a vertex or an edge: that vertex moves onto s_{t+1} when it can.
      if (!splitEdge || !boundaryEdge) {
        boundary.resize(mesh.vertexCount(), 0);
        (void)c.relocate(at, to, boundary, options.fixed);
      }
    } else if (s <= (onBoundary(a) ? 1e-9 : snap)) {
      // Through vertex a, moved onto the segment when it can be (never
      // snapped onto the boundary: that would cut the sheet through).
      at = a;
      (void)c.relocate(a, pa + s * e, boundary, options.fixed);
    } else if (s >= 1.0 - (onBoundary(b) ? 1e-9 : snap)) {
      at = b;
      (void)c.relocate(b, pa + s * e, boundary, options.fixed);
    } else {
      splitEdge = true;
      at = c.splitEdge(a, b, s);
    }
    boundary.resize(mesh.vertexCount(), 0);
    if (splitEdge && boundaryEdge) boundary[static_cast<std::size_t>(at)] = 1;
    if (at == out.chain.back()) break;  // snapped back onto where it stands
    out.chain.push_back(at);
    if (onBoundary(at)) {
      out.separated = true;
      break;
    }
    if (last) break;
  }
  out.tip = out.chain.back();
  // 2. Every chain vertex but the tip gets a twin for the left lip: the
  // triangles around it counter-clockwise from the outgoing edge up to the
  // incoming one; at the first, up to the boundary edge arriving there. When
  // the cut went through to the boundary the tip is doubled too: the
  // triangles from the boundary edge leaving it up to the incoming edge.
  const std::size_t doubled = out.separated ? out.chain.size() : out.chain.size() - 1;
  std::vector<std::array<int, 2>> lipSides(doubled);  // (prev, next) boundary neighbours
  for (std::size_t i = 0; i < doubled; ++i)
    if (i == 0 || i + 1 == out.chain.size()) lipSides[i] = c.boundaryNeighbours(out.chain[i]);
  for (std::size_t i = 0; i < doubled; ++i) {
    const int v = out.chain[i];
    const Vec2 here = c.p(v);
    const bool end = i + 1 == out.chain.size();
    // The wedge of the left lip, counter-clockwise from `start` by `limit`.
    Vec2 start = Vec2::Zero();
    double limit = 0.0;
    if (end) {
      start = c.p(lipSides[i][1]) - here;
      limit = ccwAngle(start, c.p(out.chain[i - 1]) - here);
    } else {
      start = c.p(out.chain[i + 1]) - here;
      const int back = i == 0 ? lipSides[i][0] : out.chain[i - 1];
      limit = ccwAngle(start, c.p(back) - here);
    }
    const int twin = c.addVertex(here, mesh.positions[static_cast<std::size_t>(v)], c.blendOf(v));
    for (auto& tri : mesh.triangles) {
      int k = -1;
      for (int j = 0; j < 3; ++j)
        if (tri[static_cast<std::size_t>(j)] == v) k = j;
      if (k < 0) continue;
      const Vec2 centroid = (c.p(tri[0]) + c.p(tri[1]) + c.p(tri[2])) / 3.0;
      if (ccwAngle(start, centroid - here) < limit) tri[static_cast<std::size_t>(k)] = twin;
    }
    out.twins.push_back(twin);
  }
  if (out.chain.size() < 2) out.tip = from;
  return out;
}

}  // namespace crumple::tear
