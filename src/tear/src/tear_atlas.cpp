// Baking the tear textures (tear_atlas.hpp; thesis 3.3.4, Figs. 3.24-3.25).
#include "crumple/tear/tear_atlas.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "crumple/core/geometry2d.hpp"
#include "crumple/tear/lip_masks.hpp"

namespace crumple::tear {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr long long kTile = 64;                   // texels per side of a side tile
constexpr long long kMaxAtlasTexels = 1LL << 28;  // std::length_error beyond
constexpr double kMinTurn = 1e-9;                 // sine of a turn of the cut worth a wider quad

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

long long floorDiv(long long a, long long b) {
  return a / b - ((a % b != 0) && ((a < 0) != (b < 0)));
}

// The point of a polyline nearest q: its distance and arc-length parameter.
struct Closest {
  double distance = kInf;
  double param = 0.0;
};
Closest closestOnPolyline(const std::vector<Vec2>& line, const Vec2& q) {
  Closest best;
  double along = 0.0;
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    const Vec2 ab = line[i + 1] - line[i];
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0.0 ? std::clamp((q - line[i]).dot(ab) / len2, 0.0, 1.0) : 0.0;
    const double d = (q - (line[i] + t * ab)).norm();
    const double len = std::sqrt(len2);
    if (d < best.distance) best = {d, along + t * len};
    along += len;
  }
  return best;
}

// Distance between a triangle and a polyline that does not cross it (no cut
// crosses a triangle): from the triangle's corners to the line, and from the
// line's points to the triangle.
double triangleToPolyline(const std::array<Vec2, 3>& tri, const std::vector<Vec2>& line) {
  double d = kInf;
  for (const Vec2& v : tri) d = std::min(d, closestOnPolyline(line, v).distance);
  const double area = cross(tri[1] - tri[0], tri[2] - tri[0]);
  for (const Vec2& q : line) {
    const double w1 = cross(q - tri[0], tri[2] - tri[0]) / area;
    const double w2 = cross(tri[1] - tri[0], q - tri[0]) / area;
    if (w1 >= 0.0 && w2 >= 0.0 && w1 + w2 <= 1.0) return 0.0;
    for (std::size_t k = 0; k < 3; ++k)
      d = std::min(d, distanceToSegment(q, tri[k], tri[(k + 1) % 3]));
  }
  return d;
}

// Whether q lies left of the path (leftOfPath at one pixel centred on q).
bool leftOf(const std::vector<Vec2>& path, const Vec2& q, double pixelSize) {
  PixelGrid g;
  g.origin = q - Vec2::Constant(0.5 * pixelSize);
  g.pixelSize = pixelSize;
  g.width = g.height = 1;
  return leftOfPath(path, g)[0] == 1;
}

// Consecutive points closer than tol merged.
std::vector<Vec2> withoutRepeats(const std::vector<Vec2>& line, double tol) {
  std::vector<Vec2> out;
  for (const Vec2& p : line)
    if (out.empty() || (p - out.back()).norm() > tol) out.push_back(p);
  return out;
}

// One tear's segments joined: its whole cut and detail path (thesis 3.3.4:
// T_left and T_right are updated as the tear propagates).
struct Chain {
  int tear = 0;
  std::vector<Vec2> cut;
  std::vector<Vec2> detail;
  // Both continued far beyond their ends along the cut's first and last
  // edges: leftOfPath then splits the plane along the tear and, beyond its
  // ends, along the lines of those edges, which no lip triangle crosses.
  std::vector<Vec2> paddedCut;
  std::vector<Vec2> paddedDetail;
  double length = 0.0;   // of the cut (m)
  double support = 0.0;  // the support quads' width (m)

