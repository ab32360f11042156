// Sound-source events and resonators (thesis 4.3.2; docs/SOUND.md "Events").
#include "crumple/sound/events.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>

namespace crumple::sound {
namespace {

// What the resonators need of a frame's mesh, built once per frame.
struct Topology {
  std::vector<mesh::MeshEdge> edges;
  std::vector<std::array<int, 3>> edgesOfTriangle;  // edge indices, opposite vertex k
  std::vector<Vec3> normals;                        // unit, front side (pattern CCW)
  std::vector<double> areas;
  std::vector<double> dihedral;    // per edge (0 on the border)
  std::vector<char> curvedBorder;  // per edge: a border bent enough to vibrate
  std::vector<char> flatRegion;    // per triangle: a planar region of the crumpling model
};

// A region reached by less than this share of an event's area makes no resonator.
constexpr double kMinShare = 0.05;
// The outline turns by more than this at a corner (rad): 30 degrees.
constexpr double kCornerAngle = std::numbers::pi / 6.0;

const std::vector<Vec3>& positionsOf(const SheetFrame& f) { return f.mesh->positions; }

Topology buildTopology(const SheetFrame& frame, const EventParams& params) {
  const mesh::SheetMesh& m = *frame.mesh;
  Topology t;
  t.edges = mesh::buildEdges(m);
  const std::size_t nt = m.triangles.size();
  t.edgesOfTriangle.assign(nt, {-1, -1, -1});
  for (std::size_t e = 0; e < t.edges.size(); ++e)
    for (int side = 0; side < 2; ++side) {
      const int tri = t.edges[e].triangles[static_cast<std::size_t>(side)];
      if (tri < 0) continue;
      const auto& tv = m.triangles[static_cast<std::size_t>(tri)];
      for (int k = 0; k < 3; ++k)
        if (tv[static_cast<std::size_t>(k)] != t.edges[e].v[0] &&
            tv[static_cast<std::size_t>(k)] != t.edges[e].v[1])
          t.edgesOfTriangle[static_cast<std::size_t>(tri)][static_cast<std::size_t>(k)] =
              static_cast<int>(e);
    }
  const auto& x = positionsOf(frame);
  t.normals.resize(nt);
  t.areas.resize(nt);
  t.flatRegion.assign(nt, 0);
  for (std::size_t i = 0; i < nt; ++i) {
    const auto& tv = m.triangles[i];
    const Vec3 c =
        (x[static_cast<std::size_t>(tv[1])] - x[static_cast<std::size_t>(tv[0])])
            .cross(x[static_cast<std::size_t>(tv[2])] - x[static_cast<std::size_t>(tv[0])]);
    const double n = c.norm();
    t.areas[i] = 0.5 * n;
    t.normals[i] = n > 0.0 ? Vec3(c / n) : Vec3::Zero();
    if (frame.developableRegions && !m.regionOfTriangle.empty()) {
      const auto region = static_cast<std::size_t>(m.regionOfTriangle[i]);
      t.flatRegion[i] =
          region < m.regionTypes.size() && m.regionTypes[region] == mesh::RegionType::Flat;
    }
  }
  t.dihedral.assign(t.edges.size(), 0.0);
  for (std::size_t e = 0; e < t.edges.size(); ++e) {
    if (!t.edges[e].interior()) continue;
    const Vec3& a = t.normals[static_cast<std::size_t>(t.edges[e].triangles[0])];
    const Vec3& b = t.normals[static_cast<std::size_t>(t.edges[e].triangles[1])];
    t.dihedral[e] = std::atan2(a.cross(b).norm(), a.dot(b));
  }
  // The border's normal curvature at each border vertex: the turning of the
  // border polyline along the surface normal (its in-plane turning, the
  // outline's own shape, does not count). Unknown at the outline's corners
  // (turning more than kCornerAngle in the pattern), where the faceted
  // normal's error would dominate: an edge there takes its other end's.
  std::vector<std::vector<int>> borderEdgesAt(m.vertexCount());
  for (std::size_t e = 0; e < t.edges.size(); ++e)
    if (!t.edges[e].interior())
      for (int v : t.edges[e].v)
        borderEdgesAt[static_cast<std::size_t>(v)].push_back(static_cast<int>(e));
  std::vector<Vec3> vertexNormal(m.vertexCount(), Vec3::Zero());
  for (std::size_t i = 0; i < nt; ++i)
    for (int v : m.triangles[i])
      vertexNormal[static_cast<std::size_t>(v)] += t.areas[i] * t.normals[i];
  std::vector<double> borderCurvature(m.vertexCount(), -1.0);  // -1: unknown
  for (std::size_t v = 0; v < m.vertexCount(); ++v) {
    if (borderEdgesAt[v].size() != 2 || vertexNormal[v].norm() == 0.0) continue;
    const auto other = [&](int e) {
      const auto& ev = t.edges[static_cast<std::size_t>(e)].v;
      return static_cast<std::size_t>(ev[0] == static_cast<int>(v) ? ev[1] : ev[0]);
    };
    const std::size_t before = other(borderEdgesAt[v][0]), after = other(borderEdgesAt[v][1]);
    const Vec2 pa = m.pattern[v] - m.pattern[before], pb = m.pattern[after] - m.pattern[v];
    if (pa.norm() == 0.0 || pb.norm() == 0.0 ||
        std::abs(pa.normalized().dot(pb.normalized())) < std::cos(kCornerAngle))
      continue;
    const Vec3 a = x[v] - x[before];
    const Vec3 b = x[after] - x[v];
    const double la = a.norm(), lb = b.norm();
    if (la == 0.0 || lb == 0.0) continue;
    // The two edges in either order: the turning's sign does not matter.
    const Vec3 turning = b / lb - a / la;
    borderCurvature[v] = std::abs(turning.dot(vertexNormal[v].normalized())) * 2.0 / (la + lb);
  }
  t.curvedBorder.assign(t.edges.size(), 0);
  const double minCurvature = 1.0 / params.freeBorderRadius;
  for (std::size_t e = 0; e < t.edges.size(); ++e) {
    if (t.edges[e].interior()) continue;
    const auto& ev = t.edges[e].v;
    const double k0 = borderCurvature[static_cast<std::size_t>(ev[0])];
    const double k1 = borderCurvature[static_cast<std::size_t>(ev[1])];
    const double k = k0 >= 0.0 && k1 >= 0.0 ? 0.5 * (k0 + k1) : std::max(k0, k1);
    t.curvedBorder[e] =
        k >= minCurvature && !t.flatRegion[static_cast<std::size_t>(t.edges[e].triangles[0])];
  }
  return t;
}

// Thesis 4.3.2: the regions an event sets vibrating, grown from its
// triangles across edges below a_max without a held or touching end; one
// resonator per region reached (Fig. 4.11), sized as Fig. 4.12.
// `blocked`: vertices the growth does not pass; `fixed`: vertices whose
// border edges are not free (held or touching).
std::vector<Resonator> growResonators(const SheetFrame& frame, const Topology& t,
                                      const std::vector<int>& seeds,
                                      const std::vector<char>& blocked,
                                      const std::vector<char>& fixed, const EventParams& params) {
  const mesh::SheetMesh& m = *frame.mesh;
  const std::size_t nt = m.triangles.size();
  std::vector<char> reached(nt, 0);
  std::deque<int> queue;
  for (int s : seeds)
    if (!reached[static_cast<std::size_t>(s)]) {
      reached[static_cast<std::size_t>(s)] = 1;
      queue.push_back(s);
    }
  const auto isBlocked = [&](int v) { return blocked[static_cast<std::size_t>(v)] != 0; };
  while (!queue.empty()) {
    const int tri = queue.front();
    queue.pop_front();
    for (int e : t.edgesOfTriangle[static_cast<std::size_t>(tri)]) {
      if (e < 0) continue;
      const auto& edge = t.edges[static_cast<std::size_t>(e)];
      if (!edge.interior() || t.dihedral[static_cast<std::size_t>(e)] > params.maxDihedral ||
          isBlocked(edge.v[0]) || isBlocked(edge.v[1]))
        continue;
      const int next = edge.triangles[0] == tri ? edge.triangles[1] : edge.triangles[0];
      if (reached[static_cast<std::size_t>(next)]) continue;
      reached[static_cast<std::size_t>(next)] = 1;
      queue.push_back(next);
    }
  }
  // One resonator per region reached (Fig. 4.11). A region, as the thesis
  // has it: a curved region; or a flat region, the connected near-coplanar
  // triangles the crumpling model's many small flat pieces make together
  // (4.3.2: "the angle between two adjacent triangles is smaller than
  // eps_a"); the elastic model's sheet is one region. Two triangles reached
  // join across their edge below a_max (a held or touching end does not
  // part what the event itself set vibrating) within one region id, or
  // between two flat-typed ones.
  std::vector<int> parent(nt);
  for (std::size_t i = 0; i < nt; ++i) parent[i] = static_cast<int>(i);
  const auto root = [&](int i) {
    while (parent[static_cast<std::size_t>(i)] != i)
      i = parent[static_cast<std::size_t>(i)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    return i;
  };
  const auto regionOf = [&](int tri) {
    return m.regionOfTriangle.empty() ? 0 : m.regionOfTriangle[static_cast<std::size_t>(tri)];
  };
  for (std::size_t e = 0; e < t.edges.size(); ++e) {
    const auto& edge = t.edges[e];
    if (!edge.interior()) continue;
    const int a = edge.triangles[0], b = edge.triangles[1];
    if (!reached[static_cast<std::size_t>(a)] || !reached[static_cast<std::size_t>(b)] ||
        t.dihedral[e] > params.maxDihedral)
      continue;
    const bool bothFlat =
        t.flatRegion[static_cast<std::size_t>(a)] && t.flatRegion[static_cast<std::size_t>(b)];
    if (regionOf(a) != regionOf(b) && !bothFlat) continue;
    const int ra = root(a), rb = root(b);
    if (ra != rb) parent[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
  }
  struct Group {
    double area = 0.0, border = 0.0;
    Vec3 centre = Vec3::Zero(), normal = Vec3::Zero();
    std::vector<int> triangles;
  };
  std::map<int, Group> groups;
  double reachedArea = 0.0;
  const auto& x = positionsOf(frame);
  for (std::size_t i = 0; i < nt; ++i) {
    if (!reached[i]) continue;
    Group& g = groups[root(static_cast<int>(i))];
    const auto& tv = m.triangles[i];
    const double a = t.areas[i];
    g.area += a;
    reachedArea += a;
    g.centre += a *
                (x[static_cast<std::size_t>(tv[0])] + x[static_cast<std::size_t>(tv[1])] +
                 x[static_cast<std::size_t>(tv[2])]) /
                3.0;
    g.normal += a * t.normals[i];
    g.triangles.push_back(static_cast<int>(i));
    for (int e : t.edgesOfTriangle[i]) {
      if (e < 0) continue;
      const auto& edge = t.edges[static_cast<std::size_t>(e)];
      if (edge.interior() || !t.curvedBorder[static_cast<std::size_t>(e)] ||
          fixed[static_cast<std::size_t>(edge.v[0])] || fixed[static_cast<std::size_t>(edge.v[1])])
        continue;
      g.border +=
          (x[static_cast<std::size_t>(edge.v[0])] - x[static_cast<std::size_t>(edge.v[1])]).norm();
    }
  }
  std::vector<Resonator> out;
  std::vector<char> inGroup(m.vertexCount(), 0);
  for (auto& [region, g] : groups) {
    // A sliver of a region (under 5 % of what the event reached) adds
    // nothing audible: a^3 makes it silent.
    if (g.area <= 0.0 || (groups.size() > 1 && g.area < kMinShare * reachedArea)) continue;
    Resonator r;
    r.area = g.area;
    r.centre = g.centre / g.area;
    r.normal = g.normal.norm() > 0.0 ? Vec3(g.normal.normalized()) : Vec3::UnitY();
    r.radius = std::sqrt(g.area / std::numbers::pi);
    r.border = g.border >= params.minFreeBorder ? g.border : 0.0;
    // l_r: the mean length of the rulings inside; without rulings (a flat
    // region, the elastic model), the length that makes l_r x l_c / 2 its
    // area, as the thesis' recorded rectangles (4.3.3), at most the
    // resonator's diameter; sqrt(area) without a free border.
    for (int tri : g.triangles)
      for (int v : m.triangles[static_cast<std::size_t>(tri)])
        inGroup[static_cast<std::size_t>(v)] = 1;
    double sum = 0.0;
    int count = 0;
    for (const auto& ruling : frame.rulings)
      if (inGroup[static_cast<std::size_t>(ruling[0])] &&
          inGroup[static_cast<std::size_t>(ruling[1])]) {
        sum += (x[static_cast<std::size_t>(ruling[0])] - x[static_cast<std::size_t>(ruling[1])])
                   .norm();
        ++count;
      }
    double diameter = 0.0;
    for (int tri : g.triangles)
      for (int v : m.triangles[static_cast<std::size_t>(tri)]) {
        inGroup[static_cast<std::size_t>(v)] = 0;
        diameter = std::max(diameter, 2.0 * (x[static_cast<std::size_t>(v)] - r.centre).norm());
      }
    r.ruling = count > 0        ? sum / count
               : r.border > 0.0 ? std::min(2.0 * r.area / r.border, diameter)
                                : std::sqrt(r.area);
    out.push_back(r);
  }
  return out;
}

void checkFrame(const SheetFrame& frame) {
  if (frame.mesh == nullptr) throw std::invalid_argument("sound events: a frame without a mesh");
  const mesh::SheetMesh& m = *frame.mesh;
  const std::size_t nv = m.vertexCount();
  if (m.positions.size() != nv)
    throw std::invalid_argument("sound events: " + std::to_string(m.positions.size()) +
                                " positions for " + std::to_string(nv) + " pattern points");
  if (!m.regionOfTriangle.empty() && m.regionOfTriangle.size() != m.triangles.size())
    throw std::invalid_argument("sound events: region ids do not match the triangles");
  for (const auto& tv : m.triangles)
    for (int v : tv)
      if (v < 0 || static_cast<std::size_t>(v) >= nv)
        throw std::invalid_argument("sound events: triangle vertex " + std::to_string(v) +
                                    " out of range");
  for (const Vec3& p : m.positions)
    if (!p.allFinite()) throw std::invalid_argument("sound events: a non-finite position");
  const auto vertexOk = [&](int v) { return v >= 0 && static_cast<std::size_t>(v) < nv; };
  for (const auto& r : frame.rulings)
    if (!vertexOk(r[0]) || !vertexOk(r[1]))
      throw std::invalid_argument("sound events: a ruling's vertex is out of range");
  for (int v : frame.heldVertices)
    if (!vertexOk(v)) throw std::invalid_argument("sound events: a held vertex is out of range");
  for (const auto& c : frame.contacts)
    if (!vertexOk(c.vertex) || !std::isfinite(c.slideSpeed) || c.slideSpeed < 0.0)
      throw std::invalid_argument("sound events: a malformed contact");
  if (!frame.tearAdvances.empty() && !(frame.frameDuration > 0.0))
    throw std::invalid_argument("sound events: tear advances need the frame's duration");
}

std::vector<char> blockedVertices(const SheetFrame& frame) {
  std::vector<char> blocked(frame.mesh->vertexCount(), 0);
  for (int v : frame.heldVertices) blocked[static_cast<std::size_t>(v)] = 1;
  for (const auto& c : frame.contacts) blocked[static_cast<std::size_t>(c.vertex)] = 1;
  return blocked;
}

// Point location in the pattern: the triangles in buckets of a uniform grid.
class PatternLocator {
 public:
  explicit PatternLocator(const mesh::SheetMesh& m) : m_(m) {
    lo_ = hi_ = m.pattern.empty() ? Vec2::Zero() : m.pattern.front();
    for (const Vec2& p : m.pattern) {
      lo_ = lo_.cwiseMin(p);
      hi_ = hi_.cwiseMax(p);
    }
    const double n = std::max<double>(1.0, std::sqrt(static_cast<double>(m.triangles.size())));
    nx_ = ny_ = static_cast<int>(std::ceil(n));
    const Vec2 size = (hi_ - lo_).cwiseMax(Vec2::Constant(1e-12));
    cell_ = Vec2(size.x() / nx_, size.y() / ny_);
    buckets_.assign(static_cast<std::size_t>(nx_ * ny_), {});
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      Vec2 a = m.pattern[static_cast<std::size_t>(m.triangles[t][0])], b = a;
      for (int v : m.triangles[t]) {
        a = a.cwiseMin(m.pattern[static_cast<std::size_t>(v)]);
        b = b.cwiseMax(m.pattern[static_cast<std::size_t>(v)]);
      }
      const auto [i0, j0] = bucket(a);
      const auto [i1, j1] = bucket(b);
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i)
          buckets_[static_cast<std::size_t>(j * nx_ + i)].push_back(static_cast<int>(t));
    }
  }

  struct Hit {
    int triangle = -1;
    Vec3 weights = Vec3::Zero();
  };
  // The triangle holding p (the first in index order, within a hair of its
  // edges), nullopt off the sheet.
  std::optional<Hit> locate(const Vec2& p) const {
    if ((p.array() < lo_.array()).any() || (p.array() > hi_.array()).any()) return std::nullopt;
    const auto [i, j] = bucket(p);
    for (int t : buckets_[static_cast<std::size_t>(j * nx_ + i)]) {
      const auto& tv = m_.triangles[static_cast<std::size_t>(t)];
      const Vec2& a = m_.pattern[static_cast<std::size_t>(tv[0])];
      const Vec2& b = m_.pattern[static_cast<std::size_t>(tv[1])];
      const Vec2& c = m_.pattern[static_cast<std::size_t>(tv[2])];
      const double d = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
      if (d == 0.0) continue;
      const double wb = ((p - a).x() * (c - a).y() - (p - a).y() * (c - a).x()) / d;
      const double wc = ((b - a).x() * (p - a).y() - (b - a).y() * (p - a).x()) / d;
      const double wa = 1.0 - wb - wc;
      constexpr double kTolerance = -1e-9;
      if (wa >= kTolerance && wb >= kTolerance && wc >= kTolerance) return Hit{t, Vec3(wa, wb, wc)};
    }
    return std::nullopt;
  }

 private:
  std::pair<int, int> bucket(const Vec2& p) const {
    const int i = std::clamp(static_cast<int>((p.x() - lo_.x()) / cell_.x()), 0, nx_ - 1);
    const int j = std::clamp(static_cast<int>((p.y() - lo_.y()) / cell_.y()), 0, ny_ - 1);
    return {i, j};
  }
  const mesh::SheetMesh& m_;
  Vec2 lo_, hi_, cell_;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> buckets_;
};

Vec3 surfacePoint(const mesh::SheetMesh& m, const PatternLocator::Hit& hit) {
  const auto& tv = m.triangles[static_cast<std::size_t>(hit.triangle)];
  return hit.weights[0] * m.positions[static_cast<std::size_t>(tv[0])] +
         hit.weights[1] * m.positions[static_cast<std::size_t>(tv[1])] +
         hit.weights[2] * m.positions[static_cast<std::size_t>(tv[2])];
}

}  // namespace

EventDetector::EventDetector(const EventParams& params) : params_(params) {
  if (!(params.gridSpacing > 0.0) || !std::isfinite(params.gridSpacing))
    throw std::invalid_argument("sound events: the grid spacing must be positive");
  if (params.maxGridPoints < 16)
    throw std::invalid_argument("sound events: at least 16 grid points");
  if (!(params.curvatureThreshold > 0.0) || !std::isfinite(params.curvatureThreshold))
    throw std::invalid_argument("sound events: the curvature threshold must be positive");
  if (!(params.maxDihedral > 0.0 && params.maxDihedral < std::numbers::pi))
    throw std::invalid_argument("sound events: a_max must be in (0, pi)");
  if (!(params.freeBorderRadius > 0.0) || !std::isfinite(params.freeBorderRadius))
    throw std::invalid_argument("sound events: the free border radius must be positive");
  if (!(params.minFreeBorder >= 0.0) || !std::isfinite(params.minFreeBorder))
    throw std::invalid_argument("sound events: the shortest free border must be >= 0");
  if (!(params.maxTearGap > 0.0) || !std::isfinite(params.maxTearGap))
    throw std::invalid_argument("sound events: the longest tear gap must be positive");
  if (!(params.minSlideSpeed >= 0.0) || !std::isfinite(params.minSlideSpeed))
    throw std::invalid_argument("sound events: the minimum slide speed must be >= 0");
}

void EventDetector::saveState(StateWriter& out) const {
  out.tag("SEVD");
  out.f64(step_);
  out.vec2(origin_);
  out.i32(nx_);
  out.i32(ny_);
  out.count(previous_.size());
  for (const auto& h : previous_) {
    out.boolean(h.has_value());
    out.f64(h.value_or(0.0));
  }
  out.count(lastAdvance_.size());
  for (const auto& [tear, time] : lastAdvance_) {
    out.i32(tear);
    out.f64(time);
  }
}

void EventDetector::restoreState(StateReader& in) {
  in.tag("SEVD");
  step_ = in.f64();
  origin_ = in.vec2();
  nx_ = in.i32();
  ny_ = in.i32();
  const std::size_t n = in.count(9);
  if (nx_ < 0 || ny_ < 0 || n != static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_))
    in.fail("the sound grid's size does not match its points");
  previous_.assign(n, std::nullopt);
  for (auto& h : previous_) {
    const bool defined = in.boolean();
    const double value = in.f64();
    if (defined) h = value;
  }
  lastAdvance_.clear();
  const std::size_t tears = in.count(12);
  for (std::size_t k = 0; k < tears; ++k) {
    const int tear = in.i32();
    lastAdvance_[tear] = in.f64();
  }
}

