// Compressed flat regions become curved regions (paper Sec. 5.1-5.2 and
// Appendices A-B; thesis 2.4.2-2.4.3).
//
// The imaginary rulings of the paper are handled as a pencil of chords of
// the flat region F in the pattern: parallel chords along v-perp (case c1,
// both borders on dS) or chords through a singular vertex s (case c2). The
// strip of Appendix A is the run of chords around the compressed triangle
// that go from dS to dS without meeting a constrained border or a vertex
// that is not on dS; its extreme chords are r_lim1 and r_lim2 (Appendix B).
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>

#include "crumple/mesh/delaunay.hpp"
#include "crumple/paper/compression.hpp"
#include "crumple/paper/geometric_step.hpp"
#include "region_tools.hpp"

namespace crumple::paper {

namespace {

using detail::addBoundaryVertex;
using detail::addRegion;
using detail::EdgeMap;
using detail::edgeMap;
using detail::insideLoop;
using detail::Loop;
using detail::otherFace;
using detail::regionLoop;
using detail::triangulatePolygon;

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// A pencil of chords: parallel to `dir` (apex < 0) or through vertex `apex`.
// A chord is identified by its parameter: the signed offset n.x (parallel)
// or the angle from `dir` around the apex (conical).
struct Pencil {
  int apex = -1;
  Vec2 origin =
      Vec2::Zero();          // a point of chord 0 (the compressed triangle's centroid) or the apex
  Vec2 dir = Vec2::UnitX();  // direction of chord 0
};

struct ChordEnd {
  Vec2 p = Vec2::Zero();
  int loopEdge = -1;  // loop edge crossed (p strictly inside it), or -1
  int vertex = -1;    // the loop vertex the chord ends at, or -1
};

struct Chord {
  double param = 0.0;
  ChordEnd a;  // the -dir end (parallel) or the apex (conical)
  ChordEnd b;  // the +dir end
};

struct PencilFrame {
  Vec2 point;
  Vec2 dir;
};

PencilFrame chordLine(const GeometricMesh& g, const Pencil& pencil, double param) {
  if (pencil.apex < 0) {
    const Vec2 n(-pencil.dir.y(), pencil.dir.x());
    return {pencil.origin + param * n, pencil.dir};
  }
  const double c = std::cos(param);
  const double s = std::sin(param);
  const Vec2 d(c * pencil.dir.x() - s * pencil.dir.y(), s * pencil.dir.x() + c * pencil.dir.y());
  return {g.vertices[static_cast<std::size_t>(pencil.apex)].pattern, d};
}

double paramOf(const GeometricMesh& g, const Pencil& pencil, const Vec2& p) {
  if (pencil.apex < 0) {
    const Vec2 n(-pencil.dir.y(), pencil.dir.x());
    return n.dot(p - pencil.origin);
  }
  const Vec2 d = p - g.vertices[static_cast<std::size_t>(pencil.apex)].pattern;
  return std::atan2(cross2(pencil.dir, d), pencil.dir.dot(d));
}

// Crossings of the chord line with the loop, sorted along the line. Vertices
// exactly on the line are reported as vertex ends.
std::vector<std::pair<double, ChordEnd>> crossings(const GeometricMesh& g, const Loop& loop,
                                                   const PencilFrame& line, double tol) {
  std::vector<std::pair<double, ChordEnd>> out;
  const Vec2 n(-line.dir.y(), line.dir.x());
  const std::size_t m = loop.size();
  std::vector<double> side(m);
  for (std::size_t k = 0; k < m; ++k) {
    side[k] = n.dot(g.vertices[static_cast<std::size_t>(loop.v[k])].pattern - line.point);
    if (std::abs(side[k]) <= tol) side[k] = 0.0;
  }
  for (std::size_t k = 0; k < m; ++k) {
    const Vec2& pa = g.vertices[static_cast<std::size_t>(loop.v[k])].pattern;
    if (side[k] == 0.0) {
      ChordEnd e;
      e.p = pa;
      e.vertex = static_cast<int>(k);
      out.emplace_back(line.dir.dot(pa - line.point), e);
      continue;
    }
    const double s1 = side[(k + 1) % m];
    if (s1 != 0.0 && (side[k] > 0.0) != (s1 > 0.0)) {
      const Vec2& pb = g.vertices[static_cast<std::size_t>(loop.next(k))].pattern;
      const double u = side[k] / (side[k] - s1);
      ChordEnd e;
      e.p = pa + u * (pb - pa);
      e.loopEdge = static_cast<int>(k);
      out.emplace_back(line.dir.dot(e.p - line.point), e);
    }
  }
  std::sort(out.begin(), out.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  return out;
}

bool loopEdgeOnBoundary(const Loop& loop, int k) {
  return loop.across[static_cast<std::size_t>(k)] < 0;
}

bool vertexEndFree(const GeometricMesh& g, const Loop& loop, int k) {
  return g.vertices[static_cast<std::size_t>(loop.v[static_cast<std::size_t>(k)])].onBoundary;
}

struct Context {
  const GeometricMesh& g;
  const Loop& loop;
  const std::vector<int>& interior;  // region vertices not on the loop
  double tol;
};

// The chord at `param` if it runs from dS to dS (or from the apex to dS)
// through the region without touching a constrained border, else nullopt.
std::optional<Chord> evaluateChord(const Context& c, const Pencil& pencil, double param,
                                   const char** why = nullptr) {
  // Returns no chord, saying why when asked (for the remeshing notes).
  const auto fail = [why](const char* reason) -> std::optional<Chord> {
    if (why != nullptr) *why = reason;
    return std::nullopt;
  };
  const PencilFrame line = chordLine(c.g, pencil, param);
  auto hits = crossings(c.g, c.loop, line, c.tol);
  const auto endOk = [&](const ChordEnd& e) {
    if (e.vertex >= 0) return vertexEndFree(c.g, c.loop, e.vertex);
    return loopEdgeOnBoundary(c.loop, e.loopEdge);
  };
  Chord chord;
  chord.param = param;
  if (pencil.apex < 0) {
    // The chord through `origin`-side: the pair of consecutive hits whose
    // midpoint is inside the region and closest to the pencil's origin line.
    // With a simple region the valid chord has exactly two hits.
    if (hits.size() != 2) return fail("the chord crosses the region's border more than twice");
    chord.a = hits[0].second;
    chord.b = hits[1].second;
    if (!endOk(chord.a) || !endOk(chord.b)) return fail("the chord ends on a constrained border");
  } else {
    // From the apex forwards to the first hit that is not the apex itself.
    const int apexLoop = static_cast<int>(std::find(c.loop.v.begin(), c.loop.v.end(), pencil.apex) -
                                          c.loop.v.begin());
    std::optional<ChordEnd> first;
    for (const auto& [t, e] : hits) {
      if (e.vertex == apexLoop) continue;
      if (e.loopEdge >= 0 && (e.loopEdge == apexLoop ||
                              (e.loopEdge + 1) % static_cast<int>(c.loop.size()) == apexLoop)) {
        continue;
      }
      if (t <= c.tol) continue;
      first = e;
      break;
    }
    if (!first) return fail("the chord from the apex leaves the region at once");
    if (!endOk(*first)) return fail("the chord from the apex ends on a constrained border");
    chord.a.p = line.point;
    chord.a.vertex = apexLoop;
    chord.b = *first;
  }
  // A chord along a loop edge (the strip reaches a straight piece of the
  // border parallel to it): valid as the strip's limit when on dS.
  if (chord.a.vertex >= 0 && chord.b.vertex >= 0) {
    const int m = static_cast<int>(c.loop.size());
    const int i = chord.a.vertex;
    const int j = chord.b.vertex;
    if ((i + 1) % m == j)
      return loopEdgeOnBoundary(c.loop, i) ? std::optional<Chord>(chord)
                                           : fail("the chord runs along a constrained border");
    if ((j + 1) % m == i)
      return loopEdgeOnBoundary(c.loop, j) ? std::optional<Chord>(chord)
                                           : fail("the chord runs along a constrained border");
  }
  if (!insideLoop(c.g, c.loop, 0.5 * (chord.a.p + chord.b.p)))
    return fail("the chord runs outside the region");
  // No vertex of the region may lie on the chord (a singular or handle
  // vertex inside the strip, Appendix B: "no singular point inside").
  const Vec2 d = chord.b.p - chord.a.p;
  const double len2 = d.squaredNorm();
  for (int v : c.interior) {
    const Vec2& p = c.g.vertices[static_cast<std::size_t>(v)].pattern;
    const double t = (p - chord.a.p).dot(d) / len2;
    if (t > 0.0 && t < 1.0 &&
        std::abs(cross2(d, p - chord.a.p)) / std::sqrt(len2) <= 10.0 * c.tol) {
      return fail("a vertex inside the region lies on the chord");
    }
  }
  return chord;
}

// Appendix A-B: the run of valid chords around parameter 0, bounded by the
// extreme rulings r_lim1 and r_lim2. Returns the sorted chord parameters.
std::vector<double> stripParameters(const Context& c, const Pencil& pencil, double spacing,
                                    const char** why = nullptr) {
  std::vector<double> events;
  const auto addEvent = [&](int v) {
    if (v == pencil.apex) return;
    events.push_back(paramOf(c.g, pencil, c.g.vertices[static_cast<std::size_t>(v)].pattern));
  };
  for (int v : c.loop.v) addEvent(v);
  for (int v : c.interior) addEvent(v);
  const double limit = pencil.apex < 0 ? 1e300 : std::numbers::pi * 0.999;
  events.push_back(-limit);
  events.push_back(limit);
  std::sort(events.begin(), events.end());
  events.erase(std::unique(events.begin(), events.end(),
                           [&](double x, double y) { return std::abs(x - y) <= c.tol; }),
               events.end());
  // The interval holding parameter 0 (an event at 0 is fine: start just above it).
  std::size_t i0 = 0;
  while (i0 + 2 < events.size() && events[i0 + 1] <= 0.0) ++i0;
  const auto intervalValid = [&](std::size_t i) {
    return evaluateChord(c, pencil, 0.5 * (events[i] + events[i + 1])).has_value();
  };
  if (!intervalValid(i0)) {
    evaluateChord(c, pencil, 0.5 * (events[i0] + events[i0 + 1]), why);
    return {};
  }
  const auto eventOk = [&](double param) { return evaluateChord(c, pencil, param).has_value(); };
  // Extend up.
  std::size_t hiInterval = i0;
  double hi = 0.0;
  for (;;) {
    const double e = events[hiInterval + 1];
    if (hiInterval + 2 >= events.size()) {
      hi = 0.5 * (events[hiInterval] + e);
      break;
    }
    if (!eventOk(e)) {  // pull back into the interval
      hi = e - 0.35 * (e - events[hiInterval]);
      break;
    }
    if (!intervalValid(hiInterval + 1)) {
      hi = e;
      break;
    }
    ++hiInterval;
  }
  std::size_t loInterval = i0;
  double lo = 0.0;
  for (;;) {
    const double e = events[loInterval];
    if (loInterval == 0) {
      lo = 0.5 * (e + events[loInterval + 1]);
      break;
    }
    if (!eventOk(e)) {
      lo = e + 0.35 * (events[loInterval + 1] - e);
      break;
    }
    if (!intervalValid(loInterval - 1)) {
      lo = e;
      break;
    }
    --loInterval;
  }
  if (!(hi > lo)) return {};
  std::vector<double> params{lo};
  for (double e : events) {
    if (e > lo + c.tol && e < hi - c.tol) params.push_back(e);
  }
  params.push_back(hi);
  // Fill so consecutive ruling endpoints are at most `spacing` apart along
  // the boundary (the ruling density rho_bound, Appendix B).
  std::vector<double> filled{params.front()};
  for (std::size_t k = 0; k + 1 < params.size(); ++k) {
    const auto c0 = evaluateChord(c, pencil, params[k]);
    const auto c1 = evaluateChord(c, pencil, params[k + 1]);
    int pieces = 1;
    if (c0 && c1) {
      const double gap = std::max((c1->a.p - c0->a.p).norm(), (c1->b.p - c0->b.p).norm());
      pieces = std::max(1, static_cast<int>(std::ceil(gap / spacing - 1e-9)));
    }
    for (int j = 1; j <= pieces; ++j) {
      filled.push_back(params[k] + (params[k + 1] - params[k]) * j / pieces);
    }
  }
  return filled;
}

// Splits the interior edge (a, b) at pattern point p with a new singular
// vertex, splitting both incident triangles (paper Sec. 5.2, flat-flat case).
int insertSingularOnEdge(GeometricMesh& g, int a, int b, const Vec2& p) {
  const GeometricVertex& va = g.vertices[static_cast<std::size_t>(a)];
  const GeometricVertex& vb = g.vertices[static_cast<std::size_t>(b)];
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

struct Border {
  enum class Kind { Free, FlatFlat, Curved, None } kind = Kind::None;
  int loopEdge = -1;
  Vec2 hit = Vec2::Zero();
};

// Appendix A: walks from the compressed triangle's centroid along +-dir to
// the region's border and classifies it (Fig. 6 b-d).
Border findBorder(const GeometricMesh& g, const Loop& loop, const Vec2& origin, const Vec2& dir,
                  double tol) {
  const auto hits = crossings(g, loop, {origin, dir}, tol);
  Border border;
  for (const auto& [t, e] : hits) {
    if (t <= tol) continue;
    border.hit = e.p;
    if (e.vertex >= 0) {
      // Through a vertex: free if on dS, otherwise treat the next edge.
      border.kind = g.vertices[static_cast<std::size_t>(loop.v[static_cast<std::size_t>(e.vertex)])]
                            .onBoundary
                        ? Border::Kind::Free
                        : Border::Kind::None;
      return border;
    }
    border.loopEdge = e.loopEdge;
    const int across = loop.across[static_cast<std::size_t>(e.loopEdge)];
    if (across < 0) {
      border.kind = Border::Kind::Free;
    } else if (g.regions[static_cast<std::size_t>(g.faces[static_cast<std::size_t>(across)].region)]
                   .type == mesh::RegionType::Flat) {
      border.kind = Border::Kind::FlatFlat;
    } else {
      border.kind = Border::Kind::Curved;
    }
    return border;
  }
  return border;
}

// A vertex at pattern point s inside the curved cell between rulings r0 and
// r1: its 3D position and velocity by barycentric interpolation in the cell
// triangle holding it (the cell split along its first diagonal). nullopt when
// s lies in neither triangle.
std::optional<GeometricVertex> vertexInCell(const GeometricMesh& g, const Ruling& r0,
                                            const Ruling& r1, const Vec2& s) {
  const auto P = [&](int v) -> const Vec2& {
    return g.vertices[static_cast<std::size_t>(v)].pattern;
  };
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
    v.position = l0 * V[static_cast<std::size_t>(tri[0])].position +
                 l1 * V[static_cast<std::size_t>(tri[1])].position +
                 l2 * V[static_cast<std::size_t>(tri[2])].position;
    v.velocity = l0 * V[static_cast<std::size_t>(tri[0])].velocity +
                 l1 * V[static_cast<std::size_t>(tri[1])].velocity +
                 l2 * V[static_cast<std::size_t>(tri[2])].velocity;
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
    g.regions[static_cast<std::size_t>(fr)].rulings = fan;
    g.regions[static_cast<std::size_t>(fr)].apex = s;
    rebuildCurvedFaces(g, fr);
  }
}

// Appends the triangle (a, b, c), counter-clockwise in the pattern, to `region`.
void addTriangleCCW(GeometricMesh& g, int a, int b, int c, int region) {
  const auto P = [&](int v) -> const Vec2& {
    return g.vertices[static_cast<std::size_t>(v)].pattern;
  };
  GeometricFace f;
  f.v = {a, b, c, -1};
  if (cross2(P(b) - P(a), P(c) - P(a)) < 0.0) std::swap(f.v[1], f.v[2]);
  f.region = region;
  g.faces.push_back(f);
}

// Compression of an S_G triangle against its pattern (thesis 2.4.2).
TriangleCompression faceCompression(const GeometricMesh& g, const GeometricFace& face) {
  std::array<Vec2, 3> pattern;
  std::array<Vec3, 3> position;
  for (int k = 0; k < 3; ++k) {
    pattern[static_cast<std::size_t>(k)] = g.vertices[static_cast<std::size_t>(face.v[k])].pattern;
    position[static_cast<std::size_t>(k)] =
        g.vertices[static_cast<std::size_t>(face.v[k])].position;
  }
  return analyzeCompression(pattern, position);
}

// Draws a standard normal deviate from two uniforms (Box-Muller).
double normalDeviate(const CounterRng& rng, std::uint64_t& index) {
  const double u1 = std::max(rng.uniform(index++), 1e-300);
  const double u2 = rng.uniform(index++);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

struct StripResult {
  bool done = false;
  std::string note;
};

// Appendix B: remeshes region F into the flat parts outside the strip and a
// curved region of the strip's chords.
StripResult remeshStrip(GeometricMesh& g, int region, const Pencil& pencil,
                        const CrumpleParams& params, const BoundaryPosition& boundary) {
  const EdgeMap edges = edgeMap(g);
  const auto loopOpt = regionLoop(g, region, edges);
  if (!loopOpt) return {false, "region has holes or pinches"};
  const Loop& loop = *loopOpt;
  std::vector<int> interior;
  {
    std::vector<char> onLoop(g.vertices.size(), 0);
    for (int v : loop.v) onLoop[static_cast<std::size_t>(v)] = 1;
    for (const GeometricFace& f : g.faces) {
      if (f.region != region) continue;
      for (int k = 0; k < f.size(); ++k) {
        if (!onLoop[static_cast<std::size_t>(f.v[k])]) {
          interior.push_back(f.v[k]);
          onLoop[static_cast<std::size_t>(f.v[k])] = 1;
        }
      }
    }
  }
  const double scale = std::sqrt(outlineArea(g));
  const Context ctx{g, loop, interior, 1e-10 * scale};
  const char* noStrip = "";
  const std::vector<double> stripParams =
      stripParameters(ctx, pencil, 1.0 / params.rhoBound, &noStrip);
  if (stripParams.size() < 2)
    return {false, std::string("no strip of free rulings around the compressed triangle (") +
                       noStrip + ")"};
  std::vector<Chord> chords;
  for (double p : stripParams) {
    auto c = evaluateChord(ctx, pencil, p);
    if (!c) return {false, "a ruling of the strip met a constrained border"};
    chords.push_back(*c);
  }
  // Minimum strip width: a strip thinner than a tenth of the ruling spacing
  // would make slivers; let the simulation deform further first.
  const double width = std::max((chords.back().a.p - chords.front().a.p).norm(),
                                (chords.back().b.p - chords.front().b.p).norm());
  if (width < 0.1 / params.rhoBound) return {false, "strip too narrow"};
  // Ruling ends at least half the ruling spacing apart on both borders (or
  // one shared vertex, a fan's apex): a conical pencil spaced at 1/rho_bound
  // on its far border crowds its near border, and ends millimetres apart
  // make sliver cells that stall the elastic solve. The limit rulings stay.
  // Chord ends within a quarter of the ruling spacing of a loop vertex move
  // onto it (a new vertex beside an existing one would make slivers); a chord
  // that then runs along part of a loop edge is no ruling and is dropped.
  {
    const double snap = 0.25 / params.rhoBound;
    const int m = static_cast<int>(loop.size());
    const auto snapEnd = [&](ChordEnd& e) {
      if (e.vertex >= 0) return;
      const int a = e.loopEdge;
      const int b = (a + 1) % m;
      for (int k : {a, b}) {
        const Vec2& p =
            g.vertices[static_cast<std::size_t>(loop.v[static_cast<std::size_t>(k)])].pattern;
        if ((e.p - p).norm() < snap) {
          e.p = p;
          e.vertex = k;
          e.loopEdge = -1;
          return;
        }
      }
    };
    const auto alongLoop = [&](const ChordEnd& x, const ChordEnd& y) {
      if (x.loopEdge >= 0 && y.loopEdge >= 0) return x.loopEdge == y.loopEdge;
      const ChordEnd& onEdge = x.loopEdge >= 0 ? x : y;
      const ChordEnd& atVertex = x.loopEdge >= 0 ? y : x;
      if (onEdge.loopEdge < 0) return false;  // both at vertices: handled by evaluateChord
      return atVertex.vertex == onEdge.loopEdge || atVertex.vertex == (onEdge.loopEdge + 1) % m;
    };
    std::vector<Chord> kept;
    for (Chord c : chords) {
      snapEnd(c.a);
      snapEnd(c.b);
      if (c.a.vertex >= 0 && c.a.vertex == c.b.vertex) continue;
      if (alongLoop(c.a, c.b)) continue;
      kept.push_back(c);
    }
    chords = std::move(kept);
    if (chords.size() < 2) return {false, "strip has fewer than two distinct rulings"};
  }
  {
    const double minGap = 0.5 / params.rhoBound;
    const auto apart = [&](const ChordEnd& x, const ChordEnd& y) {
      const double d = (x.p - y.p).norm();
      return d < ctx.tol || d >= minGap;
    };
    const auto spaced = [&](const Chord& x, const Chord& y) {
      return apart(x.a, y.a) && apart(x.b, y.b);
    };
    std::vector<Chord> kept{chords.front()};
    for (std::size_t k = 1; k + 1 < chords.size(); ++k) {
      if (spaced(kept.back(), chords[k]) && spaced(chords[k], chords.back()))
        kept.push_back(chords[k]);
    }
    if (chords.size() > 1) kept.push_back(chords.back());
    chords = std::move(kept);
  }

  // Vertices for the chord ends: existing loop vertices, or new ones on dS
  // edges (several per edge are kept in order along it).
  std::map<int, std::vector<std::pair<double, int>>> onEdge;  // loop edge -> (u, new vertex)
  const auto endVertex = [&](const ChordEnd& e) {
    if (e.vertex >= 0) return loop.v[static_cast<std::size_t>(e.vertex)];
    const int a = loop.v[static_cast<std::size_t>(e.loopEdge)];
    const int b = loop.next(static_cast<std::size_t>(e.loopEdge));
    const Vec2& pa = g.vertices[static_cast<std::size_t>(a)].pattern;
    const Vec2& pb = g.vertices[static_cast<std::size_t>(b)].pattern;
    const double u = (e.p - pa).norm() / (pb - pa).norm();
    // Snap onto an endpoint closer than a quarter of the ruling spacing (a
    // new vertex beside an existing one would make sliver triangles).
    const double snap = 0.25 / params.rhoBound;
    if ((e.p - pa).norm() < snap) return a;
    if ((e.p - pb).norm() < snap) return b;
    const int v = addBoundaryVertex(g, a, b, e.p, boundary);
    onEdge[e.loopEdge].emplace_back(u, v);
    return v;
  };
  std::vector<Ruling> rulings;
  for (const Chord& c : chords) {
    Ruling r;
    r.a = endVertex(c.a);
    r.b = endVertex(c.b);
    if (r.a == r.b) return {false, "degenerate ruling"};
    if (!rulings.empty() && rulings.back().a == r.a && rulings.back().b == r.b) continue;
    rulings.push_back(r);
  }
  // Drop rulings that would make a cell of (near) zero area, e.g. two chord
  // ends snapped onto one vertex next to a cone apex.
  {
    const auto P = [&](int v) -> const Vec2& {
      return g.vertices[static_cast<std::size_t>(v)].pattern;
    };
    const auto cellArea = [&](const Ruling& r0, const Ruling& r1) {
      std::vector<int> poly{r0.a, r1.a, r1.b, r0.b};
      poly.erase(std::unique(poly.begin(), poly.end()), poly.end());
      if (poly.size() > 1 && poly.front() == poly.back()) poly.pop_back();
      double area = 0.0;
      for (std::size_t k = 0; k < poly.size(); ++k)
        area += cross2(P(poly[k]), P(poly[(k + 1) % poly.size()]));
      return std::abs(0.5 * area);
    };
    const double minArea = 1e-4 / (params.rhoBound * params.rhoBound);
    std::vector<Ruling> kept;
    for (std::size_t k = 0; k < rulings.size(); ++k) {
      if (!kept.empty() && cellArea(kept.back(), rulings[k]) < minArea) {
        if (k + 1 == rulings.size() && kept.size() > 1)
          kept.back() = rulings[k];  // keep the limit ruling
        continue;
      }
      kept.push_back(rulings[k]);
    }
    rulings = std::move(kept);
  }
  if (rulings.size() < 2) return {false, "strip has fewer than two distinct rulings"};
  // The loop with the new vertices.
  std::vector<int> newLoop;
  for (std::size_t k = 0; k < loop.size(); ++k) {
    newLoop.push_back(loop.v[k]);
    auto it = onEdge.find(static_cast<int>(k));
    if (it == onEdge.end()) continue;
    auto list = it->second;
    std::sort(list.begin(), list.end());
    for (const auto& [u, v] : list) newLoop.push_back(v);
  }
  const auto position = [&](int v) {
    return static_cast<std::size_t>(std::find(newLoop.begin(), newLoop.end(), v) - newLoop.begin());
  };
  // The loop path from x forwards to y (inclusive).
  const auto path = [&](int x, int y) {
    std::vector<int> out;
    std::size_t k = position(x);
    for (std::size_t n = 0; n <= newLoop.size(); ++n) {
      out.push_back(newLoop[k]);
      if (newLoop[k] == y) break;
      k = (k + 1) % newLoop.size();
    }
    return out;
  };
  const auto contains = [](const std::vector<int>& list, int v) {
    return std::find(list.begin(), list.end(), v) != list.end();
  };
  // Every loop vertex strictly between consecutive rulings must be absent,
  // or the strip cells would not be quads/triangles.
  std::vector<std::vector<int>> sides;
  for (int end = 0; end < 2; ++end) {
    const Ruling& r = end == 0 ? rulings.front() : rulings[rulings.size() - 1];
    const Ruling& inner = end == 0 ? rulings[1] : rulings[rulings.size() - 2];
    const int innerProbe = inner.b != r.b ? inner.b : inner.a;
    std::vector<int> p1 = path(r.a, r.b);
    std::vector<int> p2 = path(r.b, r.a);
    std::vector<int>& side = contains(p1, innerProbe) ? p2 : p1;
    if (side.size() >= 3) sides.push_back(side);
  }
  // Check the strip cells: loop path between consecutive ruling ends must be
  // a single edge (or the apex).
  for (std::size_t k = 0; k + 1 < rulings.size(); ++k) {
    for (const auto& [x, y] :
         {std::pair{rulings[k].a, rulings[k + 1].a}, std::pair{rulings[k].b, rulings[k + 1].b}}) {
      if (x == y) continue;
      const std::vector<int> p1 = path(x, y);
      const std::vector<int> p2 = path(y, x);
      if (std::min(p1.size(), p2.size()) != 2) {
        return {false, "a strip cell would hold an extra boundary vertex"};
      }
    }
  }
  // Commit: drop F's faces, add the flat sides and the curved strip.
  removeRegionFaces(g, region);
  for (const std::vector<int>& side : sides) {
    triangulatePolygon(g, side, addRegion(g, mesh::RegionType::Flat), interior);
  }
  const int curved = addRegion(g, mesh::RegionType::Curved);
  g.regions[static_cast<std::size_t>(curved)].rulings = rulings;
  g.regions[static_cast<std::size_t>(curved)].apex = pencil.apex;
  rebuildCurvedFaces(g, curved);
  return {true, {}};
}

// Splits F along the crease (s1, s2) between two singular vertices (Appendix
// B, Fig. 24 (c)): the degenerate curved region of one ruling.
bool splitAlongCrease(GeometricMesh& g, int region, int s1, int s2) {
  const EdgeMap edges = edgeMap(g);
  const auto loop = regionLoop(g, region, edges);
  if (!loop) return false;
  const auto& lv = loop->v;
  const auto i1 = std::find(lv.begin(), lv.end(), s1);
  const auto i2 = std::find(lv.begin(), lv.end(), s2);
  if (i1 == lv.end() || i2 == lv.end()) return false;
  std::vector<int> a;
  std::vector<int> b;
  for (auto it = i1;; ++it) {
    if (it == lv.end()) it = lv.begin();
    a.push_back(*it);
    if (*it == s2) break;
  }
  for (auto it = i2;; ++it) {
    if (it == lv.end()) it = lv.begin();
    b.push_back(*it);
    if (*it == s1) break;
  }
  if (a.size() < 3 || b.size() < 3) return false;
  const std::vector<int> inner = detail::innerVertices(g, region, *loop);
  removeRegionFaces(g, region);
  triangulatePolygon(g, a, addRegion(g, mesh::RegionType::Flat), inner);
  triangulatePolygon(g, b, addRegion(g, mesh::RegionType::Flat), inner);
  return true;
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
  const int a = loop.v[static_cast<std::size_t>(border.loopEdge)];
  const int b = loop.next(static_cast<std::size_t>(border.loopEdge));
  const Vec2& pa = g.vertices[static_cast<std::size_t>(a)].pattern;
  const Vec2& pb = g.vertices[static_cast<std::size_t>(b)].pattern;
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
  const int ea = loop.v[static_cast<std::size_t>(border.loopEdge)];
  const int eb = loop.next(static_cast<std::size_t>(border.loopEdge));
  const int across = loop.across[static_cast<std::size_t>(border.loopEdge)];
  const int cr = g.faces[static_cast<std::size_t>(across)].region;
  Region& curved = g.regions[static_cast<std::size_t>(cr)];
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
    const Vec2 a0 = g.vertices[static_cast<std::size_t>(rulings[k - 1].a)].pattern;
    const Vec2 pa = g.vertices[static_cast<std::size_t>(rulings[k].a)].pattern;
    const Vec2 pb = g.vertices[static_cast<std::size_t>(rulings[k].b)].pattern;
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
  const auto P = [&](int v) -> const Vec2& {
    return g.vertices[static_cast<std::size_t>(v)].pattern;
  };
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
  Region& c2 = g.regions[static_cast<std::size_t>(cr)];
  c2.rulings.assign(rulings.begin() + static_cast<std::ptrdiff_t>(sup), rulings.end());
  if (c2.rulings.size() >= 2) rebuildCurvedFaces(g, cr);
  addConeFans(g, sIndex, rulings, 0, sup);
  addTriangleCCW(g, sIndex, rulings[sup].a, rulings[sup].b, addRegion(g, mesh::RegionType::Flat));
  addTriangleCCW(g, sIndex, rulings[0].a, rulings[0].b, flat);
  return sIndex;
}

// Orients the rulings of a curved region so that every .a lies on the same
// boundary chain as rulings[0].a.
std::vector<Ruling> orientedRulings(const GeometricMesh& g, std::vector<Ruling> rulings) {
  const auto P = [&](int v) -> const Vec2& {
    return g.vertices[static_cast<std::size_t>(v)].pattern;
  };
  for (std::size_t k = 1; k < rulings.size(); ++k) {
    const Vec2 a0 = P(rulings[k - 1].a);
    if (rulings[k].a != rulings[k - 1].a && rulings[k].b != rulings[k - 1].b &&
        (P(rulings[k].b) - a0).norm() < (P(rulings[k].a) - a0).norm()) {
      std::swap(rulings[k].a, rulings[k].b);
    }
  }
  return rulings;
}

}  // namespace

// Extension of paper Sec. 5.2 to the case its Sec. 7.4 lists as a limitation
// ("we do not handle the case when a pressure is applied inside a curved
// area"): a ruling of a curved region compressed by more than eps_c cannot
// stay straight, so the sheet forms a d-cone on it. The singular vertex is
// drawn with the paper's law around the most compressed ruling (uniform
// along it, exp(-d^2/sigma^2) across), and the region is remeshed around it
// as in Fig. 11 on both sides: rulings are replaced by fans from s out to the
// first ruling above theta_0 on each side, with a flat transition triangle
// at each end.
void treatCurvedCompression(GeometricMesh& g, const CrumpleParams& params, const CounterRng& rng,
                            std::uint64_t& drawIndex, GeometricStepStats& stats,
                            const FaceFilter& mayRemesh) {
  const std::size_t regionCount = g.regions.size();
  const std::size_t faceCount = g.faces.size();
  std::vector<char> settled(regionCount, 1);
  for (std::size_t f = 0; f < faceCount && mayRemesh; ++f) {
    if (!mayRemesh(static_cast<int>(f))) settled[static_cast<std::size_t>(g.faces[f].region)] = 0;
  }
  for (std::size_t r = 0; r < regionCount; ++r) {
    if (g.regions[r].type != mesh::RegionType::Curved || g.regions[r].apex >= 0) continue;
    if (!settled[r]) continue;
    if (stats.singularInserted >= params.maxSingularPerFrame) break;
    if (g.regions[r].rulings.size() < 2) continue;
    const std::vector<Ruling> rulings = orientedRulings(g, g.regions[r].rulings);
    const auto P = [&](int v) -> const Vec2& {
      return g.vertices[static_cast<std::size_t>(v)].pattern;
    };
    const auto X = [&](int v) -> const Vec3& {
      return g.vertices[static_cast<std::size_t>(v)].position;
    };
    // The most compressed ruling with both ends on dS (interior rulings only:
    // the end rulings are borders with other regions).
    std::size_t kmax = 0;
    double cmax = 0.0;
    for (std::size_t k = 1; k + 1 < rulings.size(); ++k) {
      const double c =
          edgeCompression(P(rulings[k].a), P(rulings[k].b), X(rulings[k].a), X(rulings[k].b));
      if (c > cmax) {
        cmax = c;
        kmax = k;
      }
    }
    stats.maxCompression = std::max(stats.maxCompression, cmax);
    if (kmax == 0 || !(cmax > params.curvedCompressionFactor * params.epsC)) continue;
    const std::size_t n = rulings.size() - 1;
    const Vec2 sa = P(rulings[kmax].a);
    const Vec2 sb = P(rulings[kmax].b);
    const double along = 0.15 + 0.7 * rng.uniform(drawIndex++);
    const double across = normalDeviate(rng, drawIndex) * params.sigma / std::sqrt(2.0);
    Vec2 normal(-(sb - sa).y(), (sb - sa).x());
    normal.normalize();
    if (normal.dot(P(rulings[kmax + 1].a) - sa) < 0.0) normal = -normal;
    // Keep s strictly inside the two cells next to the ruling (a tenth of
    // their width from their far rulings).
    const double wFwd = std::abs(normal.dot(P(rulings[kmax + 1].a) - sa));
    const double wBwd = std::abs(normal.dot(P(rulings[kmax - 1].a) - sa));
    const double d = std::clamp(across, -0.5 * wBwd, 0.5 * wFwd);
    const Vec2 s = sa + along * (sb - sa) + d * normal;
    std::size_t cell = d >= 0.0 ? kmax : kmax - 1;
    if (crowded(g, s, params)) continue;
    // 3D position: barycentric in the cell's triangle holding s.
    std::optional<GeometricVertex> placed = vertexInCell(g, rulings[cell], rulings[cell + 1], s);
    if (!placed) continue;
    GeometricVertex sv = *placed;
    sv.singular = true;
    const EdgeMap edges = edgeMap(g);
    const auto dihedralAt = [&](const Ruling& ruling) {
      const auto it = edges.find({std::min(ruling.a, ruling.b), std::max(ruling.a, ruling.b)});
      if (it == edges.end() || it->second[1] < 0) return 0.0;
      return dihedralAngle(g, it->second[0], it->second[1]);
    };
    // e_sup on both sides of the cell: the nearest ruling above theta_0, or
    // the region's end.
    // s lies strictly between r_{kmax-1} and r_{kmax+1}, so both transition
    // triangles have a positive area.
    (void)cell;
    std::size_t hi = n;
    for (std::size_t k = kmax + 1; k < n; ++k) {
      if (dihedralAt(rulings[k]) > params.theta0) {
        hi = k;
        break;
      }
    }
    std::size_t lo = 0;
    for (std::size_t k = kmax - 1; k > 0; --k) {
      if (dihedralAt(rulings[k]) > params.theta0) {
        lo = k;
        break;
      }
    }
    const GeometricMesh before = g;
    try {
      const int sIndex = addVertex(g, sv);
      const int cr = static_cast<int>(r);
      removeRegionFaces(g, cr);
      // What stays of C: the rulings before lo and after hi (two curved regions).
      g.regions[r].rulings.assign(rulings.begin() + static_cast<std::ptrdiff_t>(hi), rulings.end());
      if (g.regions[r].rulings.size() >= 2) rebuildCurvedFaces(g, cr);
      if (lo >= 1) {
        const int back = addRegion(g, mesh::RegionType::Curved);
        g.regions[static_cast<std::size_t>(back)].rulings.assign(
            rulings.begin(), rulings.begin() + static_cast<std::ptrdiff_t>(lo) + 1);
        rebuildCurvedFaces(g, back);
      }
      // Fans from s to both chains between r_lo and r_hi.
      addConeFans(g, sIndex, rulings, lo, hi);
      addTriangleCCW(g, sIndex, rulings[lo].a, rulings[lo].b, addRegion(g, mesh::RegionType::Flat));
      addTriangleCCW(g, sIndex, rulings[hi].a, rulings[hi].b, addRegion(g, mesh::RegionType::Flat));
      if (const std::string problem = validate(g); !problem.empty()) {
        g = before;
        stats.notes.push_back("curved region " + std::to_string(r) + ": d-cone undone (" + problem +
                              ")");
        continue;
      }
    } catch (const std::exception& e) {
      g = before;
      stats.notes.push_back("curved region " + std::to_string(r) + ": d-cone undone (" + e.what() +
                            ")");
      continue;
    }
    ++stats.singularInserted;
    ++stats.singularInCurved;
    stats.cuts.push_back(s);
    stats.notes.push_back("curved region " + std::to_string(r) +
                          ": d-cone on a ruling compressed " + std::to_string(cmax));
  }
  compact(g);
}

namespace {}  // namespace

// A flat region of S_G whose triangles stopped being coplanar (an interior
// edge above theta_0) is bent, not creased: S_P samples flat regions as a
// whole, so it bends smoothly across S_G's internal edges. Before the region
// is split (paper Sec. 5.1), the fold is offered to the ruling machinery as a
// strip of rulings parallel to the folded edge (its direction is the
// direction of zero curvature); only when that strip meets a constrained
// border is the region split along the edge as in thesis Fig. 2.5.
namespace {

// How S_P bends inside flat region r of S_G: the principal direction of
// sum theta^2 e e^T over S_P hinges whose pattern midpoint lies in r (e the
// hinge's unit pattern direction), and the midpoint of the most bent hinge.
// nullopt when no hinge there bends by more than theta_0 / 2.
std::optional<std::pair<Vec2, Vec2>> bendingDirection(const GeometricMesh& g, int r,
                                                      const mesh::SheetMesh& sp,
                                                      const std::vector<mesh::MeshEdge>& edges,
                                                      double theta0) {
  Eigen::Matrix2d tensor = Eigen::Matrix2d::Zero();
  double most = 0.5 * theta0;
  Vec2 origin = Vec2::Zero();
  const auto normal = [&](int t) {
    const auto& tri = sp.triangles[static_cast<std::size_t>(t)];
    const Vec3& a = sp.positions[static_cast<std::size_t>(tri[0])];
    return Vec3((sp.positions[static_cast<std::size_t>(tri[1])] - a)
                    .cross(sp.positions[static_cast<std::size_t>(tri[2])] - a)
                    .normalized());
  };
  for (const mesh::MeshEdge& e : edges) {
    if (!e.interior()) continue;
    const Vec2& pa = sp.pattern[static_cast<std::size_t>(e.v[0])];
    const Vec2& pb = sp.pattern[static_cast<std::size_t>(e.v[1])];
    const Vec2 mid = 0.5 * (pa + pb);
    bool inside = false;
    for (const GeometricFace& f : g.faces) {
      if (f.region != r) continue;
      if (detail::pointInPolygon(g, std::span<const int>(f.v.data(), f.size()), mid)) {
        inside = true;
        break;
      }
    }
    if (!inside) continue;
    const double theta =
        std::acos(std::clamp(normal(e.triangles[0]).dot(normal(e.triangles[1])), -1.0, 1.0));
    if (!std::isfinite(theta)) continue;
    const Vec2 dir = (pb - pa).normalized();
    tensor += theta * theta * dir * dir.transpose();
    if (theta > most) {
      most = theta;
      origin = mid;
    }
  }
  if (!(most > 0.5 * theta0)) return std::nullopt;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(tensor);
  const Vec2 dir = eig.eigenvectors().col(1);  // largest eigenvalue last
  if (!dir.allFinite()) return std::nullopt;
  return std::pair{origin, dir};
}

}  // namespace

int bendFoldedFlatRegions(GeometricMesh& g, const CrumpleParams& params,
                          const BoundaryPosition& boundary, GeometricStepStats& stats,
                          const mesh::SheetMesh* sp) {
  int bent = 0;
  std::optional<std::vector<mesh::MeshEdge>> spEdges;  // S_P's edges, once a region folds
  detail::EdgeMapCache edgeCache;
  const std::size_t regionCount = g.regions.size();
  for (std::size_t r = 0; r < regionCount; ++r) {
    if (g.regions[r].type != mesh::RegionType::Flat) continue;
    const EdgeMap& edges = edgeCache.of(g);
    double best = params.theta0;
    std::pair<int, int> fold{-1, -1};
    for (const auto& [key, faces] : edges) {
      if (faces[0] < 0 || faces[1] < 0) continue;
      if (g.faces[static_cast<std::size_t>(faces[0])].region != static_cast<int>(r) ||
          g.faces[static_cast<std::size_t>(faces[1])].region != static_cast<int>(r)) {
        continue;
      }
      const double angle = dihedralAngle(g, faces[0], faces[1]);
      if (angle > best) {
        best = angle;
        fold = key;
      }
    }
    if (fold.first < 0) continue;
    const Vec2 a = g.vertices[static_cast<std::size_t>(fold.first)].pattern;
    const Vec2 b = g.vertices[static_cast<std::size_t>(fold.second)].pattern;
    // Candidate pencils, most faithful first: how S_P bends (through its
    // most bent hinge, then through the fold), the folded S_G edge, and the
    // directions of the rulings bounding the region (a flat gap between two
    // curved strips bends like them).
    std::vector<Pencil> candidates;
    const Vec2 foldMid = 0.5 * (a + b);
    if (sp != nullptr) {
      if (!spEdges) spEdges = mesh::buildEdges(*sp);
      if (const auto bend =
              bendingDirection(g, static_cast<int>(r), *sp, *spEdges, params.theta0)) {
        candidates.push_back({-1, bend->first, bend->second});
        candidates.push_back({-1, foldMid, bend->second});
      }
    }
    candidates.push_back({-1, foldMid, (b - a).normalized()});
    if (const auto loop = regionLoop(g, static_cast<int>(r), edges)) {
      for (std::size_t k = 0; k < loop->size(); ++k) {
        const int across = loop->across[k];
        if (across < 0 ||
            g.regions[static_cast<std::size_t>(g.faces[static_cast<std::size_t>(across)].region)]
                    .type != mesh::RegionType::Curved)
          continue;
        const Vec2 d = g.vertices[static_cast<std::size_t>(loop->next(k))].pattern -
                       g.vertices[static_cast<std::size_t>(loop->v[k])].pattern;
        if (d.norm() > 0.0) candidates.push_back({-1, foldMid, d.normalized()});
      }
    }
    const GeometricMesh before = g;
    StripResult result;
    for (const Pencil& pencil : candidates) {
      try {
        result = remeshStrip(g, static_cast<int>(r), pencil, params, boundary);
      } catch (const std::exception& e) {
        g = before;
        result = {false, e.what()};
      }
      if (result.done) {
        if (const std::string problem = validate(g); !problem.empty()) {
          g = before;
          result = {false, "remeshing undone (" + problem + ")"};
        }
      }
      if (result.done) break;
    }
    if (result.done) {
      ++bent;
      ++stats.curvedCreated;
      ++stats.curvedBent;
    } else {
      stats.notes.push_back("folded flat region " + std::to_string(r) +
                            " kept its crease: " + result.note);
    }
  }
  compact(g);
  return bent;
}

void treatCompression(GeometricMesh& g, const CrumpleParams& params,
                      const BoundaryPosition& boundary, const CounterRng& rng,
                      std::uint64_t& drawIndex, GeometricStepStats& stats,
                      const FaceFilter& mayRemesh) {
  detail::EdgeMapCache edgeCache;
  // Regions holding a face that may not be remeshed yet wait (cooldown).
  std::vector<char> declined(g.regions.size(), 0);
  for (std::size_t f = 0; f < g.faces.size() && mayRemesh; ++f) {
    if (!mayRemesh(static_cast<int>(f))) declined[static_cast<std::size_t>(g.faces[f].region)] = 1;
  }
  // Regions are processed in id order, once per step: regions created here
  // keep the compressed vertices they were cut from and are looked at again
  // after the next elastic step has relaxed them (thesis 2.4.2 repeats the
  // remeshing "until there is no flat region with a highly compressed
  // triangle anymore"; across steps here, which keeps one step from
  // cascading into creases of creases).
  constexpr int kPasses = 1;
  for (int pass = 0; pass < kPasses; ++pass) {
    bool changed = false;
    const std::size_t regionCount = g.regions.size();
    declined.resize(regionCount, 0);
    // Most compressed regions first, so the per-step budget of singular
    // vertices goes where the conflict is strongest.
    std::vector<std::pair<double, std::size_t>> order;
    {
      std::vector<double> worst(regionCount, 0.0);
      for (const GeometricFace& face : g.faces) {
        if (face.size() != 3 ||
            g.regions[static_cast<std::size_t>(face.region)].type != mesh::RegionType::Flat) {
          continue;
        }
        double& w = worst[static_cast<std::size_t>(face.region)];
        w = std::max(w, faceCompression(g, face).ratio());
      }
      for (std::size_t r = 0; r < regionCount; ++r) order.emplace_back(-worst[r], r);
      std::sort(order.begin(), order.end());
    }
    for (const auto& [negWorst, r] : order) {
      if (declined[r] || g.regions[r].type != mesh::RegionType::Flat) continue;
      // (a) the most compressed triangle and its direction of minimal compression.
      int tcomp = -1;
      TriangleCompression best;
      best.lambdaMin = 2.0;
      for (std::size_t f = 0; f < g.faces.size(); ++f) {
        const GeometricFace& face = g.faces[f];
        if (face.region != static_cast<int>(r) || face.size() != 3) continue;
        const TriangleCompression c = faceCompression(g, face);
        if (c.lambdaMin < best.lambdaMin) {
          best = c;
          tcomp = static_cast<int>(f);
        }
      }
      if (tcomp < 0) continue;
      stats.maxCompression = std::max(stats.maxCompression, best.ratio());
      if (!(best.ratio() > params.epsC)) continue;
      const GeometricFace tri = g.faces[static_cast<std::size_t>(tcomp)];
      Vec2 centroid = Vec2::Zero();
      for (int k = 0; k < 3; ++k)
        centroid += g.vertices[static_cast<std::size_t>(tri.v[k])].pattern / 3.0;
      // Each remeshing is a transaction: S_G is checked afterwards and
      // restored (the region declined for this step) when it would break an
      // invariant, so one bad case cannot corrupt the sheet.
      const GeometricMesh before = g;
      const std::size_t singularBefore = static_cast<std::size_t>(stats.singularInserted);
      const auto rollback = [&](const std::string& why) {
        g = before;
        stats.singularInserted = static_cast<int>(singularBefore);
        stats.notes.push_back("flat region " + std::to_string(r) + ": remeshing undone (" + why +
                              ")");
        declined.resize(g.regions.size(), 0);
        declined[r] = 1;
      };
      try {
        // (b) the borders of the strip along +-v_perp (Appendix A, Fig. 6).
        const EdgeMap& edges = edgeCache.of(g);
        const auto loop = regionLoop(g, static_cast<int>(r), edges);
        if (!loop) {
          declined[r] = 1;
          continue;
        }
        const double tol = 1e-10 * std::sqrt(outlineArea(g));
        const Border fwd = findBorder(g, *loop, centroid, best.vPerp, tol);
        const Border bwd = findBorder(g, *loop, centroid, -best.vPerp, tol);
        std::ostringstream why;
        why << "flat region " << r << " compressed " << best.ratio() << ": ";
        if (fwd.kind == Border::Kind::None || bwd.kind == Border::Kind::None) {
          why << "strip ends on a vertex that is not on the sheet boundary";
          stats.notes.push_back(why.str());
          declined[r] = 1;
          continue;
        }
        // (c) remesh: c1 with both borders free, c2 with singular vertices.
        const auto constrained = [](const Border& b) { return b.kind != Border::Kind::Free; };
        const Border* borders[2] = {&bwd, &fwd};
        // Singular vertices on constrained borders (paper Sec. 5.2). A border
        // ruling of a curved region gets its singular vertex on the ruling
        // itself (we do not yet continue into the curved region to e_sing).
        // A border ruling of a cone from a singular vertex s: the strip's
        // rulings are attracted by s itself (Appendix B, Fig. 24 b), no new
        // singular vertex is needed.
        StripResult result;
        int singular[2] = {-1, -1};
        bool feasible = true;
        int existingApex[2] = {-1, -1};
        for (int side = 0; side < 2; ++side) {
          const Border& b = *borders[side];
          if (b.kind == Border::Kind::FlatFlat) {
            // A border edge ending at a singular vertex (e.g. a crease between
            // two): the rulings are attracted by that existing d-cone apex
            // (Appendix B, Fig. 24 b) instead of a new one beside it.
            const int ea = loop->v[static_cast<std::size_t>(b.loopEdge)];
            const int eb = loop->next(static_cast<std::size_t>(b.loopEdge));
            const bool sa = g.vertices[static_cast<std::size_t>(ea)].singular;
            const bool sb = g.vertices[static_cast<std::size_t>(eb)].singular;
            if (sa || sb) {
              const double da = (g.vertices[static_cast<std::size_t>(ea)].pattern - b.hit).norm();
              const double db = (g.vertices[static_cast<std::size_t>(eb)].pattern - b.hit).norm();
              existingApex[side] = sa && (!sb || da <= db) ? ea : eb;
            }
            continue;
          }
          if (b.kind != Border::Kind::Curved) continue;
          const int across = loop->across[static_cast<std::size_t>(b.loopEdge)];
          const int apex =
              g.regions[static_cast<std::size_t>(g.faces[static_cast<std::size_t>(across)].region)]
                  .apex;
          if (apex < 0) continue;
          const int ea = loop->v[static_cast<std::size_t>(b.loopEdge)];
          const int eb = loop->next(static_cast<std::size_t>(b.loopEdge));
          if (apex == ea || apex == eb) {
            existingApex[side] = apex;
          } else {
            feasible = false;
          }
        }
        if (!feasible) {
          why << "the strip meets a conical curved region";
          stats.notes.push_back(why.str());
          declined[r] = 1;
          continue;
        }
        const int needed = (constrained(bwd) && existingApex[0] < 0 ? 1 : 0) +
                           (constrained(fwd) && existingApex[1] < 0 ? 1 : 0);
        if (needed > 0 && stats.singularInserted + needed > params.maxSingularPerFrame) {
          why << "singular-vertex budget of this step used up";
          stats.notes.push_back(why.str());
          declined[r] = 1;
          continue;
        }
        for (int side = 0; side < 2; ++side) {
          if (existingApex[side] >= 0) {
            singular[side] = existingApex[side];
            continue;
          }
          if (!constrained(*borders[side])) continue;
          const EdgeMap e2 = edgeMap(g);
          const auto l2 = regionLoop(g, static_cast<int>(r), e2);
          if (!l2) break;
          // Re-locate the border edge in the current loop (the other side's
          // insertion may have renumbered it).
          const Border b =
              findBorder(g, *l2, centroid, side == 0 ? Vec2(-best.vPerp) : best.vPerp, tol);
          if (b.kind == Border::Kind::Curved) {
            singular[side] =
                insertSingularInCurved(g, static_cast<int>(r), *l2, b, params, rng, drawIndex);
            if (singular[side] < 0) break;
          } else {
            singular[side] = placeSingularOnBorder(g, *l2, b, params, rng, drawIndex);
            if (singular[side] < 0) break;
          }
          ++stats.singularInserted;
        }
        if ((constrained(bwd) && singular[0] < 0) || (constrained(fwd) && singular[1] < 0)) {
          why << "the strip meets a conical curved region";
          stats.notes.push_back(why.str());
          declined[r] = 1;
          continue;
        }
        // Rulings fanning from the apex on `side`: aimed where the strip
        // meets the other border (free there by construction), else through
        // the compressed triangle.
        const auto coneFrom = [&](int apex, int side) {
          Pencil pencil;
          pencil.apex = apex;
          const Vec2 s = g.vertices[static_cast<std::size_t>(apex)].pattern;
          pencil.origin = s;
          StripResult out{false, "no pencil"};
          for (const Vec2& target : {borders[1 - side]->hit, centroid}) {
            if (!((target - s).norm() > tol)) continue;
            pencil.dir = (target - s).normalized();
            out = remeshStrip(g, static_cast<int>(r), pencil, params, boundary);
            if (out.done) break;
          }
          return out;
        };
        if (singular[0] >= 0 && singular[1] >= 0) {
          result.done = splitAlongCrease(g, static_cast<int>(r), singular[0], singular[1]);
          if (result.done) ++stats.creases;
          // Two existing apices that are one vertex, or already joined by a
          // border edge, leave no crease to cut: the strip's rulings fan
          // from one of them instead (Appendix B, Fig. 24 b).
          for (int side = 0; side < 2 && !result.done; ++side) {
            if (existingApex[side] < 0) continue;
            result = coneFrom(existingApex[side], side);
            if (result.done) ++stats.curvedCreated;
          }
        } else {
          if (singular[0] >= 0 || singular[1] >= 0) {
            result = singular[0] >= 0 ? coneFrom(singular[0], 0) : coneFrom(singular[1], 1);
          } else {
            Pencil pencil;
            pencil.origin = centroid;
            pencil.dir = best.vPerp;
            result = remeshStrip(g, static_cast<int>(r), pencil, params, boundary);
          }
          if (result.done) ++stats.curvedCreated;
        }
        if (!result.done) {
          // Undo the singular vertices placed for it too: a singular vertex
          // without its cone would be damage without a cause.
          why << (result.note.empty() ? std::string("the crease could not split the region")
                                      : result.note);
          rollback(why.str());
          continue;
        }
        if (const std::string problem = validate(g); !problem.empty()) {
          rollback(problem);
          continue;
        }
        stats.cuts.push_back(centroid);
        if (stats.singularInserted > static_cast<int>(singularBefore)) {
          why << "strip with " << (stats.singularInserted - static_cast<int>(singularBefore))
              << " new singular vertices";
          stats.notes.push_back(why.str());
        }
        for (int sv : singular) {
          if (sv >= 0 && static_cast<std::size_t>(sv) < g.vertices.size()) {
            stats.cuts.push_back(g.vertices[static_cast<std::size_t>(sv)].pattern);
          }
        }
        changed = true;
      } catch (const std::exception& e) {
        // CDT refusing a polygon, a degenerate placement...: undo, go on.
        rollback(e.what());
        continue;
      }
    }
    if (!changed) break;
  }
  compact(g);
}

}  // namespace crumple::paper