  // Whether an arc length along the cut is strictly between its ends.
  bool inside(double param, double tol) const { return param > tol && param < length - tol; }
  // Whether q's nearest point on the cut is not one of its ends; at once
  // when q is ahead of the first edge's start and behind the last edge's end.
  bool beside(const Vec2& q, double tol) const {
    const std::size_t n = cut.size();
    if ((q - cut[0]).dot((cut[1] - cut[0]).normalized()) > tol &&
        (cut[n - 1] - q).dot((cut[n - 1] - cut[n - 2]).normalized()) > tol)
      return true;
    return inside(closestOnPolyline(cut, q).param, tol);
  }

  // Sine of the cut's turn at point i (0 at its ends; > 0 turning left).
  double turn(std::size_t i) const {
    if (i == 0 || i + 1 >= cut.size()) return 0.0;
    const Vec2 u = cut[i] - cut[i - 1], v = cut[i + 1] - cut[i];
    return cross(u, v) / (u.norm() * v.norm());
  }
  // Whether the cut turns at pattern point q towards `side`, away from the
  // quads of `side`'s triangles (they lie across the cut): their side of the
  // cut is convex there.
  bool turnsAwayFromQuads(const Vec2& q, LipSide side, double tol) const {
    for (std::size_t i = 1; i + 1 < cut.size(); ++i) {
      if ((cut[i] - q).norm() > tol) continue;
      const double s = turn(i);
      return side == LipSide::Left ? s > kMinTurn : s < -kMinTurn;
    }
    return false;
  }
};

std::vector<Vec2> padded(const std::vector<Vec2>& line, const Vec2& backward, const Vec2& forward,
                         double reach) {
  std::vector<Vec2> out;
  out.reserve(line.size() + 2);
  out.push_back(line.front() - reach * backward);
  out.insert(out.end(), line.begin(), line.end());
  out.push_back(line.back() + reach * forward);
  return out;
}

void checkSegment(const TearSegment& s, std::size_t index, double halfTexel) {
  const auto fail = [&](const std::string& what) {
    throw std::invalid_argument("bakeTearAtlas: segment " + std::to_string(index) + ": " + what);
  };
  if (s.cut.size() < 2) fail("the cut needs two points");
  if (s.detail.size() < 2) fail("the detail path needs two points");
  for (const Vec2& p : s.cut)
    if (!p.allFinite()) fail("non-finite cut point");
  for (const Vec2& p : s.detail)
    if (!p.allFinite()) fail("non-finite detail path point");
  if ((s.detail.front() - s.cut.front()).norm() > halfTexel ||
      (s.detail.back() - s.cut.back()).norm() > halfTexel)
    fail("the detail path does not run between the cut's ends");
}

// The tears of the segments, in order of first appearance.
std::vector<Chain> chainsOf(const std::vector<TearSegment>& segments, double tol,
                            double halfTexel) {
  std::vector<Chain> chains;
  std::map<int, std::size_t> open;  // tear -> its last chain
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const TearSegment& s = segments[i];
    checkSegment(s, i, halfTexel);
    const auto it = open.find(s.tear);
    if (it != open.end() && (chains[it->second].cut.back() - s.cut.front()).norm() <= tol) {
      Chain& c = chains[it->second];
      c.cut.insert(c.cut.end(), s.cut.begin() + 1, s.cut.end());
      c.detail.insert(c.detail.end(), s.detail.begin() + 1, s.detail.end());
    } else {
      Chain c;
      c.tear = s.tear;
      c.cut = s.cut;
      c.detail = s.detail;
      chains.push_back(std::move(c));
      open[s.tear] = chains.size() - 1;
    }
  }
  return chains;
}