std::vector<Resonator> findResonators(const SheetFrame& frame,
                                      const std::vector<int>& seedTriangles,
                                      const std::vector<char>& blocked, const EventParams& params) {
  checkFrame(frame);
  if (blocked.size() != frame.mesh->vertexCount())
    throw std::invalid_argument("findResonators: one blocked flag per vertex");
  for (int s : seedTriangles)
    if (s < 0 || static_cast<std::size_t>(s) >= frame.mesh->triangles.size())
      throw std::invalid_argument("findResonators: a seed triangle out of range");
  return growResonators(frame, buildTopology(frame, params), seedTriangles, blocked, blocked,
                        params);
}

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// The curvature grid over the pattern (thesis 4.3.2, Fig. 4.10): its step, first point and size.
struct GridGeometry {
  double step = 0.0;
  Vec2 origin = Vec2::Zero();
  int nx = 0, ny = 0;
};

// thesis 4.3.2, Fig. 4.10: the shot's grid over the pattern's bounds, centred, at the step
// asked for or larger for a big sheet.
GridGeometry shotGrid(const mesh::SheetMesh& m, const EventParams& params) {
  GridGeometry grid;
  Vec2 lo = m.pattern.front(), hi = lo;
  for (const Vec2& p : m.pattern) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Vec2 size = hi - lo;
  grid.step = std::max(params.gridSpacing,
                       std::sqrt(std::max(size.x() * size.y(), 0.0) / params.maxGridPoints));
  grid.nx = static_cast<int>(std::floor(size.x() / grid.step)) + 1;
  grid.ny = static_cast<int>(std::floor(size.y() / grid.step)) + 1;
  grid.origin = lo + 0.5 * (size - Vec2((grid.nx - 1) * grid.step, (grid.ny - 1) * grid.step));
  return grid;
}

