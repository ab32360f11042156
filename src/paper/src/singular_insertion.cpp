// Singular vertices where a compressed strip meets a border (paper Sec. 5.2,
// Fig. 11; thesis 2.4.3).
#include "singular_insertion.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "crumple/core/geometry2d.hpp"
#include "crumple/core/index.hpp"

namespace crumple::paper::detail {

namespace {

// Splits the interior edge (a, b) at pattern point p with a new singular
// vertex, splitting both incident triangles (paper Sec. 5.2, flat-flat case).
int insertSingularOnEdge(GeometricMesh& g, int a, int b, const Vec2& p) {
  const GeometricVertex& va = g.vertices[idx(a)];
  const GeometricVertex& vb = g.vertices[idx(b)];
  const double u = std::clamp(
      (p - va.pattern).dot(vb.pattern - va.pattern) / (vb.pattern - va.pattern).squaredNorm(), 0.0,
      1.0);
  GeometricVertex s;
  s.pattern = va.pattern + u * (vb.pattern - va.pattern);
  s.position = (1.0 - u) * va.position + u * vb.position;
  s.velocity = (1.0 - u) * va.velocity + u * vb.velocity;
  s.singular = true;
  const int sv = addVertex(g, s);
  const std::size_t faceCount = g.faces.size();
  for (std::size_t f = 0; f < faceCount; ++f) {
    GeometricFace face = g.faces[f];
    if (face.size() != 3) continue;
    for (int k = 0; k < 3; ++k) {
      const int x = face.v[k];
      const int y = face.v[(k + 1) % 3];
      if (!((x == a && y == b) || (x == b && y == a))) continue;
      const int o = face.v[(k + 2) % 3];
      g.faces[f].v = {x, sv, o, -1};
      GeometricFace second = face;
      second.v = {sv, y, o, -1};
      g.faces.push_back(second);
      break;
    }
  }
  return sv;
}

}  // namespace

// A vertex at pattern point s inside the curved cell between rulings r0 and
// r1: its 3D position and velocity by barycentric interpolation in the cell
// triangle holding it (the cell split along its first diagonal). nullopt when
// s lies in neither triangle.
std::optional<GeometricVertex> vertexInCell(const GeometricMesh& g, const Ruling& r0,
                                            const Ruling& r1, const Vec2& s) {
  const auto P = [&](int v) -> const Vec2& { return g.vertices[idx(v)].pattern; };
  const std::array<int, 4> q{r0.a, r1.a, r1.b, r0.b};
  for (const auto& tri :
       {std::array<int, 3>{q[0], q[1], q[2]}, std::array<int, 3>{q[0], q[2], q[3]}}) {
    const Vec2 p0 = P(tri[0]);
    const double det = cross2(P(tri[1]) - p0, P(tri[2]) - p0);
    if (std::abs(det) < 1e-30) continue;
    const double l1 = cross2(s - p0, P(tri[2]) - p0) / det;
    const double l2 = cross2(P(tri[1]) - p0, s - p0) / det;
    const double l0 = 1.0 - l1 - l2;
    if (l0 < -1e-9 || l1 < -1e-9 || l2 < -1e-9) continue;
    const auto& V = g.vertices;
    GeometricVertex v;
    v.pattern = s;
    v.position =
        l0 * V[idx(tri[0])].position + l1 * V[idx(tri[1])].position + l2 * V[idx(tri[2])].position;
    v.velocity =
        l0 * V[idx(tri[0])].velocity + l1 * V[idx(tri[1])].velocity + l2 * V[idx(tri[2])].velocity;
    return v;
  }
  return std::nullopt;
}

// paper Fig. 11: the cells of a curved region between its rulings lo and hi
// become two fans of rulings from the singular vertex s (one per boundary
// chain), each a cone region with apex s.
void addConeFans(GeometricMesh& g, int s, const std::vector<Ruling>& rulings, std::size_t lo,
                 std::size_t hi) {
  for (int chain = 0; chain < 2; ++chain) {
    std::vector<Ruling> fan;
    for (std::size_t k = lo; k <= hi; ++k) {
      const int end = chain == 0 ? rulings[k].a : rulings[k].b;
      if (!fan.empty() && fan.back().b == end) continue;
      fan.push_back({s, end});
    }
    if (fan.size() < 2) continue;
    const int fr = addRegion(g, mesh::RegionType::Curved);
    g.regions[idx(fr)].rulings = fan;
    g.regions[idx(fr)].apex = s;
    rebuildCurvedFaces(g, fr);
  }
}

// Appends the triangle (a, b, c), counter-clockwise in the pattern, to `region`.
void addTriangleCCW(GeometricMesh& g, int a, int b, int c, int region) {
  const auto P = [&](int v) -> const Vec2& { return g.vertices[idx(v)].pattern; };
  GeometricFace f;
  f.v = {a, b, c, -1};
  if (cross2(P(b) - P(a), P(c) - P(a)) < 0.0) std::swap(f.v[1], f.v[2]);
  f.region = region;
  g.faces.push_back(f);
}

// Draws a standard normal deviate from two uniforms (Box-Muller).
double normalDeviate(const CounterRng& rng, std::uint64_t& index) {
  const double u1 = std::max(rng.uniform(index++), 1e-300);
  const double u2 = rng.uniform(index++);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

// Whether a new vertex at pattern point p would sit closer than a quarter of
// the ruling spacing to an existing S_G vertex: S_P triangles that small
// (tens of micrometres when d-cones pile up) make the elastic system too
// ill-conditioned to factor, so such an insertion is declined.
bool crowded(const GeometricMesh& g, const Vec2& p, const CrumpleParams& params) {
  const double gap = 0.25 / params.rhoBound;
  return std::any_of(g.vertices.begin(), g.vertices.end(),
                     [&](const GeometricVertex& v) { return (v.pattern - p).norm() < gap; });
}

// paper Sec. 5.2 (flat-flat case): the singular vertex goes on the border
// edge itself, near where the imaginary ruling meets it, spread along the
// edge with the law exp(-d^2/sigma^2) and kept off its ends.
int placeSingularOnBorder(GeometricMesh& g, const Loop& loop, const Border& border,
                          const CrumpleParams& params, const CounterRng& rng,
                          std::uint64_t& drawIndex) {
  const int a = loop.v[idx(border.loopEdge)];
  const int b = loop.next(idx(border.loopEdge));
  const Vec2& pa = g.vertices[idx(a)].pattern;
  const Vec2& pb = g.vertices[idx(b)].pattern;
  const double len = (pb - pa).norm();
  const double u0 = (border.hit - pa).norm() / len;
  const double shift = normalDeviate(rng, drawIndex) * params.sigma / std::sqrt(2.0);
  const double u = std::clamp(u0 + shift / len, 0.15, 0.85);
  if (crowded(g, pa + u * (pb - pa), params)) return -1;
  return insertSingularOnEdge(g, a, b, pa + u * (pb - pa));
}

// paper Sec. 5.2 and Fig. 11 (curved case): the strip meets the border ruling
// e_lim of a curved region C. Following v-perp into C, e_sing is the first
// ruling with a dihedral angle above theta_0 (e_lim itself if none); the
// singular vertex s is drawn uniform along e_sing and normal across it with
// the law exp(-d^2/sigma^2), kept inside C. C's rulings from e_lim up to e_sup
// (the next ruling past s above theta_0, or C's far end) are replaced by two
// fans of rulings from s with a flat transition triangle, and the triangle
// between e_lim and s joins F. Returns s, or -1 (nothing changed) when C is
// already a cone with an apex.
int insertSingularInCurved(GeometricMesh& g, int flat, const Loop& loop, const Border& border,
                           const CrumpleParams& params, const CounterRng& rng,
                           std::uint64_t& drawIndex) {
  const int ea = loop.v[idx(border.loopEdge)];
  const int eb = loop.next(idx(border.loopEdge));
  const int across = loop.across[idx(border.loopEdge)];
  const int cr = g.faces[idx(across)].region;
  Region& curved = g.regions[idx(cr)];
  if (curved.apex >= 0 || curved.rulings.size() < 2) return -1;
  std::vector<Ruling> rulings = curved.rulings;
  const auto same = [](const Ruling& r, int x, int y) {
    return (r.a == x && r.b == y) || (r.a == y && r.b == x);
  };
  if (same(rulings.back(), ea, eb)) std::reverse(rulings.begin(), rulings.end());
  if (!same(rulings.front(), ea, eb)) return -1;  // the border is not C's end ruling
  const std::size_t n = rulings.size() - 1;       // cells 0..n-1
  // Orient every ruling so .a is on the same chain as rulings[0].a.
  for (std::size_t k = 1; k <= n; ++k) {
    const Vec2 a0 = g.vertices[idx(rulings[k - 1].a)].pattern;
    const Vec2 pa = g.vertices[idx(rulings[k].a)].pattern;
    const Vec2 pb = g.vertices[idx(rulings[k].b)].pattern;
    if ((pb - a0).norm() < (pa - a0).norm() && rulings[k].a != rulings[k - 1].a)
      std::swap(rulings[k].a, rulings[k].b);
  }
  const EdgeMap edges = edgeMap(g);
  const auto dihedralAt = [&](const Ruling& r) {
    const auto it = edges.find({std::min(r.a, r.b), std::max(r.a, r.b)});
    if (it == edges.end() || it->second[1] < 0) return 0.0;
    return dihedralAngle(g, it->second[0], it->second[1]);
  };
  std::size_t ksing = 0;
  for (std::size_t k = 1; k < n; ++k) {
    if (dihedralAt(rulings[k]) > params.theta0) {
      ksing = k;
      break;
    }
  }
  const auto P = [&](int v) -> const Vec2& { return g.vertices[idx(v)].pattern; };
  // Draw s: uniform along e_sing (kept off its ends), normal across it.
  const Vec2 sa = P(rulings[ksing].a);
  const Vec2 sb = P(rulings[ksing].b);
  const double along = 0.15 + 0.7 * rng.uniform(drawIndex++);
  double across2 = normalDeviate(rng, drawIndex) * params.sigma / std::sqrt(2.0);
  // With e_sing = e_lim the vertex must fall inside C, on the bending side.
  // (Mesh quality: at least a quarter of the first cell from e_lim, or the
  // triangle joining F would be a sliver.)
  if (ksing == 0)
    across2 = std::max(std::abs(across2), 0.25 * (P(rulings[1].a) - P(rulings[0].a)).norm());
  Vec2 normal(-(sb - sa).y(), (sb - sa).x());
  normal.normalize();
  // Positive offsets point away from e_lim, into C.
  if (normal.dot(0.5 * (P(rulings[n].a) + P(rulings[n].b)) - 0.5 * (sa + sb)) < 0.0)
    normal = -normal;
  Vec2 s = sa + along * (sb - sa) + across2 * normal;
  // Locate s in a cell j (0 <= j < n); outside C it is clamped onto e_sing.
  const auto inCell = [&](std::size_t j, const Vec2& p) {
    const std::array<Vec2, 4> q{P(rulings[j].a), P(rulings[j + 1].a), P(rulings[j + 1].b),
                                P(rulings[j].b)};
    int sign = 0;
    for (int k = 0; k < 4; ++k) {
      const double c = cross2(q[(k + 1) % 4] - q[k], p - q[k]);
      if (std::abs(c) < 1e-18) continue;
      const int sg = c > 0.0 ? 1 : -1;
      if (sign == 0) sign = sg;
      if (sg != sign) return false;
    }
    return true;
  };
  std::size_t cell = n;
  for (std::size_t j = 0; j < n && cell == n; ++j) {
    if (inCell(j, s)) cell = j;
  }
  if (cell == n) {
    s = sa + along * (sb - sa);
    if (ksing == 0) s += 0.25 * (P(rulings[1].a) - P(rulings[0].a)).norm() * normal;
    cell = ksing < n ? ksing : n - 1;
    if (!inCell(cell, s)) cell = ksing > 0 ? ksing - 1 : 0;
  }
  if (crowded(g, s, params)) return -1;
  // 3D position of s: barycentric in the cell's triangle holding it.
  std::optional<GeometricVertex> placed = vertexInCell(g, rulings[cell], rulings[cell + 1], s);
  if (!placed) return -1;
  GeometricVertex sv = *placed;
  sv.singular = true;
  // e_sup: the next ruling past s above theta_0, else C's far end.
  std::size_t sup = n;
  for (std::size_t k = cell + 1; k < n; ++k) {
    if (dihedralAt(rulings[k]) > params.theta0) {
      sup = k;
      break;
    }
  }
  const int sIndex = addVertex(g, sv);
  // Rebuild: C keeps rulings sup..n; fans from s on both chains; transition
  // triangle (s, a_sup, b_sup) flat; triangle (s, a_0, b_0) joins F.
  removeRegionFaces(g, cr);
  Region& c2 = g.regions[idx(cr)];
  c2.rulings.assign(rulings.begin() + static_cast<std::ptrdiff_t>(sup), rulings.end());
  if (c2.rulings.size() >= 2) rebuildCurvedFaces(g, cr);
  addConeFans(g, sIndex, rulings, 0, sup);
  addTriangleCCW(g, sIndex, rulings[sup].a, rulings[sup].b, addRegion(g, mesh::RegionType::Flat));
  addTriangleCCW(g, sIndex, rulings[0].a, rulings[0].b, flat);
  return sIndex;
}

}  // namespace crumple::paper::detail