// The path for leftOfPath over `grid` alone: every run of segments that no
// pixel centre of the grid lies across, along the chord (leftOfPath's rays
// run across it), merged into one segment. Such segments are never crossed
// by a pixel's ray, nor is their merger (its ends are on the same side of
// the grid), and the ends and so the chord are kept: the same answer, in a
// fraction of the time on a long tear.
std::vector<Vec2> pathAcross(const std::vector<Vec2>& path, const PixelGrid& grid) {
  const Vec2 along = (path.back() - path.front()).normalized();
  const auto s = [&](const Vec2& p) { return (p - path.front()).dot(along); };
  const Vec2 size = grid.pixelSize * Vec2(grid.width, grid.height);
  double lo = kInf, hi = -kInf;
  for (const Vec2& c : {grid.origin, Vec2(grid.origin + Vec2(size.x(), 0.0)),
                        Vec2(grid.origin + Vec2(0.0, size.y())), Vec2(grid.origin + size)}) {
    lo = std::min(lo, s(c) - grid.pixelSize);
    hi = std::max(hi, s(c) + grid.pixelSize);
  }
  std::vector<Vec2> out{path.front()};
  std::size_t last = 0;  // index of out.back() in path
  for (std::size_t i = 1; i < path.size(); ++i) {
    const double a = s(path[i - 1]), b = s(path[i]);
    if (std::max(a, b) < lo || std::min(a, b) > hi) continue;
    if (last != i - 1) out.push_back(path[i - 1]);
    out.push_back(path[i]);
    last = i;
  }
  if (last != path.size() - 1) out.push_back(path.back());
  return out;
}

// Where a texel's centre is for a chain.
enum TexelSide : std::uint8_t {
  kRightOfPath = 0,
  kLeftOfPath = 1,
  kBeyondTheEnds = 2,  // its nearest point on the cut is one of the cut's ends
};

// The TexelSide of every texel of the shared grid for one chain:
// leftOfPath over kTile x kTile tiles made when first needed, so that every
// texel is decided once and all patches read the same answer.
class SideTiles {
 public:
  SideTiles(const Chain& chain, double texel, double tol)
      : chain_(chain), texel_(texel), tol_(tol) {}
  TexelSide at(long long i, long long j) {
    const long long ti = floorDiv(i, kTile), tj = floorDiv(j, kTile);
    auto [it, made] = tiles_.try_emplace({ti, tj});
    if (made) {
      PixelGrid g;
      g.origin =
          Vec2(static_cast<double>(ti * kTile) * texel_, static_cast<double>(tj * kTile) * texel_);
      g.pixelSize = texel_;
      g.width = g.height = static_cast<int>(kTile);
      it->second = leftOfPath(pathAcross(chain_.paddedDetail, g), g);
      for (int y = 0; y < g.height; ++y)
        for (int x = 0; x < g.width; ++x)
          if (!chain_.beside(g.centre(x, y), tol_))
            it->second[static_cast<std::size_t>(y * g.width + x)] = kBeyondTheEnds;
    }
    return static_cast<TexelSide>(
        it->second[static_cast<std::size_t>((j - tj * kTile) * kTile + (i - ti * kTile))]);
  }

 private:
  const Chain& chain_;
  double texel_;
  double tol_;
  std::map<std::pair<long long, long long>, std::vector<std::uint8_t>> tiles_;
};

// How one triangle borders the tears.
struct Bordering {
  std::array<int, 3> edgeChain{-1, -1, -1};            // chain whose cut edge k is on
  std::vector<std::pair<std::size_t, LipSide>> sides;  // each chain it borders, its side
  const LipSide* sideOf(std::size_t chain) const {
    for (const auto& [c, s] : sides)
      if (c == chain) return &s;
    return nullptr;
  }
};

// Shelf packing of the rects, tallest first: their places in the atlas.
void pack(TearAtlas& atlas) {
  std::vector<std::size_t> order(atlas.patches.size());
  long long area = 0;
  int widest = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    order[i] = i;
    const auto& r = atlas.patches[i].rect;
    area += static_cast<long long>(r.width) * r.height;
    widest = std::max(widest, r.width);
  }
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const auto &ra = atlas.patches[a].rect, &rb = atlas.patches[b].rect;
    if (ra.height != rb.height) return ra.height > rb.height;
    if (ra.width != rb.width) return ra.width > rb.width;
    return a < b;
  });
  const int width =
      std::max(widest, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(area)))));
  int x = 0, y = 0, shelf = 0;
  for (const std::size_t i : order) {
    auto& r = atlas.patches[i].rect;
    if (x + r.width > width) {
      y += shelf;
      x = 0;
      shelf = 0;
    }
    r.x = x;
    r.y = y;
    x += r.width;
    shelf = std::max(shelf, r.height);
  }
  atlas.width = order.empty() ? 0 : width;
  atlas.height = order.empty() ? 0 : y + shelf;
}