// The sheet at each grid point: its surface point and triangle (-1: off the sheet).
struct GridSamples {
  std::vector<std::optional<Vec3>> point;
  std::vector<int> triangleAt;
};

// thesis 4.3.2: the surface point of every grid point, located in the pattern.
GridSamples sampleGrid(const mesh::SheetMesh& m, const PatternLocator& locator,
                       const GridGeometry& grid) {
  const std::size_t n = static_cast<std::size_t>(grid.nx * grid.ny);
  GridSamples samples;
  samples.point.resize(n);
  samples.triangleAt.assign(n, -1);
  for (int j = 0; j < grid.ny; ++j)
    for (int i = 0; i < grid.nx; ++i) {
      const std::size_t k = static_cast<std::size_t>(j * grid.nx + i);
      if (const auto hit = locator.locate(grid.origin + grid.step * Vec2(i, j))) {
        samples.point[k] = surfacePoint(m, *hit);
        samples.triangleAt[k] = hit->triangle;
      }
    }
  return samples;
}

// thesis 4.3.2: the mean curvature H = (Laplacian . n) / 2 at each grid point by central
// differences; undefined where a neighbour is off the sheet or across an opened tear.
std::vector<std::optional<double>> gridCurvature(const std::vector<std::optional<Vec3>>& point,
                                                 const GridGeometry& grid) {
  const int nx = grid.nx, ny = grid.ny;
  std::vector<std::optional<double>> now(point.size());
  const double h2 = grid.step * grid.step;
  for (int j = 1; j + 1 < ny; ++j)
    for (int i = 1; i + 1 < nx; ++i) {
      const std::size_t k = static_cast<std::size_t>(j * nx + i);
      const auto& e = point[k + 1];
      const auto& w = point[k - 1];
      const auto& nn = point[k + static_cast<std::size_t>(nx)];
      const auto& s = point[k - static_cast<std::size_t>(nx)];
      if (!point[k] || !e || !w || !nn || !s) continue;
      const Vec3& p = *point[k];
      const double reach = 2.0 * grid.step;
      if ((*e - p).norm() > reach || (*w - p).norm() > reach || (*nn - p).norm() > reach ||
          (*s - p).norm() > reach)
        continue;
      const Vec3 normal = (*e - *w).cross(*nn - *s);
      if (normal.norm() == 0.0) continue;
      const Vec3 laplacian = (*e + *w + *nn + *s - 4.0 * p) / h2;
      now[k] = 0.5 * laplacian.dot(normal.normalized());
    }
  return now;
}

