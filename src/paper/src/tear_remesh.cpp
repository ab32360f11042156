#include "crumple/paper/tear_remesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <stdexcept>
#include <string>

#include "crumple/core/geometry2d.hpp"
#include "crumple/core/index.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/tear/cut.hpp"

namespace crumple::paper {

namespace {

const Vec2& patternOf(const GeometricMesh& g, int v) { return g.vertices[idx(v)].pattern; }

// Whether segments [a, b] and [c, d] meet (touching within tol counts).
bool segmentsMeet(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d, double tol) {
  if (distanceToSegment(a, c, d) <= tol || distanceToSegment(b, c, d) <= tol ||
      distanceToSegment(c, a, b) <= tol || distanceToSegment(d, a, b) <= tol)
    return true;
  const double d1 = cross2(b - a, c - a), d2 = cross2(b - a, d - a);
  const double d3 = cross2(d - c, a - c), d4 = cross2(d - c, b - c);
  return ((d1 > 0.0) != (d2 > 0.0)) && ((d3 > 0.0) != (d4 > 0.0));
}

// Whether the advance [from, to] touches face f (crosses, ends in or runs
// along it).
bool advanceTouchesFace(const GeometricMesh& g, int f, const Vec2& from, const Vec2& to,
                        double tol) {
  const GeometricFace& face = g.faces[idx(f)];
  const int n = face.size();
  bool inside = true;  // `to` strictly inside the (counter-clockwise) face, if it is convex there
  double winding = 0.0;
  for (int k = 0; k < n; ++k) {
    const Vec2& a = patternOf(g, face.v[idx(k)]);
    const Vec2& b = patternOf(g, face.v[idx((k + 1) % n)]);
    if (segmentsMeet(from, to, a, b, tol)) return true;
    inside = inside && cross2(b - a, to - a) > 0.0;
    winding += std::atan2(cross2(a - to, b - to), (a - to).dot(b - to));
  }
  return inside || std::abs(winding) > 3.0;  // a whole turn: inside a non-convex quad too
}

// Cases 1-2 (thesis Figs. 3.21-3.22), reduced to case 3: curved region r
// becomes flat triangles, each quad split on a diagonal that keeps both
// halves counter-clockwise; its vertices stay where they are in the pattern
// and in 3D.
void flattenRegion(GeometricMesh& g, int r) {
  Region& region = g.regions[idx(r)];
  region.type = mesh::RegionType::Flat;
  region.rulings.clear();
  region.apex = -1;
  std::vector<GeometricFace> faces;
  faces.reserve(g.faces.size() + 8);
  for (const GeometricFace& f : g.faces) {
    if (f.region != r || f.size() == 3) {
      faces.push_back(f);
      continue;
    }
    const auto P = [&](int k) -> const Vec2& { return patternOf(g, f.v[idx(k)]); };
    const auto ccw = [](const Vec2& a, const Vec2& b, const Vec2& c) {
      return cross2(b - a, c - a) > 0.0;
    };
    // The diagonal whose two triangles are both counter-clockwise, the
    // shorter one when both are.
    const bool d02 = ccw(P(0), P(1), P(2)) && ccw(P(0), P(2), P(3));
    const bool d13 = ccw(P(1), P(2), P(3)) && ccw(P(1), P(3), P(0));
    const bool use02 = d02 && (!d13 || (P(2) - P(0)).norm() <= (P(3) - P(1)).norm());
    if (!use02 && !d13)
      throw std::invalid_argument("cutGeometricMesh: a quad of curved region " + std::to_string(r) +
                                  " cannot be split into triangles");
    const std::array<int, 4>& v = f.v;
    GeometricFace a, b;
    a.region = b.region = r;
    a.v =
        use02 ? std::array<int, 4>{v[0], v[1], v[2], -1} : std::array<int, 4>{v[1], v[2], v[3], -1};
    b.v =
        use02 ? std::array<int, 4>{v[0], v[2], v[3], -1} : std::array<int, 4>{v[1], v[3], v[0], -1};
    faces.push_back(a);
    faces.push_back(b);
  }
  g.faces = std::move(faces);
}

// The directed boundary edges of S_G (face on the left): next[a] = b.
std::map<int, int> boundaryNext(const GeometricMesh& g) {
  std::map<std::pair<int, int>, int> uses;
  for (const GeometricFace& f : g.faces)
    for (int k = 0; k < f.size(); ++k) {
      const int a = f.v[idx(k)];
      const int b = f.v[idx((k + 1) % f.size())];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  std::map<int, int> next;
  for (const GeometricFace& f : g.faces)
    for (int k = 0; k < f.size(); ++k) {
      const int a = f.v[idx(k)];
      const int b = f.v[idx((k + 1) % f.size())];
      if (uses[{std::min(a, b), std::max(a, b)}] != 1) continue;
      if (!next.emplace(a, b).second)
        throw std::invalid_argument("cutGeometricMesh: the outline touches itself at vertex " +
                                    std::to_string(a));
    }
  return next;
}

// The outline of S_G from its boundary edges (one simple loop): its corners
// are the loop's vertices flagged `corner` and those where the loop turns;
// every boundary vertex gets the segment holding it. The loop starts at the
// old outline's first corner when it is still a vertex, so outline
// parameters keep their origin.
void rebuildOutline(GeometricMesh& g, const Vec2& firstCorner, double perimeter) {
  const std::map<int, int> next = boundaryNext(g);
  if (next.empty()) throw std::invalid_argument("cutGeometricMesh: S_G has no outline");
  int start = next.begin()->first;
  for (const auto& [a, b] : next)
    if (g.vertices[idx(a)].corner && (patternOf(g, a) - firstCorner).norm() == 0.0) start = a;
  std::vector<int> loop;
  for (int v = start;;) {
    loop.push_back(v);
    const auto it = next.find(v);
    if (it == next.end())
      throw std::invalid_argument("cutGeometricMesh: the outline is not closed");
    v = it->second;
    if (v == start) break;
    if (loop.size() > next.size())
      throw std::invalid_argument("cutGeometricMesh: the outline is not one loop");
  }
  if (loop.size() != next.size())
    throw std::invalid_argument("cutGeometricMesh: the sheet's outline is more than one loop");
  const std::size_t n = loop.size();
  const double straight = 1e-11 * perimeter;  // off the line through both neighbours: a corner
  std::vector<char> isCorner(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    GeometricVertex& v = g.vertices[idx(loop[k])];
    const Vec2& a = patternOf(g, loop[(k + n - 1) % n]);
    const Vec2& b = patternOf(g, loop[(k + 1) % n]);
    const double off = (b - a).norm() > 0.0
                           ? std::abs(cross2(b - a, v.pattern - a)) / (b - a).norm()
                           : (v.pattern - a).norm();
    if (v.corner || off > straight || (v.pattern - a).dot(b - v.pattern) <= 0.0) {
      isCorner[k] = 1;
      v.corner = true;
    }
  }
  if (!isCorner[0])
    throw std::invalid_argument("cutGeometricMesh: the outline lost its first corner");
  g.outline.clear();
  int segment = -1;
  for (std::size_t k = 0; k < n; ++k) {
    GeometricVertex& v = g.vertices[idx(loop[k])];
    if (isCorner[k]) {
      g.outline.push_back(v.pattern);
      ++segment;
    }
    v.onBoundary = true;
    v.outlineSegment = segment;
  }
}

// thesis 3.3.3 cases 1-2 (Figs. 3.21-3.22) reduced to case 3: the curved regions the advance
// [from, to] touches become flat; returns how many.
int flattenTouchedRegions(GeometricMesh& h, const Vec2& from, const Vec2& to, double tol) {
  std::set<int> curved;
  for (std::size_t f = 0; f < h.faces.size(); ++f) {
    const int r = h.faces[f].region;
    if (h.regions[idx(r)].type == mesh::RegionType::Curved &&
        advanceTouchesFace(h, static_cast<int>(f), from, to, tol))
      curved.insert(r);
  }
  for (int r : curved) flattenRegion(h, r);
  return static_cast<int>(curved.size());
}

// Adds triangle (a, b, c) of S_G face `face` to the cut's triangle mesh.
void addTriangle(mesh::SheetMesh& sm, int a, int b, int c, int face) {
  sm.triangles.push_back({a, b, c});
  sm.regionOfTriangle.push_back(face);
}

// S_G's faces as a triangle mesh for tear::cutAlong; each triangle's region is its S_G face.
mesh::SheetMesh triangleMesh(const GeometricMesh& h) {
  mesh::SheetMesh sm;
  for (const GeometricVertex& v : h.vertices) {
    sm.pattern.push_back(v.pattern);
    sm.positions.push_back(v.position);
  }
  for (std::size_t f = 0; f < h.faces.size(); ++f) {
    const auto& v = h.faces[f].v;
    addTriangle(sm, v[0], v[1], v[2], static_cast<int>(f));
    if (h.faces[f].size() == 4) addTriangle(sm, v[0], v[2], v[3], static_cast<int>(f));
  }
  sm.regionTypes.assign(h.faces.size(), mesh::RegionType::Flat);
  return sm;
}

// Splits sm's triangle holding the directed outline edge a -> b at v, a new vertex on it.
void splitOutlineTriangle(mesh::SheetMesh& sm, int a, int b, int v) {
  for (std::size_t t = 0; t < sm.triangles.size(); ++t) {
    auto& tri = sm.triangles[t];
    for (std::size_t k = 0; k < 3; ++k) {
      if (tri[k] != a || tri[(k + 1) % 3] != b) continue;
      const int c = tri[(k + 2) % 3];
      const int face = sm.regionOfTriangle[t];
      tri = {a, v, c};
      addTriangle(sm, v, b, c, face);
      return;
    }
  }
  throw std::logic_error("cutGeometricMesh: an outline edge without its triangle");
}

// thesis 3.3.3: the tear's start s_t, an S_G outline vertex or a new one on the outline edge
// holding it (added to h and sm); -1 when `from` is not on the outline.
int tearStartVertex(GeometricMesh& h, mesh::SheetMesh& sm, const Vec2& from, double tol) {
  int fromVertex = -1;
  for (std::size_t v = 0; v < h.vertices.size(); ++v)
    if (h.vertices[v].onBoundary && (h.vertices[v].pattern - from).norm() <= tol) {
      fromVertex = static_cast<int>(v);
      break;
    }
  if (fromVertex < 0) {
    const std::map<int, int> next = boundaryNext(h);
    for (const auto& [a, b] : next) {
      if (distanceToSegment(from, patternOf(h, a), patternOf(h, b)) > tol) continue;
      const Vec2 pa = patternOf(h, a), pb = patternOf(h, b);
      const double u = std::clamp((from - pa).dot(pb - pa) / (pb - pa).squaredNorm(), 0.0, 1.0);
      GeometricVertex nv;
      nv.pattern = pa + u * (pb - pa);
      const GeometricVertex& va = h.vertices[idx(a)];
      const GeometricVertex& vb = h.vertices[idx(b)];
      nv.position = (1.0 - u) * va.position + u * vb.position;
      nv.velocity = (1.0 - u) * va.velocity + u * vb.velocity;
      nv.onBoundary = true;
      nv.outlineSegment = va.outlineSegment;
      fromVertex = addVertex(h, nv);
      sm.pattern.push_back(nv.pattern);
      sm.positions.push_back(nv.position);
      // Split the triangle holding the edge a -> b.
      splitOutlineTriangle(sm, a, b, fromVertex);
      break;
    }
  }
  return fromVertex;
}

// thesis 3.3.3: the S_G vertices of the cut's new vertices of sm (from index `before` on),
// blended from the old ones, placed on the surface when options.surface says where.
void addCutVertices(GeometricMesh& h, const mesh::SheetMesh& sm, const tear::CutResult& cut,
                    std::size_t before, const GeometricCutOptions& options) {
  for (std::size_t i = before; i < sm.vertexCount(); ++i) {
    const tear::VertexBlend& b = cut.blends.at(i - before);
    GeometricVertex nv;
    nv.pattern = sm.pattern[i];
    nv.position = sm.positions[i];
    for (std::size_t k = 0; k < 3; ++k)
      if (b.vertex[k] >= 0) nv.velocity += b.weight[k] * h.vertices[idx(b.vertex[k])].velocity;
    nv.onBoundary = true;
    Vec3 x, v;
    if (options.surface && options.surface(nv.pattern, x, v) && x.allFinite() && v.allFinite()) {
      nv.position = x;
      nv.velocity = v;
    }
    (void)addVertex(h, nv);
  }
}

// thesis 3.3.3 case 3 (Fig. 3.23): S_G's faces in their old order after the cut, an unchanged
// face as it was, a cut one as its triangles.
std::vector<GeometricFace> facesAfterCut(const GeometricMesh& h, const mesh::SheetMesh& sm) {
  std::vector<std::vector<std::array<int, 3>>> pieces(h.faces.size());
  for (std::size_t t = 0; t < sm.triangles.size(); ++t)
    pieces[idx(sm.regionOfTriangle[t])].push_back(sm.triangles[t]);
  std::vector<GeometricFace> faces;
  for (std::size_t f = 0; f < h.faces.size(); ++f) {
    const GeometricFace& old = h.faces[f];
    const auto& mine = pieces[f];
    const bool same =
        old.size() == 4
            ? mine.size() == 2 && mine[0] == std::array<int, 3>{old.v[0], old.v[1], old.v[2]} &&
                  mine[1] == std::array<int, 3>{old.v[0], old.v[2], old.v[3]}
            : mine.size() == 1 && mine[0] == std::array<int, 3>{old.v[0], old.v[1], old.v[2]};
    if (same) {
      faces.push_back(old);
      continue;
    }
    if (old.size() == 4)
      throw std::logic_error("cutGeometricMesh: the cut went through a curved quad");
    for (const auto& t : mine) {
      GeometricFace nf;
      nf.v = {t[0], t[1], t[2], -1};
      nf.region = old.region;
      faces.push_back(nf);
    }
  }
  return faces;
}

// thesis 3.3.3 (the split s_t^1, s_t^2 of Fig. 3.20): each lip copy's move off the cut's
// centre line for a kerf of width w; a new tear's first copies slide along their outline edge.
std::vector<std::pair<int, Vec2>> kerfMoves(const GeometricMesh& h, const std::vector<Vec2>& centre,
                                            const tear::CutResult& cut, double w,
                                            const std::optional<Vec2>& previousDirection,
                                            const std::vector<std::vector<int>>& trianglesOf) {
  const auto left = [](const Vec2& d) { return Vec2(-d.y(), d.x()); };
  const std::map<int, int> next = boundaryNext(h);
  std::map<int, int> prev;
  for (const auto& [a, b] : next) prev[b] = a;
  std::vector<std::pair<int, Vec2>> moves;
  for (std::size_t k = 0; k < cut.twins.size(); ++k) {
    const Vec2& p = centre[k];
    const Vec2 out = (centre[k + 1] - p).normalized();
    std::optional<Vec2> in;
    if (k > 0)
      in = (p - centre[k - 1]).normalized();
    else if (previousDirection)
      in = previousDirection->normalized();
    for (const int c : {cut.chain[k], cut.twins[k]}) {
      Vec2 centroid = Vec2::Zero();
      for (int f : trianglesOf[idx(c)])
        centroid += (patternArea(h, f) > 0.0 ? 1.0 : 0.0) *
                    (patternOf(h, h.faces[idx(f)].v[0]) + patternOf(h, h.faces[idx(f)].v[1]) +
                     patternOf(h, h.faces[idx(f)].v[2])) /
                    3.0;
      centroid /= static_cast<double>(std::max<std::size_t>(1, trianglesOf[idx(c)].size()));
      const double side = cross2(out, centroid - p) > 0.0 ? 1.0 : -1.0;
      Vec2 move;
      if (in) {
        const Vec2 nIn = side * left(*in), nOut = side * left(out);
        move = 0.5 * w * (nIn + nOut) / std::max(1.0 + nIn.dot(nOut), 0.2);
      } else {
        // The copy's outline edge: the boundary edge that is not on the cut.
        // The copy's next vertex on the cut: the chain's second point (either
        // lip's copy of it, or the tip when the cut is one edge long).
        const int n = next.at(c);
        const bool cutForward = n == cut.chain[1] || (cut.twins.size() > 1 && n == cut.twins[1]);
        const int q = cutForward ? prev.at(c) : next.at(c);
        const Vec2 e = patternOf(h, q) - p;
        const double sine = std::abs(cross2(e.normalized(), out));
        if (sine < 0.05)
          throw std::invalid_argument("cutGeometricMesh: the tear runs along the outline");
        const double slide = std::min(0.5 * w / sine, 0.3 * e.norm());
        move = slide * e.normalized();
      }
      moves.emplace_back(c, move);
    }
  }
  return moves;
}

}  // namespace

// thesis 3.3.3 "Remeshing", Figs. 3.20-3.23.
std::optional<GeometricCutResult> cutGeometricMesh(GeometricMesh& g, const Vec2& from,
                                                   const Vec2& to,
                                                   const GeometricCutOptions& options,
                                                   const std::optional<Vec2>& previousDirection) {
  if (!(options.kerf > 0.0) || !std::isfinite(options.kerf))
    throw std::invalid_argument("cutGeometricMesh: kerf must be finite and > 0");
  if (!from.allFinite() || !to.allFinite())
    throw std::invalid_argument("cutGeometricMesh: non-finite advance");
  if (previousDirection) {
    const Vec2 d = to - from;
    const double turn =
        std::atan2(std::abs(cross2(*previousDirection, d)), previousDirection->dot(d));
    if (turn > options.maxTurn)
      throw std::invalid_argument("cutGeometricMesh: the tear would turn back by " +
                                  std::to_string(turn * 180.0 / std::numbers::pi) + " degrees");
  }
  GeometricMesh h = g;
  const double perimeter = outlinePerimeter(h);
  const double tol = 1e-9 * perimeter;
  const double w = options.kerf;
  GeometricCutResult result;

  // Cases 1-2 to case 3: the curved regions the advance touches become flat.
  result.regionsFlattened = flattenTouchedRegions(h, from, to, tol);

  // S_G's faces as a triangle mesh; each triangle's region is its S_G face.
  mesh::SheetMesh sm = triangleMesh(h);

  // s_t: an S_G outline vertex, or a new one on the outline edge holding it.
  const int fromVertex = tearStartVertex(h, sm, from, tol);
  if (fromVertex < 0)
    throw std::invalid_argument("cutGeometricMesh: the tear's start is not on S_G's outline");

  // The cut (thesis 3.3.3): existing S_G vertices never move.
  const std::size_t before = h.vertices.size();
  std::vector<char> fixed(before, 1);
  tear::CutOptions cutOptions;
  cutOptions.snap = options.snap;
  cutOptions.fixed = &fixed;
  const tear::CutResult cut = tear::cutAlong(sm, fromVertex, to, cutOptions);
  if (cut.separated) return std::nullopt;
  if (cut.chain.size() < 2) throw std::invalid_argument("cutGeometricMesh: the cut is empty");

  // New vertices: the lips' copies and s_{t+1}, blended from the old ones.
  addCutVertices(h, sm, cut, before, options);
  // Faces in their old order: an unchanged face as it was, a cut one as its pieces.
  h.faces = facesAfterCut(h, sm);

  // The kerf: each lip's copies move off the centre line by w / 2, to where
  // the kerf lines of the cut's pieces on either side of them meet; a new
  // tear's first copies slide along their outline edge instead. s_{t+1}
  // stays: the slit is a V there.
  std::vector<Vec2> centre;
  for (int v : cut.chain) centre.push_back(sm.pattern[idx(v)]);
  result.cut = centre;
  std::vector<std::vector<int>> trianglesOf(h.vertices.size());
  for (std::size_t f = 0; f < h.faces.size(); ++f)
    for (int k = 0; k < h.faces[f].size(); ++k)
      trianglesOf[idx(h.faces[f].v[idx(k)])].push_back(static_cast<int>(f));
  const std::vector<std::pair<int, Vec2>> moves =
      kerfMoves(h, centre, cut, w, previousDirection, trianglesOf);
  for (const auto& [c, move] : moves) h.vertices[idx(c)].pattern += move;
  for (const auto& [c, move] : moves)
    for (int f : trianglesOf[idx(c)])
      if (!(patternArea(h, f) > 0.0))
        throw std::invalid_argument("cutGeometricMesh: the kerf folds a face over");
  h.vertices[idx(cut.tip)].corner = true;
  h.vertices[idx(cut.tip)].onBoundary = true;

  rebuildOutline(h, g.outline.front(), perimeter);
  if (const std::string problem = validate(h); !problem.empty())
    throw std::invalid_argument("cutGeometricMesh: S_G after the cut: " + problem);
  result.tip = cut.tip;
  g = std::move(h);
  return result;
}

}  // namespace crumple::paper