// The triangle's corners in the pattern.
std::array<Vec2, 3> cornersOf(const mesh::SheetMesh& mesh, int t) {
  const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
  return std::array<Vec2, 3>{mesh.pattern[static_cast<std::size_t>(tri[0])],
                             mesh.pattern[static_cast<std::size_t>(tri[1])],
                             mesh.pattern[static_cast<std::size_t>(tri[2])]};
}

// The lengths of a bake: below tol points coincide, lipTol a lip's distance to its cut,
// reach how far the padded paths run beyond the cut's ends.
struct AtlasScale {
  double tol = 0.0;
  double lipTol = 0.0;
  double reach = 0.0;
};

// The bake's lengths from the extent of the mesh's pattern and of the segments' paths.
AtlasScale atlasScale(const mesh::SheetMesh& mesh, const std::vector<TearSegment>& segments,
                      const TearAtlasParams& params) {
  const double texel = params.texelSize;
  Vec2 lo = Vec2::Constant(kInf), hi = -lo;
  for (const Vec2& p : mesh.pattern) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  for (const TearSegment& s : segments)
    for (const auto* line : {&s.cut, &s.detail})
      for (const Vec2& p : *line)
        if (p.allFinite()) {
          lo = lo.cwiseMin(p);
          hi = hi.cwiseMax(p);
        }
  const double extent =
      lo.allFinite() ? std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff()) : 0.0;
  AtlasScale scale;
  const double tol = 1e-9 * std::max(extent, 1e-3);
  scale.tol = tol;
  scale.lipTol = std::max(tol, params.lipTolerance);
  scale.reach = 4.0 * (lo.allFinite() ? (hi - lo).norm() : 0.0) + 1e3 * texel;
  return scale;
}

// thesis 3.3.4: each tear's joined cut and detail path with their length, support width and
// padded paths; tears that have not advanced dropped.
std::vector<Chain> tearChains(const std::vector<TearSegment>& segments, const AtlasScale& scale,
                              const TearAtlasParams& params) {
  const double texel = params.texelSize;
  const double tol = scale.tol;
  const double reach = scale.reach;
  std::vector<Chain> chains = chainsOf(segments, tol, 0.5 * texel);
  std::erase_if(chains, [&](Chain& c) {
    c.cut = withoutRepeats(c.cut, tol);
    c.detail = withoutRepeats(c.detail, tol);
    return c.cut.size() < 2;  // a tear that has not advanced cuts nothing
  });
  for (Chain& c : chains) {
    for (std::size_t i = 0; i + 1 < c.cut.size(); ++i) c.length += (c.cut[i + 1] - c.cut[i]).norm();
    double farthest = 0.0;
    for (std::size_t i = 0; i < c.detail.size(); ++i) {
      farthest = std::max(farthest, closestOnPolyline(c.cut, c.detail[i]).distance);
      if (i + 1 < c.detail.size())
        farthest = std::max(
            farthest, closestOnPolyline(c.cut, 0.5 * (c.detail[i] + c.detail[i + 1])).distance);
    }
    c.support = farthest + params.margin * texel;
    const Vec2 backward = (c.cut[1] - c.cut[0]).normalized();
    const Vec2 forward = (c.cut[c.cut.size() - 1] - c.cut[c.cut.size() - 2]).normalized();
    c.paddedCut = padded(c.cut, backward, forward, reach);
    c.paddedDetail = padded(c.detail, backward, forward, reach);
  }
  return chains;
}