// A frame's Topology, built the first time an event needs it.
class LazyTopology {
 public:
  LazyTopology(const SheetFrame& frame, const EventParams& params)
      : frame_(frame), params_(params) {}
  const Topology& get() {
    if (!topology_) topology_ = buildTopology(frame_, params_);
    return *topology_;
  }

 private:
  const SheetFrame& frame_;
  const EventParams& params_;
  std::optional<Topology> topology_;
};

// What the event searches of one frame share: its resonators' inputs and where events go.
struct EventSearch {
  const SheetFrame& frame;
  const EventParams& params;
  const std::vector<char>& blocked;  // held and touching vertices
  LazyTopology& topology;
  double& resonatorMs;  // time spent growing resonators
  std::vector<SoundEvent>& events;
};

// thesis 4.3.2 "Event Detection": crumpling events, the 4-connected patches of grid points
// whose curvature changed sign the same way by more than the threshold, with their resonators.
void crumplingEvents(EventSearch& out, const GridGeometry& grid, const GridSamples& samples,
                     const std::vector<std::optional<double>>& now,
                     const std::vector<std::optional<double>>& previous) {
  const std::vector<std::optional<Vec3>>& point = samples.point;
  const std::vector<int>& triangleAt = samples.triangleAt;
  const int nx = grid.nx, ny = grid.ny;
  const std::size_t n = now.size();
  const double h2 = grid.step * grid.step;
  std::vector<int> flag(n, 0);  // +1: became positive, -1: became negative
  for (std::size_t k = 0; k < n; ++k) {
    if (!now[k] || !previous[k]) continue;
    const double a = *previous[k], b = *now[k];
    if (a * b < 0.0 && std::abs(b - a) > out.params.curvatureThreshold) flag[k] = b > 0.0 ? 1 : -1;
  }
  std::vector<char> seen(n, 0);
  for (std::size_t start = 0; start < n; ++start) {
    if (flag[start] == 0 || seen[start]) continue;
    SoundEvent ev;
    ev.kind = EventKind::Crumpling;
    std::vector<int> seeds;
    std::vector<std::size_t> stack{start};
    seen[start] = 1;
    int count = 0;
    while (!stack.empty()) {
      const std::size_t k = stack.back();
      stack.pop_back();
      ev.amplitude += std::abs(*now[k] - *previous[k]) * h2;
      ev.position += *point[k];
      ++count;
      seeds.push_back(triangleAt[k]);
      const int i = static_cast<int>(k) % nx, j = static_cast<int>(k) / nx;
      const std::pair<int, int> around[] = {{i + 1, j}, {i - 1, j}, {i, j + 1}, {i, j - 1}};
      for (const auto& [a, b] : around) {
        if (a < 0 || b < 0 || a >= nx || b >= ny) continue;
        const std::size_t q = static_cast<std::size_t>(b * nx + a);
        if (seen[q] || flag[q] != flag[start]) continue;
        seen[q] = 1;
        stack.push_back(q);
      }
    }
    ev.position /= count;
    std::sort(seeds.begin(), seeds.end());
    seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
    ev.normal = out.topology.get().normals[static_cast<std::size_t>(seeds.front())];
    const auto grow = Clock::now();
    ev.resonators =
        growResonators(out.frame, out.topology.get(), seeds, out.blocked, out.blocked, out.params);
    out.resonatorMs += msSince(grow);
    out.events.push_back(std::move(ev));
  }
}

