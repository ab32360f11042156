// The strip of imaginary rulings (paper Appendices A-B; thesis 2.4.3).
//
// The imaginary rulings of the paper are handled as a pencil of chords of
// the flat region F in the pattern: parallel chords along v-perp (case c1,
// both borders on dS) or chords through a singular vertex s (case c2). The
// strip of Appendix A is the run of chords around the compressed triangle
// that go from dS to dS without meeting a constrained border or a vertex
// that is not on dS; its extreme chords are r_lim1 and r_lim2 (Appendix B).
#include "strip.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <optional>
#include <span>

#include "crumple/core/geometry2d.hpp"
#include "crumple/core/index.hpp"

namespace crumple::paper::detail {

namespace {

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
  return {g.vertices[idx(pencil.apex)].pattern, d};
}

double paramOf(const GeometricMesh& g, const Pencil& pencil, const Vec2& p) {
  if (pencil.apex < 0) {
    const Vec2 n(-pencil.dir.y(), pencil.dir.x());
    return n.dot(p - pencil.origin);
  }
  const Vec2 d = p - g.vertices[idx(pencil.apex)].pattern;
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
    side[k] = n.dot(g.vertices[idx(loop.v[k])].pattern - line.point);
    if (std::abs(side[k]) <= tol) side[k] = 0.0;
  }
  for (std::size_t k = 0; k < m; ++k) {
    const Vec2& pa = g.vertices[idx(loop.v[k])].pattern;
    if (side[k] == 0.0) {
      ChordEnd e;
      e.p = pa;
      e.vertex = static_cast<int>(k);
      out.emplace_back(line.dir.dot(pa - line.point), e);
      continue;
    }
    const double s1 = side[(k + 1) % m];
    if (s1 != 0.0 && (side[k] > 0.0) != (s1 > 0.0)) {
      const Vec2& pb = g.vertices[idx(loop.next(k))].pattern;
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

bool loopEdgeOnBoundary(const Loop& loop, int k) { return loop.across[idx(k)] < 0; }

bool vertexEndFree(const GeometricMesh& g, const Loop& loop, int k) {
  return g.vertices[idx(loop.v[idx(k)])].onBoundary;
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
    const Vec2& p = c.g.vertices[idx(v)].pattern;
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
    events.push_back(paramOf(c.g, pencil, c.g.vertices[idx(v)].pattern));
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

// The pattern cell between rulings r0 and r1 (a quad, or a triangle where
// they share an end): its area and its longest side.
struct CellShape {
  double area = 0.0;
  double longest = 0.0;
};

CellShape cellShape(const GeometricMesh& g, const Ruling& r0, const Ruling& r1) {
  std::vector<int> poly{r0.a, r1.a, r1.b, r0.b};
  poly.erase(std::unique(poly.begin(), poly.end()), poly.end());
  if (poly.size() > 1 && poly.front() == poly.back()) poly.pop_back();
  double twiceArea = 0.0, longest = 0.0;
  for (std::size_t k = 0; k < poly.size(); ++k) {
    const Vec2& u = g.vertices[idx(poly[k])].pattern;
    const Vec2& w = g.vertices[idx(poly[(k + 1) % poly.size()])].pattern;
    twiceArea += cross2(u, w);
    longest = std::max(longest, (w - u).norm());
  }
  return {std::abs(0.5 * twiceArea), longest};
}

// Ruling ends at least half the ruling spacing apart on both borders (or
// one shared vertex, a fan's apex): a conical pencil spaced at 1/rho_bound
// on its far border crowds its near border, and ends millimetres apart
// make sliver cells that stall the elastic solve. The limit rulings stay.
// Chord ends within a quarter of the ruling spacing of a loop vertex move
// onto it (a new vertex beside an existing one would make slivers); a chord
// that then runs along part of a loop edge is no ruling and is dropped.
// Returns false when fewer than two chords are left.
bool spaceChords(const GeometricMesh& g, const Loop& loop, double tol, const CrumpleParams& params,
                 std::vector<Chord>& chords) {
  {
    const double snap = 0.25 / params.rhoBound;
    const int m = static_cast<int>(loop.size());
    const auto snapEnd = [&](ChordEnd& e) {
      if (e.vertex >= 0) return;
      const int a = e.loopEdge;
      const int b = (a + 1) % m;
      for (int k : {a, b}) {
        const Vec2& p = g.vertices[idx(loop.v[idx(k)])].pattern;
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
    if (chords.size() < 2) return false;
  }
  {
    const double minGap = 0.5 / params.rhoBound;
    const auto apart = [&](const ChordEnd& x, const ChordEnd& y) {
      const double d = (x.p - y.p).norm();
      return d < tol || d >= minGap;
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
  return true;
}

// The loop path from x forwards to y (inclusive) along `loop`.
std::vector<int> loopPath(const std::vector<int>& loop, int x, int y) {
  std::vector<int> out;
  auto k = idx(std::find(loop.begin(), loop.end(), x) - loop.begin());
  for (std::size_t n = 0; n <= loop.size(); ++n) {
    out.push_back(loop[k]);
    if (loop[k] == y) break;
    k = (k + 1) % loop.size();
  }
  return out;
}

// A sheet corner strictly between two consecutive ruling ends (the
// spacing rule dropped the chord through it) would make a cell of five or
// more sides. Such a cell is split by rulings through the corner, each
// joined to a vertex of the other chain, as a ruled surface's rulings join
// its two boundary curves (do Carmo 1976, Sec. 3-5); every cell is then a
// triangle or a quad. Any other vertex there (a handle, an earlier
// ruling's end) still declines the strip (docs/CRUMPLING.md "The flap was
// a declined strip").
// Returns false (the strip is declined) when a cell cannot be split so.
bool splitCellsAtCorners(const GeometricMesh& g, const Loop& loop, const std::vector<int>& newLoop,
                         const CrumpleParams& params, std::vector<Ruling>& rulings) {
  const auto P = [&](int v) -> const Vec2& { return g.vertices[idx(v)].pattern; };
  // The loop path from x to y that passes neither ox nor oy (the other
  // chain's ends), inclusive; empty when there is none.
  const auto chain = [&](int x, int y, int ox, int oy) {
    if (x == y) return std::vector<int>{x};
    std::vector<int> best;
    std::vector<int> backwards = loopPath(newLoop, y, x);
    std::reverse(backwards.begin(), backwards.end());
    for (const std::vector<int>& p : {loopPath(newLoop, x, y), backwards}) {
      if (p.size() < 2 || p.front() != x || p.back() != y) continue;
      bool clear = true;
      for (std::size_t k = 1; k + 1 < p.size(); ++k)
        if ((p[k] == ox && ox != x && ox != y) || (p[k] == oy && oy != x && oy != y)) clear = false;
      if (clear && (best.empty() || p.size() < best.size())) best = p;
    }
    return best;
  };
  // Whether the segment (x, y) crosses a loop edge away from its ends.
  const auto crossesLoop = [&](int x, int y) {
    const Vec2 a = P(x), b = P(y);
    for (std::size_t k = 0; k < newLoop.size(); ++k) {
      const int u = newLoop[k], w = newLoop[(k + 1) % newLoop.size()];
      if (u == x || u == y || w == x || w == y) continue;
      const double d1 = cross2(b - a, P(u) - a), d2 = cross2(b - a, P(w) - a);
      const double d3 = cross2(P(w) - P(u), a - P(u)), d4 = cross2(P(w) - P(u), b - P(u));
      if (((d1 > 0.0) != (d2 > 0.0)) && ((d3 > 0.0) != (d4 > 0.0))) return true;
    }
    return !insideLoop(g, loop, 0.5 * (a + b));
  };
  // The width of the cell between rulings (a0, b0) and (a1, b1): twice its
  // area over its longest side (0 when degenerate).
  const auto cellWidth = [&](int a0, int b0, int a1, int b1) {
    const CellShape c = cellShape(g, {a0, b0}, {a1, b1});
    return c.longest > 0.0 ? 2.0 * c.area / c.longest : 0.0;
  };
  // Each cell between consecutive rulings is zipped: a monotone walk along
  // both chains, one ruling per step, that keeps the thinnest cell widest
  // (a cell thinner than a quarter of the ruling spacing is a sliver that
  // stalls the elastic solve, as in the spacing rule above).
  const double minWidth = 0.25 / params.rhoBound;
  std::vector<Ruling> zipped{rulings.front()};
  for (std::size_t k = 0; k + 1 < rulings.size(); ++k) {
    const Ruling& r0 = rulings[k];
    const Ruling& r1 = rulings[k + 1];
    const std::vector<int> ca = chain(r0.a, r1.a, r0.b, r1.b);
    const std::vector<int> cb = chain(r0.b, r1.b, r0.a, r1.a);
    if (ca.empty() || cb.empty()) return false;
    if (ca.size() <= 2 && cb.size() <= 2) {
      zipped.push_back(r1);
      continue;
    }
    for (const std::vector<int>* c : {&ca, &cb})
      for (std::size_t q = 1; q + 1 < c->size(); ++q)
        if (!g.vertices[idx((*c)[q])].corner) return false;
    // best[i][j]: the widest thinnest cell of a walk from (0, 0) to ruling
    // (ca[i], cb[j]); from[i][j] the step taken into it.
    const std::size_t na = ca.size(), nb = cb.size();
    std::vector<double> best(na * nb, -1.0);
    std::vector<int> from(na * nb, -1);
    best[0] = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < na; ++i) {
      for (std::size_t j = 0; j < nb; ++j) {
        if (i + j == 0) continue;
        const bool last = i + 1 == na && j + 1 == nb;
        if (!last && (ca[i] == cb[j] || crossesLoop(ca[i], cb[j]))) continue;
        for (int step = 0; step < 3; ++step) {  // 0: along a, 1: along b, 2: both
          if ((step != 1 && i == 0) || (step != 0 && j == 0)) continue;
          const std::size_t pi = step != 1 ? i - 1 : i, pj = step != 0 ? j - 1 : j;
          const double before = best[pi * nb + pj];
          if (before < 0.0) continue;
          const double w = std::min(before, cellWidth(ca[pi], cb[pj], ca[i], cb[j]));
          if (w > best[i * nb + j]) {
            best[i * nb + j] = w;
            from[i * nb + j] = step;
          }
        }
      }
    }
    if (best[na * nb - 1] < minWidth) return false;
    std::vector<Ruling> walk;
    for (std::size_t i = na - 1, j = nb - 1; i + j > 0;) {
      walk.push_back({ca[i], cb[j]});
      const int step = from[i * nb + j];
      if (step != 1) --i;
      if (step != 0) --j;
    }
    zipped.insert(zipped.end(), walk.rbegin(), walk.rend());
  }
  rulings = std::move(zipped);
  return true;
}

}  // namespace

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
      border.kind = g.vertices[idx(loop.v[idx(e.vertex)])].onBoundary ? Border::Kind::Free
                                                                      : Border::Kind::None;
      return border;
    }
    border.loopEdge = e.loopEdge;
    const int across = loop.across[idx(e.loopEdge)];
    if (across < 0) {
      border.kind = Border::Kind::Free;
    } else if (g.regions[idx(g.faces[idx(across)].region)].type == mesh::RegionType::Flat) {
      border.kind = Border::Kind::FlatFlat;
    } else {
      border.kind = Border::Kind::Curved;
    }
    return border;
  }
  return border;
}

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
    for (int v : loop.v) onLoop[idx(v)] = 1;
    for (const GeometricFace& f : g.faces) {
      if (f.region != region) continue;
      for (int k = 0; k < f.size(); ++k) {
        if (!onLoop[idx(f.v[k])]) {
          interior.push_back(f.v[k]);
          onLoop[idx(f.v[k])] = 1;
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
  if (!spaceChords(g, loop, ctx.tol, params, chords))
    return {false, "strip has fewer than two distinct rulings"};

  // Vertices for the chord ends: existing loop vertices, or new ones on dS
  // edges (several per edge are kept in order along it).
  std::map<int, std::vector<std::pair<double, int>>> onEdge;  // loop edge -> (u, new vertex)
  const auto endVertex = [&](const ChordEnd& e) {
    if (e.vertex >= 0) return loop.v[idx(e.vertex)];
    const int a = loop.v[idx(e.loopEdge)];
    const int b = loop.next(idx(e.loopEdge));
    const Vec2& pa = g.vertices[idx(a)].pattern;
    const Vec2& pb = g.vertices[idx(b)].pattern;
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
    const double minArea = 1e-4 / (params.rhoBound * params.rhoBound);
    std::vector<Ruling> kept;
    for (std::size_t k = 0; k < rulings.size(); ++k) {
      if (!kept.empty() && cellShape(g, kept.back(), rulings[k]).area < minArea) {
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
  const auto path = [&](int x, int y) { return loopPath(newLoop, x, y); };
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
  if (!splitCellsAtCorners(g, loop, newLoop, params, rulings))
    return {false, "a strip cell would hold an extra boundary vertex"};
  // Commit: drop F's faces, add the flat sides and the curved strip.
  removeRegionFaces(g, region);
  for (const std::vector<int>& side : sides) {
    triangulatePolygon(g, side, addRegion(g, mesh::RegionType::Flat), interior);
  }
  const int curved = addRegion(g, mesh::RegionType::Curved);
  g.regions[idx(curved)].rulings = rulings;
  g.regions[idx(curved)].apex = pencil.apex;
  rebuildCurvedFaces(g, curved);
  return {true, {}};
}

}  // namespace crumple::paper::detail