// thesis 3.3.4: the lip triangles, with a boundary edge on a cut, and their side of it
// (counter-clockwise triangles: left of the edge walked from corner k to corner k + 1).
std::map<int, Bordering> lipTriangles(const mesh::SheetMesh& mesh, const std::vector<Chain>& chains,
                                      const AtlasScale& scale) {
  const double tol = scale.tol;
  const double lipTol = scale.lipTol;
  std::map<int, Bordering> borders;
  if (chains.empty()) return borders;
  for (const mesh::MeshEdge& e : mesh::buildEdges(mesh)) {
    if (e.interior()) continue;
    const int t = e.triangles[0];
    const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
    int k = 0;
    while (k < 3 && !((tri[static_cast<std::size_t>(k)] == e.v[0] ||
                       tri[static_cast<std::size_t>(k)] == e.v[1]) &&
                      (tri[static_cast<std::size_t>((k + 1) % 3)] == e.v[0] ||
                       tri[static_cast<std::size_t>((k + 1) % 3)] == e.v[1])))
      ++k;
    const auto p = cornersOf(mesh, t);
    const Vec2& a = p[static_cast<std::size_t>(k)];
    const Vec2& b = p[static_cast<std::size_t>((k + 1) % 3)];
    for (std::size_t c = 0; c < chains.size(); ++c) {
      const Closest ca = closestOnPolyline(chains[c].cut, a);
      const Closest cb = closestOnPolyline(chains[c].cut, b);
      if (ca.distance > lipTol || cb.distance > lipTol || std::abs(ca.param - cb.param) <= tol ||
          closestOnPolyline(chains[c].cut, 0.5 * (a + b)).distance > lipTol)
        continue;
      Bordering& bd = borders[t];
      const LipSide side = ca.param < cb.param ? LipSide::Left : LipSide::Right;
      if (const LipSide* known = bd.sideOf(c); known == nullptr)
        bd.sides.emplace_back(c, side);
      else if (*known != side)
        break;  // both sides of one cut: not a lip (cannot happen in a cut mesh)
      bd.edgeChain[static_cast<std::size_t>(k)] = static_cast<int>(c);
      break;
    }
  }
  return borders;
}

// thesis 3.3.4, Fig. 3.25: adds the other triangles the detail path may reach into, nearer to
// the cut than the support width, on the side of their points beside the cut.
void nearTriangles(const mesh::SheetMesh& mesh, const std::vector<Chain>& chains,
                   const AtlasScale& scale, double texel, std::map<int, Bordering>& borders) {
  const double tol = scale.tol;
  const double lipTol = scale.lipTol;
  for (std::size_t c = 0; c < chains.size(); ++c) {
    const Chain& ch = chains[c];
    Vec2 clo = Vec2::Constant(kInf), chi = -clo;
    for (const Vec2& q : ch.cut) {
      clo = clo.cwiseMin(q);
      chi = chi.cwiseMax(q);
    }
    clo.array() -= ch.support;
    chi.array() += ch.support;
    for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t) {
      const auto it = borders.find(t);
      if (it != borders.end() && it->second.sideOf(c) != nullptr) continue;
      const auto p = cornersOf(mesh, t);
      const Vec2 tlo = p[0].cwiseMin(p[1]).cwiseMin(p[2]), thi = p[0].cwiseMax(p[1]).cwiseMax(p[2]);
      if ((tlo.array() > chi.array()).any() || (thi.array() < clo.array()).any()) continue;
      if (!(triangleToPolyline(p, ch.cut) < ch.support)) continue;
      int left = 0, right = 0;
      for (const Vec2& q :
           {p[0], p[1], p[2], Vec2((p[0] + p[1] + p[2]) / 3.0), Vec2(0.5 * (p[0] + p[1])),
            Vec2(0.5 * (p[1] + p[2])), Vec2(0.5 * (p[2] + p[0]))}) {
        const Closest near = closestOnPolyline(ch.cut, q);
        if (near.distance <= lipTol || !ch.inside(near.param, tol)) continue;
        (leftOf(ch.paddedCut, q, texel) ? left : right) += 1;
      }
      if ((left > 0) == (right > 0)) continue;  // beyond the ends (or astride: cannot be)
      borders[t].sides.emplace_back(c, left > 0 ? LipSide::Left : LipSide::Right);
    }
  }
}