// thesis 4.3.2 "Event Detection": friction events, the touching vertices connected by the
// mesh's edges, at their mean sliding speed, each with its resonators.
void frictionEvents(EventSearch& out) {
  const SheetFrame& frame = out.frame;
  const mesh::SheetMesh& m = *frame.mesh;
  std::vector<double> speed(m.vertexCount(), -1.0);
  for (const auto& c : frame.contacts)
    speed[static_cast<std::size_t>(c.vertex)] =
        std::max(speed[static_cast<std::size_t>(c.vertex)], c.slideSpeed);
  const Topology& t = out.topology.get();
  std::vector<std::vector<int>> neighbours(m.vertexCount());
  for (const auto& e : t.edges)
    if (speed[static_cast<std::size_t>(e.v[0])] >= 0.0 &&
        speed[static_cast<std::size_t>(e.v[1])] >= 0.0) {
      neighbours[static_cast<std::size_t>(e.v[0])].push_back(e.v[1]);
      neighbours[static_cast<std::size_t>(e.v[1])].push_back(e.v[0]);
    }
  std::vector<std::vector<int>> trianglesAt(m.vertexCount());
  for (std::size_t i = 0; i < m.triangles.size(); ++i)
    for (int v : m.triangles[i])
      if (speed[static_cast<std::size_t>(v)] >= 0.0)
        trianglesAt[static_cast<std::size_t>(v)].push_back(static_cast<int>(i));
  std::vector<char> held(m.vertexCount(), 0);
  for (int v : frame.heldVertices) held[static_cast<std::size_t>(v)] = 1;
  std::vector<char> done(m.vertexCount(), 0);
  for (std::size_t v0 = 0; v0 < m.vertexCount(); ++v0) {
    if (speed[v0] < 0.0 || done[v0]) continue;
    std::vector<int> component, stack{static_cast<int>(v0)};
    done[v0] = 1;
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      component.push_back(v);
      for (int w : neighbours[static_cast<std::size_t>(v)])
        if (!done[static_cast<std::size_t>(w)]) {
          done[static_cast<std::size_t>(w)] = 1;
          stack.push_back(w);
        }
    }
    SoundEvent ev;
    ev.kind = EventKind::Friction;
    std::vector<int> seeds;
    for (int v : component) {
      ev.amplitude += speed[static_cast<std::size_t>(v)];
      ev.position += m.positions[static_cast<std::size_t>(v)];
      seeds.insert(seeds.end(), trianglesAt[static_cast<std::size_t>(v)].begin(),
                   trianglesAt[static_cast<std::size_t>(v)].end());
    }
    ev.amplitude /= static_cast<double>(component.size());
    ev.position /= static_cast<double>(component.size());
    if (ev.amplitude < out.params.minSlideSpeed || seeds.empty()) continue;
    std::sort(seeds.begin(), seeds.end());
    seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
    ev.normal = t.normals[static_cast<std::size_t>(seeds.front())];
    const auto grow = Clock::now();
    // The vibration starts where the sheet rubs and spreads from there:
    // the held points and the ridges stop it, the contacts do not (the
    // rubbing ones are its source, and a coarse mesh touches a table at
    // scattered vertices that would otherwise wall every patch in).
    ev.resonators = growResonators(frame, t, seeds, held, out.blocked, out.params);
    out.resonatorMs += msSince(grow);
    out.events.push_back(std::move(ev));
  }
}

