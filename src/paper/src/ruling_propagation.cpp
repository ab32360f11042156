// Compressed flat regions become curved regions (paper Sec. 5.1-5.2 and
// Appendices A-B; thesis 2.4.2-2.4.3): the compression treatment, which
// finds the strip (strip.hpp) and its singular vertex
// (singular_insertion.hpp).
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <sstream>

#include "crumple/core/index.hpp"
#include "crumple/paper/compression.hpp"
#include "crumple/paper/geometric_step.hpp"
#include "region_tools.hpp"
#include "singular_insertion.hpp"
#include "strip.hpp"

namespace crumple::paper {

namespace {

using detail::addConeFans;
using detail::addRegion;
using detail::addTriangleCCW;
using detail::Border;
using detail::crowded;
using detail::EdgeMap;
using detail::edgeMap;
using detail::findBorder;
using detail::insertSingularInCurved;
using detail::normalDeviate;
using detail::Pencil;
using detail::placeSingularOnBorder;
using detail::regionLoop;
using detail::remeshStrip;
using detail::StripResult;
using detail::triangulatePolygon;
using detail::vertexInCell;

// Compression of an S_G triangle against its pattern (thesis 2.4.2).
TriangleCompression faceCompression(const GeometricMesh& g, const GeometricFace& face) {
  std::array<Vec2, 3> pattern;
  std::array<Vec3, 3> position;
  for (std::size_t k = 0; k < 3; ++k) {
    pattern[k] = g.vertices[idx(face.v[k])].pattern;
    position[k] = g.vertices[idx(face.v[k])].position;
  }
  return analyzeCompression(pattern, position);
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

// Orients the rulings of a curved region so that every .a lies on the same
// boundary chain as rulings[0].a.
std::vector<Ruling> orientedRulings(const GeometricMesh& g, std::vector<Ruling> rulings) {
  const auto P = [&](int v) -> const Vec2& { return g.vertices[idx(v)].pattern; };
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
    if (!mayRemesh(static_cast<int>(f))) settled[idx(g.faces[f].region)] = 0;
  }
  for (std::size_t r = 0; r < regionCount; ++r) {
    if (g.regions[r].type != mesh::RegionType::Curved || g.regions[r].apex >= 0) continue;
    if (!settled[r]) continue;
    if (stats.singularInserted >= params.maxSingularPerFrame) break;
    if (g.regions[r].rulings.size() < 2) continue;
    const std::vector<Ruling> rulings = orientedRulings(g, g.regions[r].rulings);
    const auto P = [&](int v) -> const Vec2& { return g.vertices[idx(v)].pattern; };
    const auto X = [&](int v) -> const Vec3& { return g.vertices[idx(v)].position; };
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
        g.regions[idx(back)].rulings.assign(rulings.begin(),
                                            rulings.begin() + static_cast<std::ptrdiff_t>(lo) + 1);
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
    const auto& tri = sp.triangles[idx(t)];
    const Vec3& a = sp.positions[idx(tri[0])];
    return Vec3((sp.positions[idx(tri[1])] - a).cross(sp.positions[idx(tri[2])] - a).normalized());
  };
  for (const mesh::MeshEdge& e : edges) {
    if (!e.interior()) continue;
    const Vec2& pa = sp.pattern[idx(e.v[0])];
    const Vec2& pb = sp.pattern[idx(e.v[1])];
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
      if (g.faces[idx(faces[0])].region != static_cast<int>(r) ||
          g.faces[idx(faces[1])].region != static_cast<int>(r)) {
        continue;
      }
      const double angle = dihedralAngle(g, faces[0], faces[1]);
      if (angle > best) {
        best = angle;
        fold = key;
      }
    }
    if (fold.first < 0) continue;
    const Vec2 a = g.vertices[idx(fold.first)].pattern;
    const Vec2 b = g.vertices[idx(fold.second)].pattern;
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
            g.regions[idx(g.faces[idx(across)].region)].type != mesh::RegionType::Curved)
          continue;
        const Vec2 d = g.vertices[idx(loop->next(k))].pattern - g.vertices[idx(loop->v[k])].pattern;
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

namespace {

// The state the compression treatment of one step shares between regions.
struct CompressionStep {
  GeometricMesh& g;
  const CrumpleParams& params;
  const BoundaryPosition& boundary;
  const CounterRng& rng;
  std::uint64_t& drawIndex;
  GeometricStepStats& stats;
  detail::EdgeMapCache& edgeCache;
  std::vector<char>& declined;  // per region: waits for a later step
};

// thesis 2.4.2: the regions by their most compressed flat triangle, most compressed first.
std::vector<std::pair<double, std::size_t>> regionsByCompression(const GeometricMesh& g) {
  const std::size_t regionCount = g.regions.size();
  std::vector<std::pair<double, std::size_t>> order;
  std::vector<double> worst(regionCount, 0.0);
  for (const GeometricFace& face : g.faces) {
    if (face.size() != 3 || g.regions[idx(face.region)].type != mesh::RegionType::Flat) {
      continue;
    }
    double& w = worst[idx(face.region)];
    w = std::max(w, faceCompression(g, face).ratio());
  }
  for (std::size_t r = 0; r < regionCount; ++r) order.emplace_back(-worst[r], r);
  std::sort(order.begin(), order.end());
  return order;
}

// paper Sec. 5.1 (a): region r's most compressed triangle (-1: none) and its compression.
int mostCompressedTriangle(const GeometricMesh& g, std::size_t r, TriangleCompression& best) {
  int tcomp = -1;
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
  return tcomp;
}

// paper Sec. 5.2, Appendix B Fig. 24 b: the existing d-cone apex each strip border ends at;
// false when a border is a ruling of a cone whose apex it does not hold.
bool existingApices(const GeometricMesh& g, const detail::Loop& loop,
                    const Border* const (&borders)[2], int (&existingApex)[2]) {
  bool feasible = true;
  for (int side = 0; side < 2; ++side) {
    const Border& b = *borders[side];
    if (b.kind == Border::Kind::FlatFlat) {
      // A border edge ending at a singular vertex (e.g. a crease between
      // two): the rulings are attracted by that existing d-cone apex
      // (Appendix B, Fig. 24 b) instead of a new one beside it.
      const int ea = loop.v[idx(b.loopEdge)];
      const int eb = loop.next(idx(b.loopEdge));
      const bool sa = g.vertices[idx(ea)].singular;
      const bool sb = g.vertices[idx(eb)].singular;
      if (sa || sb) {
        const double da = (g.vertices[idx(ea)].pattern - b.hit).norm();
        const double db = (g.vertices[idx(eb)].pattern - b.hit).norm();
        existingApex[side] = sa && (!sb || da <= db) ? ea : eb;
      }
      continue;
    }
    if (b.kind != Border::Kind::Curved) continue;
    const int across = loop.across[idx(b.loopEdge)];
    const int apex = g.regions[idx(g.faces[idx(across)].region)].apex;
    if (apex < 0) continue;
    const int ea = loop.v[idx(b.loopEdge)];
    const int eb = loop.next(idx(b.loopEdge));
    if (apex == ea || apex == eb) {
      existingApex[side] = apex;
    } else {
      feasible = false;
    }
  }
  return feasible;
}

// paper Sec. 5.2 (thesis 2.4.3): a singular vertex on each constrained border of the strip
// that has no existing apex; singular[side] stays -1 where the insertion fails.
void insertBorderSingulars(CompressionStep& step, std::size_t r, const Vec2& centroid,
                           const Vec2& vPerp, double tol, const Border* const (&borders)[2],
                           const int (&existingApex)[2], int (&singular)[2]) {
  GeometricMesh& g = step.g;
  const auto constrained = [](const Border& b) { return b.kind != Border::Kind::Free; };
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
    const Border b = findBorder(g, *l2, centroid, side == 0 ? Vec2(-vPerp) : vPerp, tol);
    if (b.kind == Border::Kind::Curved) {
      singular[side] = insertSingularInCurved(g, static_cast<int>(r), *l2, b, step.params, step.rng,
                                              step.drawIndex);
      if (singular[side] < 0) break;
    } else {
      singular[side] = placeSingularOnBorder(g, *l2, b, step.params, step.rng, step.drawIndex);
      if (singular[side] < 0) break;
    }
    ++step.stats.singularInserted;
  }
}

// paper Appendix B, Fig. 24: region r remeshed as a crease between two singular vertices,
// a cone of rulings from one, or a strip of parallel rulings along vPerp.
StripResult remeshCompressedStrip(CompressionStep& step, std::size_t r, const Vec2& centroid,
                                  const Vec2& vPerp, double tol, const Border* const (&borders)[2],
                                  const int (&existingApex)[2], const int (&singular)[2]) {
  GeometricMesh& g = step.g;
  GeometricStepStats& stats = step.stats;
  StripResult result;
  // Rulings fanning from the apex on `side`: aimed where the strip
  // meets the other border (free there by construction), else through
  // the compressed triangle.
  const auto coneFrom = [&](int apex, int side) {
    Pencil pencil;
    pencil.apex = apex;
    const Vec2 s = g.vertices[idx(apex)].pattern;
    pencil.origin = s;
    StripResult out{false, "no pencil"};
    for (const Vec2& target : {borders[1 - side]->hit, centroid}) {
      if (!((target - s).norm() > tol)) continue;
      pencil.dir = (target - s).normalized();
      out = remeshStrip(g, static_cast<int>(r), pencil, step.params, step.boundary);
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
      pencil.dir = vPerp;
      result = remeshStrip(g, static_cast<int>(r), pencil, step.params, step.boundary);
    }
    if (result.done) ++stats.curvedCreated;
  }
  return result;
}

// The cuts of a strip made (its triangle's centroid, its singular vertices) for the cooldown.
void recordStrip(const GeometricMesh& g, const Vec2& centroid, const int (&singular)[2],
                 std::size_t singularBefore, std::ostringstream& why, GeometricStepStats& stats) {
  stats.cuts.push_back(centroid);
  if (stats.singularInserted > static_cast<int>(singularBefore)) {
    why << "strip with " << (stats.singularInserted - static_cast<int>(singularBefore))
        << " new singular vertices";
    stats.notes.push_back(why.str());
  }
  for (int sv : singular) {
    if (inRange(g.vertices, sv)) {
      stats.cuts.push_back(g.vertices[idx(sv)].pattern);
    }
  }
}

// paper Sec. 5.1-5.2, Appendices A-B: flat region r's most compressed triangle made a strip
// of rulings, as a transaction; whether S_G changed.
bool treatCompressedRegion(CompressionStep& step, std::size_t r) {
  GeometricMesh& g = step.g;
  const CrumpleParams& params = step.params;
  GeometricStepStats& stats = step.stats;
  std::vector<char>& declined = step.declined;
  // (a) the most compressed triangle and its direction of minimal compression.
  TriangleCompression best;
  const int tcomp = mostCompressedTriangle(g, r, best);
  if (tcomp < 0) return false;
  stats.maxCompression = std::max(stats.maxCompression, best.ratio());
  if (!(best.ratio() > params.epsC)) return false;
  const GeometricFace tri = g.faces[idx(tcomp)];
  Vec2 centroid = Vec2::Zero();
  for (int k = 0; k < 3; ++k) centroid += g.vertices[idx(tri.v[k])].pattern / 3.0;
  // Each remeshing is a transaction: S_G is checked afterwards and
  // restored (the region declined for this step) when it would break an
  // invariant, so one bad case cannot corrupt the sheet.
  const GeometricMesh before = g;
  const std::size_t singularBefore = idx(stats.singularInserted);
  const auto rollback = [&](const std::string& why) {
    g = before;
    stats.singularInserted = static_cast<int>(singularBefore);
    stats.notes.push_back("flat region " + std::to_string(r) + ": remeshing undone (" + why + ")");
    declined.resize(g.regions.size(), 0);
    declined[r] = 1;
  };
  try {
    // (b) the borders of the strip along +-v_perp (Appendix A, Fig. 6).
    const EdgeMap& edges = step.edgeCache.of(g);
    const auto loop = regionLoop(g, static_cast<int>(r), edges);
    if (!loop) {
      declined[r] = 1;
      return false;
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
      return false;
    }
    // (c) remesh: c1 with both borders free, c2 with singular vertices.
    const auto constrained = [](const Border& b) { return b.kind != Border::Kind::Free; };
    const Border* const borders[2] = {&bwd, &fwd};
    // Singular vertices on constrained borders (paper Sec. 5.2). A border
    // ruling of a curved region gets its singular vertex on the ruling
    // itself (we do not yet continue into the curved region to e_sing).
    // A border ruling of a cone from a singular vertex s: the strip's
    // rulings are attracted by s itself (Appendix B, Fig. 24 b), no new
    // singular vertex is needed.
    int singular[2] = {-1, -1};
    int existingApex[2] = {-1, -1};
    if (!existingApices(g, *loop, borders, existingApex)) {
      why << "the strip meets a conical curved region";
      stats.notes.push_back(why.str());
      declined[r] = 1;
      return false;
    }
    const int needed = (constrained(bwd) && existingApex[0] < 0 ? 1 : 0) +
                       (constrained(fwd) && existingApex[1] < 0 ? 1 : 0);
    if (needed > 0 && stats.singularInserted + needed > params.maxSingularPerFrame) {
      why << "singular-vertex budget of this step used up";
      stats.notes.push_back(why.str());
      declined[r] = 1;
      return false;
    }
    insertBorderSingulars(step, r, centroid, best.vPerp, tol, borders, existingApex, singular);
    if ((constrained(bwd) && singular[0] < 0) || (constrained(fwd) && singular[1] < 0)) {
      // The other side's singular vertex may be in S_G already: undone
      // with the rest, as a failed remeshing is.
      why << "the strip meets a conical curved region";
      rollback(why.str());
      return false;
    }
    const StripResult result =
        remeshCompressedStrip(step, r, centroid, best.vPerp, tol, borders, existingApex, singular);
    if (!result.done) {
      // Undo the singular vertices placed for it too: a singular vertex
      // without its cone would be damage without a cause.
      why << (result.note.empty() ? std::string("the crease could not split the region")
                                  : result.note);
      rollback(why.str());
      return false;
    }
    if (const std::string problem = validate(g); !problem.empty()) {
      rollback(problem);
      return false;
    }
    recordStrip(g, centroid, singular, singularBefore, why, stats);
    return true;
  } catch (const std::exception& e) {
    // CDT refusing a polygon, a degenerate placement...: undo, go on.
    rollback(e.what());
    return false;
  }
}

}  // namespace

// paper Sec. 5.1-5.2 and Appendices A-B; thesis 2.4.2-2.4.3.
void treatCompression(GeometricMesh& g, const CrumpleParams& params,
                      const BoundaryPosition& boundary, const CounterRng& rng,
                      std::uint64_t& drawIndex, GeometricStepStats& stats,
                      const FaceFilter& mayRemesh) {
  detail::EdgeMapCache edgeCache;
  // Regions holding a face that may not be remeshed yet wait (cooldown).
  std::vector<char> declined(g.regions.size(), 0);
  for (std::size_t f = 0; f < g.faces.size() && mayRemesh; ++f) {
    if (!mayRemesh(static_cast<int>(f))) declined[idx(g.faces[f].region)] = 1;
  }
  CompressionStep step{g, params, boundary, rng, drawIndex, stats, edgeCache, declined};
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
    const std::vector<std::pair<double, std::size_t>> order = regionsByCompression(g);
    for (const auto& entry : order) {
      const std::size_t r = entry.second;
      if (declined[r] || g.regions[r].type != mesh::RegionType::Flat) continue;
      if (treatCompressedRegion(step, r)) changed = true;
    }
    if (!changed) break;
  }
  compact(g);
}

}  // namespace crumple::paper