// thesis 3.3.4, Fig. 3.25: triangle t's patch outline, its lip edges extended by their
// support quads, with its tear and side (the first chain it has a lip edge on).
TearPatch patchOutline(const mesh::SheetMesh& mesh, const std::vector<Chain>& chains, int t,
                       const Bordering& bd, double lipTol) {
  TearPatch patch;
  patch.triangle = t;
  const auto* first = &bd.sides.front();
  for (const auto& s : bd.sides)
    if (std::find(bd.edgeChain.begin(), bd.edgeChain.end(), static_cast<int>(s.first)) !=
        bd.edgeChain.end()) {
      first = &s;
      break;
    }
  patch.tear = chains[first->first].tear;
  patch.side = first->second;
  const auto p = cornersOf(mesh, t);
  for (int k = 0; k < 3; ++k) {
    patch.polygon.push_back(p[static_cast<std::size_t>(k)]);
    const int c = bd.edgeChain[static_cast<std::size_t>(k)];
    if (c < 0) continue;
    patch.lipEdges = static_cast<std::uint8_t>(patch.lipEdges | (1u << k));
    const Chain& ch = chains[static_cast<std::size_t>(c)];
    const LipSide side = *bd.sideOf(static_cast<std::size_t>(c));
    const Vec2& a = p[static_cast<std::size_t>(k)];
    const Vec2& b = p[static_cast<std::size_t>((k + 1) % 3)];
    const Vec2 d = (b - a).normalized();
    const Vec2 out(d.y(), -d.x());  // away from the triangle
    const double w = ch.support;
    patch.polygon.push_back(a + w * out - (ch.turnsAwayFromQuads(a, side, lipTol) ? w : 0.0) * d);
    patch.polygon.push_back(b + w * out + (ch.turnsAwayFromQuads(b, side, lipTol) ? w : 0.0) * d);
  }
  return patch;
}

// thesis 3.3.4 (T_left, T_right): a patch's rect on the shared texel grid with a texel to
// spare around its outline, and its mask, paper on the patch's side of every path it borders.
std::vector<std::uint8_t> patchMask(TearPatch& patch, const Bordering& bd, double texel,
                                    std::vector<SideTiles>& sides, long long& texels) {
  Vec2 plo = Vec2::Constant(kInf), phi = -plo;
  for (const Vec2& q : patch.polygon) {
    plo = plo.cwiseMin(q);
    phi = phi.cwiseMax(q);
  }
  const long long x0 = static_cast<long long>(std::floor(plo.x() / texel)) - 1;
  const long long y0 = static_cast<long long>(std::floor(plo.y() / texel)) - 1;
  const long long x1 = static_cast<long long>(std::ceil(phi.x() / texel)) + 1;
  const long long y1 = static_cast<long long>(std::ceil(phi.y() / texel)) + 1;
  texels += (x1 - x0) * (y1 - y0);
  if (texels > kMaxAtlasTexels)
    throw std::length_error("bakeTearAtlas: the patches need over 2^28 texels");
  patch.rect.width = static_cast<int>(x1 - x0);
  patch.rect.height = static_cast<int>(y1 - y0);
  patch.rect.origin = Vec2(static_cast<double>(x0) * texel, static_cast<double>(y0) * texel);
  std::vector<std::uint8_t> m(static_cast<std::size_t>((x1 - x0) * (y1 - y0)));
  for (long long j = y0; j < y1; ++j)
    for (long long i = x0; i < x1; ++i) {
      // Paper on the patch's side of every path it borders; beyond a
      // tear's ends the paper is whole.
      bool paper = true;
      for (const auto& [c, side] : bd.sides) {
        const TexelSide at = sides[c].at(i, j);
        paper =
            paper && (at == kBeyondTheEnds || at == static_cast<TexelSide>(side == LipSide::Left));
      }
      m[static_cast<std::size_t>((j - y0) * (x1 - x0) + (i - x0))] = paper ? 255 : 0;
    }
  return m;
}