// thesis 4.4: tearing events, each tear whose tip advanced, at its advance's length over the
// time since its previous advance (lastAdvance: tear -> that time).
void tearingEvents(EventSearch& out, const PatternLocator& locator,
                   std::map<int, double>& lastAdvance) {
  const SheetFrame& frame = out.frame;
  const mesh::SheetMesh& m = *frame.mesh;
  std::map<int, std::pair<double, Vec2>> tips;  // tear -> (length, last tip)
  for (const auto& a : frame.tearAdvances) {
    auto& [length, tip] = tips[a.tear];
    length += (a.to - a.from).norm();
    tip = a.to;
  }
  for (const auto& [tear, advance] : tips) {
    SoundEvent ev;
    ev.kind = EventKind::Tearing;
    ev.tear = tear;
    const auto last = lastAdvance.find(tear);
    ev.duration = last == lastAdvance.end()
                      ? frame.frameDuration
                      : std::clamp(frame.time - last->second, frame.frameDuration,
                                   std::max(frame.frameDuration, out.params.maxTearGap));
    lastAdvance[tear] = frame.time;
    ev.amplitude = advance.first / ev.duration;
    if (const auto hit = locator.locate(advance.second)) {
      ev.position = surfacePoint(m, *hit);
      ev.normal = out.topology.get().normals[static_cast<std::size_t>(hit->triangle)];
    } else {
      // The tip on the outline, a hair outside every triangle: its nearest vertex.
      std::size_t best = 0;
      for (std::size_t v = 1; v < m.vertexCount(); ++v)
        if ((m.pattern[v] - advance.second).squaredNorm() <
            (m.pattern[best] - advance.second).squaredNorm())
          best = v;
      ev.position = m.positions[best];
    }
    out.events.push_back(std::move(ev));
  }
}

}  // namespace

