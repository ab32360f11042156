#include "crumple/tear/cut.hpp"

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

struct Cutter {
  mesh::SheetMesh& m;
  double eps;  // pattern length below which points coincide

  Vec2 p(int v) const { return m.pattern[static_cast<std::size_t>(v)]; }

  int addVertex(const Vec2& pattern, const Vec3& position) {
    m.pattern.push_back(pattern);
    m.positions.push_back(position);
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
    const int n = addVertex(q, x);
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

  // Inserts q inside triangle t (split into three); returns the new vertex.
  int splitTriangle(int t, const Vec2& q) {
    const auto tri = m.triangles[static_cast<std::size_t>(t)];
    const Vec2 a = p(tri[0]), b = p(tri[1]), c = p(tri[2]);
    const double area = cross(b - a, c - a);
    const double wb = cross(q - a, c - a) / area, wc = cross(b - a, q - a) / area;
    const Vec3 x = (1.0 - wb - wc) * m.positions[static_cast<std::size_t>(tri[0])] +
                   wb * m.positions[static_cast<std::size_t>(tri[1])] +
                   wc * m.positions[static_cast<std::size_t>(tri[2])];
    const int n = addVertex(q, x);
    const int region = m.regionOfTriangle[static_cast<std::size_t>(t)];
    m.triangles[static_cast<std::size_t>(t)] = {tri[0], tri[1], n};
    addTriangle({tri[1], tri[2], n}, region);
    addTriangle({tri[2], tri[0], n}, region);
    return n;
  }
};

}  // namespace

CutResult cutAlong(mesh::SheetMesh& mesh, int from, const Vec2& to) {
  bool onBoundary = false;
  for (const auto& loop : boundaryLoops(mesh))
    for (int v : loop) onBoundary = onBoundary || v == from;
  if (!onBoundary)
    throw std::invalid_argument("cutAlong: vertex " + std::to_string(from) +
                                " is not on the boundary");
  double extent = 0.0;
  for (const Vec2& q : mesh.pattern) extent = std::max(extent, q.cwiseAbs().maxCoeff());
  Cutter c{mesh, 1e-12 * std::max(extent, 1e-3)};
  CutResult out;
  out.chain.push_back(from);
  int at = from;
  // 1. The segment as a chain of edges.
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
    if (r >= 1.0 - 1e-12) {  // `to` is in this triangle, or on its far edge
      if (r <= 1.0 + 1e-12 && s <= 1e-9) {
        at = a;  // `to` is a vertex already
      } else if (r <= 1.0 + 1e-12 && s >= 1.0 - 1e-9) {
        at = b;
      } else if (r <= 1.0 + 1e-12) {
        at = c.splitEdge(a, b, s);
      } else {
        at = c.splitTriangle(t, to);
      }
      out.chain.push_back(at);
      break;
    }
    if (s <= 1e-9) {
      at = a;  // through vertex a
    } else if (s >= 1.0 - 1e-9) {
      at = b;
    } else {
      at = c.splitEdge(a, b, s);
    }
    out.chain.push_back(at);
  }
  out.tip = out.chain.back();
  // 2. Every chain vertex but the tip gets a twin for the left lip: the
  // triangles around it counter-clockwise from the outgoing edge up to the
  // incoming one (for the first, up to the boundary).
  for (std::size_t i = 0; i + 1 < out.chain.size(); ++i) {
    const int v = out.chain[i];
    const Vec2 here = c.p(v);
    const Vec2 ahead = c.p(out.chain[i + 1]) - here;
    const double limit = i == 0 ? std::numbers::pi : ccwAngle(ahead, c.p(out.chain[i - 1]) - here);
    const int twin = c.addVertex(here, mesh.positions[static_cast<std::size_t>(v)]);
    for (auto& tri : mesh.triangles) {
      int k = -1;
      for (int j = 0; j < 3; ++j)
        if (tri[static_cast<std::size_t>(j)] == v) k = j;
      if (k < 0) continue;
      const Vec2 centroid = (c.p(tri[0]) + c.p(tri[1]) + c.p(tri[2])) / 3.0;
      const Vec2 dir = centroid - here;
      const bool left = i == 0 ? cross(ahead, dir) > 0.0 : ccwAngle(ahead, dir) < limit;
      if (left) tri[static_cast<std::size_t>(k)] = twin;
    }
    out.twins.push_back(twin);
  }
  return out;
}

}  // namespace crumple::tear