// thesis 3.3.4, Fig. 3.25: the patches of the bordering triangles into the atlas, and their
// masks.
std::vector<std::vector<std::uint8_t>> bakePatches(const mesh::SheetMesh& mesh,
                                                   const std::vector<Chain>& chains,
                                                   const std::map<int, Bordering>& borders,
                                                   const AtlasScale& scale, double texel,
                                                   TearAtlas& atlas) {
  std::vector<SideTiles> sides;
  sides.reserve(chains.size());
  for (const Chain& c : chains) sides.emplace_back(c, texel, scale.tol);
  std::vector<std::vector<std::uint8_t>> masks;
  long long texels = 0;
  for (const auto& [t, bd] : borders) {
    TearPatch patch = patchOutline(mesh, chains, t, bd, scale.lipTol);
    std::vector<std::uint8_t> m = patchMask(patch, bd, texel, sides, texels);
    atlas.patches.push_back(std::move(patch));
    masks.push_back(std::move(m));
  }
  return masks;
}

}  // namespace

TearAtlas bakeTearAtlas(const mesh::SheetMesh& mesh, const std::vector<TearSegment>& segments,
                        const TearAtlasParams& params) {
  if (!(params.texelSize > 0.0) || !std::isfinite(params.texelSize))
    throw std::invalid_argument("bakeTearAtlas: texel size must be finite and > 0");
  if (!(params.margin >= 0.0) || !std::isfinite(params.margin))
    throw std::invalid_argument("bakeTearAtlas: margin must be finite and >= 0");
  const double texel = params.texelSize;
  TearAtlas atlas;
  atlas.texelSize = texel;

  // Lengths below tol are coincident points (the cut's points are the
  // mesh's pattern positions).
  const AtlasScale scale = atlasScale(mesh, segments, params);
  const std::vector<Chain> chains = tearChains(segments, scale, params);

  // 1. Lip edges: boundary edges on a cut; the triangle's side is the cut's
  // side its interior is on (counter-clockwise triangles: left of the edge
  // walked from corner k to corner k + 1).
  std::map<int, Bordering> borders = lipTriangles(mesh, chains, scale);

  // 2. The other triangles the detail path may reach into: nearer to the cut
  // than the support width. Their side is that of their points beside the
  // cut (whose nearest point on it is not an end): a triangle at the tip may
  // reach around it to the other side, ahead of it.
  nearTriangles(mesh, chains, scale, texel, borders);

  // 3. The patches: outlines with their support quads (Fig. 3.25), rects on
  // the shared texel grid with a texel to spare around the outline (the
  // renderers' bilinear lookups stay inside), masks.
  const std::vector<std::vector<std::uint8_t>> masks =
      bakePatches(mesh, chains, borders, scale, texel, atlas);

  // 4. One atlas.
  pack(atlas);
  if (static_cast<long long>(atlas.width) * atlas.height > kMaxAtlasTexels)
    throw std::length_error("bakeTearAtlas: the atlas would exceed 2^28 texels");
  atlas.mask.assign(static_cast<std::size_t>(atlas.width) * static_cast<std::size_t>(atlas.height),
                    0);
  for (std::size_t i = 0; i < atlas.patches.size(); ++i) {
    const auto& r = atlas.patches[i].rect;
    for (int j = 0; j < r.height; ++j)
      std::copy_n(masks[i].begin() + static_cast<std::ptrdiff_t>(j) * r.width, r.width,
                  atlas.mask.begin() + (static_cast<std::ptrdiff_t>(r.y + j) * atlas.width + r.x));
  }
  return atlas;
}

}  // namespace crumple::tear