std::vector<SoundEvent> EventDetector::detect(const SheetFrame& frame) {
  const auto start = Clock::now();
  struct AddTime {
    double& total;
    Clock::time_point from;
    ~AddTime() { total += msSince(from); }
  } addTime{detectMs_, start};
  checkFrame(frame);
  const mesh::SheetMesh& m = *frame.mesh;
  std::vector<SoundEvent> events;
  if (m.triangles.empty()) return events;
  const PatternLocator locator(m);
  if (nx_ == 0) {
    // The grid (Fig. 4.10), fixed for the shot: over the pattern's bounds,
    // centred, at the step asked for or larger for a big sheet.
    const GridGeometry grid = shotGrid(m, params_);
    step_ = grid.step;
    nx_ = grid.nx;
    ny_ = grid.ny;
    origin_ = grid.origin;
    previous_.assign(static_cast<std::size_t>(nx_ * ny_), std::nullopt);
  }
  const GridGeometry grid{step_, origin_, nx_, ny_};
  const GridSamples samples = sampleGrid(m, locator, grid);
  // H = (Laplacian . n) / 2 by central differences over the grid's four
  // neighbours (the pattern is the surface's isometric chart); undefined
  // where a neighbour is off the sheet or across an opened tear.
  std::vector<std::optional<double>> now = gridCurvature(samples.point, grid);

  // Crumpling events: 4-connected patches whose curvature changed sign the
  // same way by more than the threshold; amplitude the sum of the changes.
  const std::vector<char> blocked = blockedVertices(frame);
  LazyTopology topology(frame, params_);
  EventSearch out{frame, params_, blocked, topology, resonatorMs_, events};
  crumplingEvents(out, grid, samples, now, previous_);
  previous_ = std::move(now);

  // Friction events: the touching vertices, connected by the mesh's edges;
  // amplitude their mean sliding speed.
  if (!frame.contacts.empty()) frictionEvents(out);

  // Tearing events (thesis 4.4): each tear whose tip advanced, at its
  // advance's length over the time since its previous advance.
  tearingEvents(out, locator, lastAdvance_);
  return events;
}

}  // namespace crumple::sound
