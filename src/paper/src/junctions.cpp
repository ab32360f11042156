// Junction points between flat and curved regions (paper Sec. 6.1; thesis
// 2.5.1, Figs. 12-13 / 2.15-2.16).
#include <algorithm>
#include <cmath>
#include <numeric>

#include "crumple/core/geometry2d.hpp"
#include "crumple/core/index.hpp"
#include "crumple/paper/geometric_step.hpp"
#include "region_tools.hpp"

namespace crumple::paper {

namespace {

using detail::EdgeMap;
using detail::edgeMap;

std::array<int, 2> facesOf(const EdgeMap& edges, int a, int b) {
  const auto it = edges.find({std::min(a, b), std::max(a, b)});
  return it == edges.end() ? std::array<int, 2>{-1, -1} : it->second;
}

// Appends the flat triangles of a curved cell between rulings r0 and r1
// (a quad is cut along its shorter pattern diagonal).
void addFlatCell(GeometricMesh& g, const Ruling& r0, const Ruling& r1, int region) {
  std::vector<int> poly{r0.a, r1.a, r1.b, r0.b};
  poly.erase(std::unique(poly.begin(), poly.end()), poly.end());
  if (poly.size() > 1 && poly.front() == poly.back()) poly.pop_back();
  const auto P = [&](int v) -> const Vec2& { return g.vertices[idx(v)].pattern; };
  const auto add = [&](int a, int b, int c) {
    GeometricFace f;
    f.v = {a, b, c, -1};
    if (cross2(P(b) - P(a), P(c) - P(a)) < 0.0) std::swap(f.v[1], f.v[2]);
    f.region = region;
    if (std::abs(cross2(P(b) - P(a), P(c) - P(a))) > 0.0) g.faces.push_back(f);
  };
  if (poly.size() == 3) {
    add(poly[0], poly[1], poly[2]);
  } else if (poly.size() == 4) {
    if ((P(poly[0]) - P(poly[2])).norm() <= (P(poly[1]) - P(poly[3])).norm()) {
      add(poly[0], poly[1], poly[2]);
      add(poly[0], poly[2], poly[3]);
    } else {
      add(poly[0], poly[1], poly[3]);
      add(poly[1], poly[2], poly[3]);
    }
  }
}

// paper Sec. 6.1, Fig. 12 right: the junction points of C's end ruling
// `end` (0 or last) slide one ruling spacing along dS into the flat region F
// across it, and the strip they sweep becomes a new cell of C. Returns false
// (nothing changed) when dS does not continue into F at both ends, the new
// ruling would leave F or pass a vertex of F, or a junction point would
// reach another region whose angle with F is larger (Fig. 13).
bool expandIntoFlat(GeometricMesh& g, int region, bool front, int flat, double thetaCF,
                    const CrumpleParams& params, const BoundaryPosition& boundary) {
  using namespace detail;
  const EdgeMap edges = edgeMap(g);
  const auto loopOpt = regionLoop(g, flat, edges);
  if (!loopOpt) return false;
  Loop loop = *loopOpt;
  const Region& c = g.regions[idx(region)];
  const Ruling r = front ? c.rulings.front() : c.rulings.back();
  const auto P = [&](int v) -> const Vec2& { return g.vertices[idx(v)].pattern; };
  const std::size_t m = loop.size();
  const auto indexOf = [&](int v) {
    return idx(std::find(loop.v.begin(), loop.v.end(), v) - loop.v.begin());
  };
  const std::size_t ia = indexOf(r.a);
  const std::size_t ib = indexOf(r.b);
  if (ia == m || ib == m) return false;
  // The ruling is loop edge ia -> ib or ib -> ia; each end moves along the
  // loop edge on its other side.
  const bool aFirst = (ia + 1) % m == ib;
  if (!aFirst && (ib + 1) % m != ia) return false;
  const double h = 1.0 / params.rhoBound;
  struct Move {
    int from = -1;
    int to = -1;  // existing vertex, or -1 with `point` on loop edge `edge`
    Vec2 point = Vec2::Zero();
    std::size_t edge = 0;
  };
  const auto slide = [&](std::size_t i, bool forward) -> std::optional<Move> {
    Move mv;
    mv.from = loop.v[i];
    if (g.vertices[idx(mv.from)].singular && !g.vertices[idx(mv.from)].onBoundary) {
      mv.to = mv.from;  // a cone apex stays
      return mv;
    }
    const std::size_t e =
        forward ? i : (i + m - 1) % m;             // loop edge leaving i away from the ruling
    if (loop.across[e] >= 0) return std::nullopt;  // not dS
    const int other = forward ? loop.v[(i + 1) % m] : loop.v[(i + m - 1) % m];
    const double len = (P(other) - P(mv.from)).norm();
    if (len <= 1.5 * h) {
      mv.to = other;
      return mv;
    }
    mv.point = P(mv.from) + (P(other) - P(mv.from)) * (h / len);
    mv.edge = e;
    return mv;
  };
  // Walking away from the ruling: from a backwards when the loop runs a -> b.
  const auto ma = slide(ia, !aFirst);
  const auto mb = slide(ib, aFirst);
  if (!ma || !mb) return false;
  if (ma->to == r.a && mb->to == r.b) return false;
  // Fig. 13: a junction point reaching a vertex shared with a third region
  // moves only if C's angle with F beats that region's.
  for (const Move* mv : {&*ma, &*mb}) {
    if (mv->to < 0 || mv->to == mv->from) continue;
    for (std::size_t k = 0; k < m; ++k) {
      if (loop.v[k] != mv->to && loop.next(k) != mv->to) continue;
      if (loop.across[k] < 0) continue;
      const auto faces =
          edges.at({std::min(loop.v[k], loop.next(k)), std::max(loop.v[k], loop.next(k))});
      const double opp = dihedralAngle(g, faces[0], faces[1]);
      if (!(thetaCF > opp)) return false;
    }
  }
  // The new ruling must run inside F, crossing no loop edge and no vertex.
  const Vec2 pa = ma->to >= 0 ? P(ma->to) : ma->point;
  const Vec2 pb = mb->to >= 0 ? P(mb->to) : mb->point;
  if ((pb - pa).norm() < 1e-9) return false;
  if (!insideLoop(g, loop, 0.5 * (pa + pb))) return false;
  const auto cross2 = [](const Vec2& u, const Vec2& v) { return u.x() * v.y() - u.y() * v.x(); };
  for (std::size_t k = 0; k < m; ++k) {
    const Vec2& q0 = P(loop.v[k]);
    const Vec2& q1 = P(loop.next(k));
    const double d1 = cross2(pb - pa, q0 - pa);
    const double d2 = cross2(pb - pa, q1 - pa);
    const double d3 = cross2(q1 - q0, pa - q0);
    const double d4 = cross2(q1 - q0, pb - q0);
    const double tol = 1e-12 * (pb - pa).squaredNorm();
    if (((d1 > tol && d2 < -tol) || (d1 < -tol && d2 > tol)) &&
        ((d3 > tol && d4 < -tol) || (d3 < -tol && d4 > tol))) {
      return false;
    }
  }
  const std::vector<int> inner = innerVertices(g, flat, loop);
  for (int v : inner) {
    const Vec2 q = P(v);
    const double t = (q - pa).dot(pb - pa) / (pb - pa).squaredNorm();
    if (t > -0.05 && t < 1.05 && std::abs(cross2(pb - pa, q - pa)) / (pb - pa).norm() < 0.25 * h)
      return false;
  }
  // Commit: new vertices on dS, F re-triangulated without the swept cell.
  std::vector<int> newLoop = loop.v;
  const auto place = [&](const Move& mv) {
    if (mv.to >= 0) return mv.to;
    const int a = loop.v[mv.edge];
    const int b = loop.next(mv.edge);
    const int v = addBoundaryVertex(g, a, b, mv.point, boundary);
    const auto it = std::find(newLoop.begin(), newLoop.end(), b);
    newLoop.insert(it == newLoop.begin() ? newLoop.end() : it, v);
    return v;
  };
  const int na = place(*ma);
  const int nb = place(*mb);
  // Remainder of F: the loop path from the new end next to b around to the
  // new end next to a, avoiding the ruling (a, b).
  const std::size_t n2 = newLoop.size();
  const auto pos = [&](int v) {
    return idx(std::find(newLoop.begin(), newLoop.end(), v) - newLoop.begin());
  };
  std::vector<int> rest;
  {
    // Loop runs a -> b (aFirst) or b -> a; the remainder runs from b's new
    // end forwards to a's new end (aFirst), else from a's to b's.
    const int start = aFirst ? nb : na;
    const int stop = aFirst ? na : nb;
    std::size_t k = pos(start);
    for (std::size_t step = 0; step <= n2; ++step) {
      rest.push_back(newLoop[k]);
      if (newLoop[k] == stop) break;
      k = (k + 1) % n2;
    }
  }
  removeRegionFaces(g, flat);
  if (rest.size() >= 3) triangulatePolygon(g, rest, flat, inner);
  Region& cr = g.regions[idx(region)];
  const Ruling added{na, nb};
  if (front) {
    cr.rulings.insert(cr.rulings.begin(), added);
  } else {
    cr.rulings.push_back(added);
  }
  rebuildCurvedFaces(g, region);
  return true;
}

}  // namespace

double rulingDihedral(const GeometricMesh& g, int region, int k) {
  const Ruling& r = g.regions[idx(region)].rulings[idx(k)];
  const EdgeMap edges = edgeMap(g);
  const auto faces = facesOf(edges, r.a, r.b);
  if (faces[0] < 0 || faces[1] < 0) return 0.0;
  return dihedralAngle(g, faces[0], faces[1]);
}

// paper Sec. 6.1: at each border ruling between C and a flat region F, the
// dihedral angle theta_CF below theta_low moves the junction points into C
// (F grows) up to the first ruling whose angle exceeds theta_low; a curved
// region whose rulings are all below theta_low turns flat; theta_CF above
// theta_high moves them into F by one ruling spacing (C grows), subject to
// the opposite-region rule of Fig. 13.
void updateJunctions(GeometricMesh& g, const CrumpleParams& params,
                     const BoundaryPosition& boundary, GeometricStepStats& stats) {
  detail::EdgeMapCache edgeCache;
  for (std::size_t ri = 0; ri < g.regions.size(); ++ri) {
    if (g.regions[ri].type != mesh::RegionType::Curved) continue;
    const int region = static_cast<int>(ri);
    std::vector<Ruling> rulings = g.regions[ri].rulings;
    if (rulings.size() < 2) continue;
    const EdgeMap& edges = edgeCache.of(g);
    // Dihedral at every ruling (0 at an end ruling on dS).
    std::vector<double> angle(rulings.size(), 0.0);
    std::vector<int> outside(rulings.size(), -1);  // face across an end ruling
    for (std::size_t k = 0; k < rulings.size(); ++k) {
      const auto faces = facesOf(edges, rulings[k].a, rulings[k].b);
      if (faces[0] >= 0 && faces[1] >= 0) angle[k] = dihedralAngle(g, faces[0], faces[1]);
      if (k == 0 || k + 1 == rulings.size()) {
        for (int f : faces) {
          if (f >= 0 && g.faces[idx(f)].region != region) outside[k] = f;
        }
      }
    }
    const GeometricMesh regionBefore = g;
    const auto undoIfBroken = [&](const char* what) {
      if (const std::string problem = validate(g); !problem.empty()) {
        g = regionBefore;
        stats.notes.push_back(std::string(what) + " of curved region " + std::to_string(ri) +
                              " undone (" + problem + ")");
        return true;
      }
      return false;
    };
    const bool apexRegion = g.regions[ri].apex >= 0;
    // A cone from a singular vertex is kept whole: its apex is permanent and
    // its rulings are what makes the singularity visible.
    if (apexRegion) continue;
    const bool allLow = std::all_of(angle.begin() + 1, angle.end() - 1,
                                    [&](double a) { return a < params.thetaLow; });
    const auto flatOutside = [&](std::size_t k) {
      return outside[k] >= 0 &&
             g.regions[idx(g.faces[idx(outside[k])].region)].type == mesh::RegionType::Flat;
    };
    const bool endsLow = (outside.front() < 0 || angle.front() < params.thetaLow) &&
                         (outside.back() < 0 || angle.back() < params.thetaLow);
    if (allLow && endsLow) {
      // The whole curved region becomes flat (thesis 2.5.1, last paragraph).
      removeRegionFaces(g, region);
      g.regions[ri].type = mesh::RegionType::Flat;
      g.regions[ri].rulings.clear();
      for (std::size_t k = 0; k + 1 < rulings.size(); ++k)
        addFlatCell(g, rulings[k], rulings[k + 1], region);
      if (!undoIfBroken("flattening")) ++stats.curvedFlattened;
      continue;
    }
    // Shrink from each end next to a flat region while theta_CF < theta_low.
    std::size_t first = 0;
    std::size_t last = rulings.size() - 1;
    // An end on dS (no region across) shrinks the same way; the cells it
    // gives up form a new flat region.
    const auto canShrink = [&](std::size_t k) {
      return outside[k] < 0 || (flatOutside(k) && angle[k] < params.thetaLow);
    };
    if (canShrink(0)) {
      while (first + 1 < last && angle[first + 1] < params.thetaLow) ++first;
    }
    if (canShrink(rulings.size() - 1)) {
      while (last > first + 1 && angle[last - 1] < params.thetaLow) --last;
    }
    if (first == 0 && last == rulings.size() - 1) {
      // Fig. 12 right: theta_CF above theta_high moves the junction points
      // into F so the next elastic steps can smooth the angle out.
      for (const bool front : {true, false}) {
        const std::size_t k = front ? 0 : rulings.size() - 1;
        if (!flatOutside(k) || !(angle[k] > params.thetaHigh)) continue;
        const int flat = g.faces[idx(outside[k])].region;
        const GeometricMesh before = g;
        bool moved = false;
        try {
          moved = expandIntoFlat(g, region, front, flat, angle[k], params, boundary);
        } catch (const std::exception& e) {
          g = before;
          stats.notes.push_back(std::string("junction move undone (") + e.what() + ")");
        }
        if (moved) {
          if (const std::string problem = validate(g); !problem.empty()) {
            g = before;
            stats.notes.push_back("junction move undone (" + problem + ")");
          } else {
            ++stats.junctionMoves;
          }
        }
        break;  // one move per region and step: the edge map is stale afterwards
      }
      continue;
    }
    const auto newFlat = [&]() {
      Region r;
      r.type = mesh::RegionType::Flat;
      g.regions.push_back(r);
      return static_cast<int>(g.regions.size()) - 1;
    };
    const int frontFlat =
        first == 0 ? -1 : (flatOutside(0) ? g.faces[idx(outside.front())].region : newFlat());
    const int backFlat =
        last + 1 == rulings.size()
            ? -1
            : (flatOutside(rulings.size() - 1) ? g.faces[idx(outside.back())].region : newFlat());
    removeRegionFaces(g, region);
    for (std::size_t k = 0; k < first; ++k) addFlatCell(g, rulings[k], rulings[k + 1], frontFlat);
    for (std::size_t k = last; k + 1 < rulings.size(); ++k)
      addFlatCell(g, rulings[k], rulings[k + 1], backFlat);
    g.regions[ri].rulings.assign(rulings.begin() + static_cast<std::ptrdiff_t>(first),
                                 rulings.begin() + static_cast<std::ptrdiff_t>(last) + 1);
    if (g.regions[ri].rulings.size() >= 2) {
      rebuildCurvedFaces(g, region);
    } else {
      g.regions[ri].rulings.clear();
    }
    if (!undoIfBroken("junction shrink"))
      stats.junctionMoves += static_cast<int>(first + (rulings.size() - 1 - last));
  }
  compact(g);
}

}  // namespace crumple::paper
