#include "crumple/paper/cone_fit.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

#include "cone_runs.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/geometry2d.hpp"
#include "crumple/core/index.hpp"
#include "crumple/paper/compression.hpp"

namespace crumple::paper {

namespace {

constexpr const char* kStage = "cones";

// An eigenvalue of sum u_i u_i^T below this fraction of its trace counts as
// zero: the minimizer of eq. (2) is then not unique.
constexpr double kNullEigenvalue = 1e-12;
// |xi| below this (apex farther than 1e9 L from the centre): apex at infinity.
constexpr double kInfinityXi = 1e-9;
// Contributions whose distances differ by less than this (m) are tied.
constexpr double kTieDistance = 1e-9;

void requireFinite(const Vec3& v, const char* what) {
  if (!v.allFinite()) throw NumericalError(kStage, std::string(what) + " is not finite");
}
void requireFinite(const Vec2& v, const char* what) {
  if (!v.allFinite()) throw NumericalError(kStage, std::string(what) + " is not finite");
}
void requireFinite(double v, const char* what) {
  if (!std::isfinite(v)) throw NumericalError(kStage, std::string(what) + " is not finite");
}

Vec2 rotate(const Vec2& v, double angle) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

}  // namespace

// ---------------------------------------------------------------------------
// paper Sec. 6.2, eq. (2): apex of the generalized cone best fitting the
// tangent planes, in the projective (Blaschke cylinder) form of the header.
ApexFit fitApex(std::span<const RulingPlane> planes, const FitFrame& frame) {
  if (planes.empty()) throw std::invalid_argument("fitApex: no ruling planes");
  if (!(frame.length > 0.0) || !std::isfinite(frame.length)) {
    throw std::invalid_argument("fitApex: the frame length must be positive and finite");
  }
  requireFinite(frame.centre, "fit frame centre");
  const double L = frame.length;
  const Vec3& c = frame.centre;
  const std::size_t n = planes.size();

  // u_i = (n_i, (w_i + n_i . c) / L): the plane on the Blaschke cylinder,
  // relative to the centre and scaled so all four coordinates are O(1).
  std::vector<Vec4> u(n);
  Mat4 m = Mat4::Zero();
  Vec3 preferred = Vec3::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const RulingPlane& p = planes[i];
    requireFinite(p.normal, "ruling plane normal");
    requireFinite(p.w, "ruling plane offset");
    const double len = p.normal.norm();
    if (!(len > 1e-300)) throw NumericalError(kStage, "ruling plane with a zero normal");
    const Vec3 normal = p.normal / len;
    const double w = p.w / len;
    u[i] << normal, (w + normal.dot(c)) / L;
    m += u[i] * u[i].transpose();
    if (p.direction.allFinite() && p.direction.norm() > 0.0) {
      const Vec3 d = p.direction.normalized();
      preferred += preferred.dot(d) < 0.0 ? Vec3(-d) : d;
    }
  }
  if (!m.allFinite()) throw NumericalError(kStage, "apex fit matrix is not finite");

  Eigen::SelfAdjointEigenSolver<Mat4> eig(m);
  if (eig.info() != Eigen::Success)
    throw NumericalError(kStage, "apex fit eigen-decomposition failed");
  const Vec4 lambda = eig.eigenvalues();  // ascending
  const Mat4 vectors = eig.eigenvectors();
  const double nullTol = kNullEigenvalue * std::max(m.trace(), 1.0);
  int nullDim = 1;
  while (nullDim < 4 && lambda(nullDim) <= nullTol) ++nullDim;

  ApexFit fit;
  Vec4 x = vectors.col(0);
  if (nullDim > 1) {
    // Degenerate (fewer than three independent planes): choose, among the
    // exact minimizers, the point at infinity closest to the mean ruling
    // direction (see RulingPlane::direction).
    fit.degenerate = true;
    const Eigen::MatrixXd basis = vectors.leftCols(nullDim);
    Eigen::MatrixXd infinite;  // orthonormal basis of the minimizers with xi = 0
    const Eigen::RowVectorXd xiRow = basis.row(3);
    if (xiRow.norm() < 1e-12) {
      infinite = basis;
    } else {
      Eigen::HouseholderQR<Eigen::MatrixXd> qr(xiRow.transpose());
      const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(nullDim, nullDim);
      infinite = basis * q.rightCols(nullDim - 1);
    }
    Vec4 target = Vec4::Zero();
    target.head<3>() = preferred;
    Eigen::VectorXd proj = infinite * (infinite.transpose() * target);
    if (proj.norm() < 1e-9 * std::max(preferred.norm(), 1e-300) || preferred.norm() == 0.0) {
      proj = infinite.col(0);
    }
    x = proj.normalized();
  }

  const double xi = x(3);
  if (std::abs(xi) <= kInfinityXi) {
    fit.atInfinity = true;
    x(3) = 0.0;
    x.normalize();
    Vec3 d = x.head<3>();
    if (preferred.norm() > 0.0) {
      if (d.dot(preferred) < 0.0) d = -d;
    } else {
      Eigen::Index k = 0;
      d.cwiseAbs().maxCoeff(&k);
      if (d(k) < 0.0) d = -d;
    }
    fit.direction = d;
    fit.apex = Vec3::Zero();
  } else {
    fit.apex = c + L * x.head<3>() / xi;
    const Vec3 away = fit.apex - c;
    fit.direction = away.norm() > 0.0
                        ? Vec3(away.normalized())
                        : (preferred.norm() > 0.0 ? Vec3(preferred.normalized()) : Vec3::UnitX());
  }

  // e_i = (L u_i . X)^2 with |X| = 1 (header: the plane-apex distance scaled
  // by L / sqrt(L^2 + |a - c|^2), or L |n_i . d| at infinity).
  fit.contributions.resize(n);
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = L * u[i].dot(x);
    fit.contributions[i] = r * r;
    sum += r * r;
  }
  fit.sumSquares = sum;
  fit.rms = std::sqrt(sum / static_cast<double>(n));
  fit.maxDistance =
      std::sqrt(*std::max_element(fit.contributions.begin(), fit.contributions.end()));
  requireFinite(fit.apex, "fitted apex");
  requireFinite(fit.direction, "fitted apex direction");
  requireFinite(fit.rms, "apex fit error");
  requireFinite(fit.maxDistance, "apex fit error");
  return fit;
}

namespace {

// thesis Algorithm 3 (segmentation_rec) on rulings front..back.
void segmentRange(std::span<const RulingPlane> planes, double tolerance, const FitFrame& frame,
                  bool shareBorders, int front, int back, std::vector<ConeSegment>& out) {
  const int minSize = shareBorders ? 2 : 1;
  int f = front;
  int b = back;
  const auto fitRange = [&] { return fitApex(planes.subspan(idx(f), idx(b - f + 1)), frame); };
  ApexFit fit = fitRange();
  while (fit.maxDistance > tolerance && b - f + 1 > minSize) {
    // Drop the end ruling whose tangent plane is farther from the apex.
    if (fit.contributions.front() > fit.contributions.back()) {
      ++f;
    } else {
      --b;
    }
    fit = fitRange();
  }
  if (shareBorders) {
    if (f != front) segmentRange(planes, tolerance, frame, shareBorders, front, f, out);
  } else if (f > front) {
    segmentRange(planes, tolerance, frame, shareBorders, front, f - 1, out);
  }
  out.push_back({f, b, std::move(fit)});
  if (shareBorders) {
    if (b != back) segmentRange(planes, tolerance, frame, shareBorders, b, back, out);
  } else if (b < back) {
    segmentRange(planes, tolerance, frame, shareBorders, b + 1, back, out);
  }
}

}  // namespace

// paper Sec. 6.2 "Iterative segmentation algorithm"; thesis Algorithms 2-3.
std::vector<ConeSegment> segmentRulings(std::span<const RulingPlane> planes, double tolerance,
                                        const FitFrame& frame, bool shareBorders) {
  if (planes.empty()) throw std::invalid_argument("segmentRulings: no ruling planes");
  if (!(tolerance >= 0.0)) throw std::invalid_argument("segmentRulings: negative tolerance");
  std::vector<ConeSegment> out;
  segmentRange(planes, tolerance, frame, shareBorders, 0, static_cast<int>(planes.size()) - 1, out);
  return out;
}

// paper Sec. 6.2 / thesis 2.5.2: a^proj, orthogonal projection of the apex on
// the ruling, carried into the pattern by its coordinate along the ruling.
Vec2 apexInPattern(const Vec3& apex, const RulingGeometry& ruling) {
  requireFinite(apex, "apex");
  const Vec3 d3 = ruling.b3 - ruling.a3;
  const Vec2 d2 = ruling.b2 - ruling.a2;
  const double l3 = d3.norm();
  const double l2 = d2.norm();
  if (!(l3 > 0.0) || !(l2 > 0.0))
    throw NumericalError(kStage, "apex mapped through a ruling of zero length");
  const double t = (apex - ruling.a3).dot(d3 / l3);
  const Vec2 out = ruling.a2 + t * (d2 / l2);
  requireFinite(out, "pattern apex");
  return out;
}

// paper Sec. 6.2 ("local coordinate within the ruling frame"), extended:
// both in-plane coordinates of the apex in the frame (u, n x u) of the
// tangent plane, carried by the local isometry of the plane onto the pattern.
Vec2 apexInPatternInPlane(const Vec3& apex, const RulingGeometry& ruling) {
  requireFinite(apex, "apex");
  const Vec3 d3 = ruling.b3 - ruling.a3;
  const Vec2 d2 = ruling.b2 - ruling.a2;
  if (!(d3.norm() > 0.0) || !(d2.norm() > 0.0)) {
    throw NumericalError(kStage, "apex mapped through a ruling of zero length");
  }
  const double nlen = ruling.normal.norm();
  if (!(nlen > 0.0)) return apexInPattern(apex, ruling);
  const Vec3 n = ruling.normal / nlen;
  Vec3 u = d3 - d3.dot(n) * n;
  if (!(u.norm() > 1e-12 * d3.norm())) return apexInPattern(apex, ruling);
  u.normalize();
  const Vec3 v = n.cross(u);
  const Vec2 ubar = d2.normalized();
  const Vec2 vbar(-ubar.y(), ubar.x());
  const Vec3 r = apex - ruling.a3;
  const Vec2 out = ruling.a2 + r.dot(u) * ubar + r.dot(v) * vbar;
  requireFinite(out, "pattern apex");
  return out;
}

// paper Sec. 6.2 (apex at infinity, Fig. 15 a_4): the cylinder direction
// carried into the pattern by its angle to the ruling in the tangent plane.
Vec2 directionInPattern(const Vec3& direction, const RulingGeometry& ruling) {
  requireFinite(direction, "apex direction");
  const Vec3 d3 = ruling.b3 - ruling.a3;
  const Vec2 d2 = ruling.b2 - ruling.a2;
  if (!(d3.norm() > 0.0) || !(d2.norm() > 0.0)) {
    throw NumericalError(kStage, "direction mapped through a ruling of zero length");
  }
  const Vec2 ubar = d2.normalized();
  const double nlen = ruling.normal.norm();
  if (!(nlen > 0.0)) return ubar;
  const Vec3 n = ruling.normal / nlen;
  const Vec3 dp = direction - direction.dot(n) * n;
  Vec3 up = d3 - d3.dot(n) * n;
  if (!(dp.norm() > 1e-12 * direction.norm()) || !(up.norm() > 1e-12 * d3.norm())) return ubar;
  up.normalize();
  const Vec3 v = n.cross(up);
  const double phi = std::atan2(dp.dot(v), dp.dot(up));
  Vec2 out = rotate(ubar, phi);
  requireFinite(out, "pattern apex direction");
  return out.normalized();
}

// paper Sec. 6.2: the ruling r_j of minimal contribution e_j carries the apex.
PatternApex patternApex(const ConeSegment& segment, std::span<const RulingGeometry> rulings,
                        ApexMapping mapping) {
  if (segment.first < 0 || segment.last < segment.first || !inRange(rulings, segment.last) ||
      segment.fit.contributions.size() != idx(segment.last - segment.first + 1)) {
    throw std::invalid_argument("patternApex: segment does not match the rulings");
  }
  const std::vector<double>& e = segment.fit.contributions;
  const double eMin = *std::min_element(e.begin(), e.end());
  // Rulings tied with the minimum (plane distances within kTieDistance,
  // e.g. exact data where every e_j is rounding noise): the one whose 3D
  // line passes closest to the apex (most parallel to it at infinity).
  const auto offLine = [&](std::size_t i) {
    const RulingGeometry& r = rulings[idx(segment.first) + i];
    const Vec3 u = (r.b3 - r.a3).normalized();
    if (segment.fit.atInfinity) return u.cross(segment.fit.direction).norm();
    const Vec3 d = segment.fit.apex - r.a3;
    return (d - d.dot(u) * u).norm();
  };
  std::size_t best = e.size();
  double bestOff = 0.0;
  for (std::size_t i = 0; i < e.size(); ++i) {
    if (std::sqrt(e[i]) > std::sqrt(eMin) + kTieDistance) continue;
    const double off = offLine(i);
    if (best == e.size() || off < bestOff) {
      best = i;
      bestOff = off;
    }
  }
  PatternApex out;
  out.ruling = segment.first + static_cast<int>(best);
  const RulingGeometry& r = rulings[idx(out.ruling)];
  out.atInfinity = segment.fit.atInfinity;
  if (out.atInfinity) {
    out.direction = directionInPattern(segment.fit.direction, r);
  } else {
    out.point = mapping == ApexMapping::AlongRuling ? apexInPattern(segment.fit.apex, r)
                                                    : apexInPatternInPlane(segment.fit.apex, r);
    out.direction = (r.b2 - r.a2).normalized();
  }
  return out;
}
// ---------------------------------------------------------------------------
// Remeshing a curved region into generalized cones (paper Sec. 6.2 last
// paragraphs, Fig. 15; thesis 2.5.2, Fig. 2.19): the runs in cone_runs.cpp.

namespace {

using cones::Chain;
using cones::ChainRuling;
using cones::polygonNormal;
using cones::RegionContext;
using cones::RunRefitter;
using cones::RunResult;
using cones::vertexS;

// Pattern polygon (deduplicated) of the face between two rulings given by
// their pattern endpoints; checks it is strictly convex with orientation
// `sign`.
bool convexFace(const std::array<Vec2, 4>& poly, const std::array<bool, 4>& skip, double sign,
                double minArea) {
  std::vector<Vec2> v;
  for (std::size_t k = 0; k < 4; ++k) {
    if (!skip[k]) v.push_back(poly[k]);
  }
  if (v.size() < 3) return false;
  double area = 0.0;
  for (std::size_t k = 0; k < v.size(); ++k) area += cross2(v[k], v[(k + 1) % v.size()]);
  if (!(sign * 0.5 * area > minArea)) return false;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const Vec2& a = v[k];
    const Vec2& b = v[(k + 1) % v.size()];
    const Vec2& c = v[(k + 2) % v.size()];
    if (!(sign * cross2(b - a, c - b) > 0.0)) return false;
  }
  return true;
}

// paper Sec. 6.2, Fig. 15: orients the rulings so that every .a is on the side of r_0.a.
void orientRulings(const GeometricMesh& g, std::vector<Ruling>& rulings) {
  for (std::size_t k = 1; k < rulings.size(); ++k) {
    const Ruling& p = rulings[k - 1];
    Ruling& r = rulings[k];
    bool flip = false;
    if (r.a == p.a || r.b == p.b) {
      flip = false;
    } else if (r.a == p.b || r.b == p.a) {
      flip = true;
    } else {
      const auto P = [&](int v) -> const Vec2& { return g.vertices[idx(v)].pattern; };
      flip = (P(r.b) - P(p.a)).norm() + (P(r.a) - P(p.b)).norm() <
             (P(r.a) - P(p.a)).norm() + (P(r.b) - P(p.b)).norm();
    }
    if (flip) std::swap(r.a, r.b);
  }
}

// thesis 2.5.2: marks the vertices the resampling keeps; returns the region's faces by vertex set.
std::map<std::vector<int>, int> markFixedVertices(const GeometricMesh& g, int region,
                                                  RegionContext& ctx) {
  ctx.fixedVertex.assign(g.vertices.size(), 0);
  for (std::size_t v = 0; v < g.vertices.size(); ++v) {
    const GeometricVertex& gv = g.vertices[v];
    ctx.fixedVertex[v] = gv.handle || gv.singular || gv.corner;
  }
  std::map<std::vector<int>, int> faceOf;  // sorted vertex set -> face of this region
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    const GeometricFace& face = g.faces[f];
    if (face.region != region) {
      for (int k = 0; k < face.size(); ++k) ctx.fixedVertex[idx(face.v[k])] = 1;
      continue;
    }
    std::vector<int> key(face.v.begin(), face.v.begin() + face.size());
    std::sort(key.begin(), key.end());
    faceOf[key] = static_cast<int>(f);
  }
  return faceOf;
}

// paper Sec. 6.2: each ruling's tangent-plane normal; false when one has no tangent plane.
bool setRulingNormals(const GeometricMesh& g, const std::map<std::vector<int>, int>& faceOf,
                      RegionContext& ctx) {
  const std::size_t nr = ctx.rulings.size();
  std::vector<Vec3> faceNormals(nr - 1);
  for (std::size_t k = 0; k + 1 < nr; ++k) {
    const Ruling& r0 = ctx.rulings[k];
    const Ruling& r1 = ctx.rulings[k + 1];
    std::vector<int> key{r0.a, r0.b, r1.a, r1.b};
    std::sort(key.begin(), key.end());
    key.erase(std::unique(key.begin(), key.end()), key.end());
    const auto it = faceOf.find(key);
    faceNormals[k] = it != faceOf.end() ? faceNormal(g, it->second) : polygonNormal(g, r0, r1);
  }
  ctx.rulingNormal.resize(nr);
  for (std::size_t k = 0; k < nr; ++k) {
    Vec3 n = Vec3::Zero();
    if (k > 0) n += faceNormals[k - 1];
    if (k + 1 < nr) n += faceNormals[k];
    if (!n.allFinite())
      throw NumericalError(kStage, "face normal of a curved region is not finite");
    if (!(n.norm() > 1e-12)) return false;
    ctx.rulingNormal[k] = n.normalized();
  }
  return true;
}

// paper Sec. 6.2, Fig. 15: the runs of consecutive rulings between two boundary chains on dS.
std::vector<std::pair<int, int>> boundaryRuns(const GeometricMesh& g,
                                              const std::vector<Ruling>& rulings) {
  const std::size_t nr = rulings.size();
  std::set<std::pair<int, int>> boundaryEdges;
  for (const GeometricEdge& e : buildEdges(g)) {
    if (!e.interior()) boundaryEdges.insert({e.v[0], e.v[1]});
  }
  const auto onBoundary = [&](int v) {
    const GeometricVertex& gv = g.vertices[idx(v)];
    return gv.onBoundary && gv.outlineSegment >= 0 &&
           gv.outlineSegment < static_cast<int>(g.outline.size());
  };
  const auto sideOnBoundary = [&](int a, int b) {
    return a == b || boundaryEdges.contains({std::min(a, b), std::max(a, b)});
  };
  std::vector<std::pair<int, int>> runs;
  for (int k = 0; k < static_cast<int>(nr);) {
    const Ruling& r = rulings[idx(k)];
    if (!onBoundary(r.a) || !onBoundary(r.b)) {
      ++k;
      continue;
    }
    int e = k;
    while (e + 1 < static_cast<int>(nr)) {
      const Ruling& p = rulings[idx(e)];
      const Ruling& q = rulings[idx(e + 1)];
      if (!onBoundary(q.a) || !onBoundary(q.b) || !sideOnBoundary(p.a, q.a) ||
          !sideOnBoundary(p.b, q.b))
        break;
      ++e;
    }
    if (e > k) runs.emplace_back(k, e);
    k = e + 1;
  }
  return runs;
}

// thesis 2.5.2, Fig. 2.19: one refitted run's rulings, its new endpoints added on dS.
std::vector<Ruling> runRulings(GeometricMesh& g, const BoundaryCurve& curve,
                               const RegionContext& ctx, const std::pair<int, int>& run,
                               const RunResult& rr) {
  // Velocities of the old chain vertices, to interpolate along each chain.
  std::array<std::vector<std::pair<double, Vec3>>, 2> velocity;
  for (int k = run.first; k <= run.second; ++k) {
    const Ruling& r = ctx.rulings[idx(k)];
    for (std::size_t c = 0; c < 2; ++c) {
      const int v = c == 0 ? r.a : r.b;
      velocity[c].emplace_back(rr.chains[c].tOf(vertexS(g, v)), g.vertices[idx(v)].velocity);
    }
  }
  std::array<std::map<double, int>, 2> created;
  const double same = 1e-9 * ctx.spacing;
  const auto vertexAt = [&](std::size_t c, double t) {
    auto it = created[c].lower_bound(t - same);
    if (it != created[c].end() && std::abs(it->first - t) <= same) return it->second;
    const Chain& chain = rr.chains[c];
    const double s = chain.sAt(t);
    GeometricVertex v;
    int seg = -1;
    v.pattern = outlinePoint(g, s, &seg);
    v.position = curve.evaluate(s);
    v.onBoundary = true;
    v.outlineSegment = seg;
    const auto& vel = velocity[c];
    std::size_t j = 0;
    while (j + 1 < vel.size() && vel[j + 1].first < t) ++j;
    if (j + 1 < vel.size() && vel[j + 1].first > vel[j].first) {
      const double f = std::clamp((t - vel[j].first) / (vel[j + 1].first - vel[j].first), 0.0, 1.0);
      v.velocity = (1.0 - f) * vel[j].second + f * vel[j + 1].second;
    } else {
      v.velocity = vel[j].second;
    }
    requireFinite(v.pattern, "new boundary vertex");
    requireFinite(v.position, "new boundary vertex");
    const int id = addVertex(g, v);
    created[c][t] = id;
    return id;
  };
  std::vector<Ruling> out;
  for (const ChainRuling& cr : rr.rulings) {
    Ruling r;
    r.a = cr.v[0] >= 0 ? cr.v[0] : vertexAt(0, cr.t[0]);
    r.b = cr.v[1] >= 0 ? cr.v[1] : vertexAt(1, cr.t[1]);
    out.push_back(r);
  }
  return out;
}

// paper Sec. 6.2: the region's new ruling list, each run of `old` replaced by its refit.
std::vector<Ruling> spliceRuns(const std::vector<Ruling>& old,
                               const std::vector<std::pair<int, int>>& runs,
                               const std::vector<std::vector<Ruling>>& runRulings) {
  const std::size_t nr = old.size();
  std::vector<Ruling> rulings;
  std::size_t run = 0;
  for (int k = 0; k < static_cast<int>(nr);) {
    if (run < runs.size() && runs[run].first == k) {
      for (const Ruling& r : runRulings[run]) rulings.push_back(r);
      k = runs[run].second + 1;
      ++run;
      continue;
    }
    rulings.push_back(old[idx(k)]);
    ++k;
  }
  return rulings;
}

// Whether every new face is convex in the pattern, oriented as the faces between `old`.
bool refittedFacesValid(const GeometricMesh& g, const std::vector<Ruling>& old,
                        const std::vector<Ruling>& rulings) {
  const std::size_t nr = old.size();
  const auto P = [&](int v) -> const Vec2& { return g.vertices[idx(v)].pattern; };
  double sign = 0.0;
  for (std::size_t k = 0; k + 1 < nr && sign == 0.0; ++k) {
    const Ruling& r0 = old[k];
    const Ruling& r1 = old[k + 1];
    const double area = cross2(P(r0.a), P(r1.a)) + cross2(P(r1.a), P(r1.b)) +
                        cross2(P(r1.b), P(r0.b)) + cross2(P(r0.b), P(r0.a));
    if (area != 0.0) sign = area > 0.0 ? 1.0 : -1.0;
  }
  const double minArea = 1e-14 * std::abs(outlineArea(g));
  std::set<std::array<int, 4>> originalFaces;
  for (std::size_t k = 0; k + 1 < nr; ++k) {
    const Ruling& r0 = old[k];
    const Ruling& r1 = old[k + 1];
    originalFaces.insert({r0.a, r0.b, r1.a, r1.b});
  }
  bool ok = sign != 0.0;
  for (std::size_t k = 0; ok && k + 1 < rulings.size(); ++k) {
    const Ruling& r0 = rulings[k];
    const Ruling& r1 = rulings[k + 1];
    if (originalFaces.contains({r0.a, r0.b, r1.a, r1.b})) continue;  // untouched face
    const std::array<int, 4> ids{r0.a, r1.a, r1.b, r0.b};
    std::array<Vec2, 4> poly;
    std::array<bool, 4> skip{false, false, false, false};
    for (std::size_t j = 0; j < 4; ++j) poly[j] = P(ids[j]);
    if (ids[1] == ids[0]) skip[1] = true;
    if (ids[2] == ids[3]) skip[3] = true;
    if (r0.a == r1.a && r0.b == r1.b) continue;
    ok = convexFace(poly, skip, sign, minArea);
  }
  return ok;
}

}  // namespace

// paper Sec. 6.2 (last paragraphs), Fig. 15; thesis 2.5.2, Fig. 2.19.
ConeRefitResult refitCurvedRegion(GeometricMesh& g, int region, const BoundaryCurve& curve,
                                  const CrumpleParams& params, double paperLength) {
  if (!inRange(g.regions, region)) {
    throw std::out_of_range("refitCurvedRegion: region index out of range");
  }
  const Region& reg = g.regions[idx(region)];
  if (reg.type != mesh::RegionType::Curved)
    throw std::invalid_argument("refitCurvedRegion: not a curved region");
  if (!(paperLength > 0.0) || !std::isfinite(paperLength)) {
    throw std::invalid_argument("refitCurvedRegion: paperLength must be positive");
  }
  if (!(params.rhoBound > 0.0) || !std::isfinite(params.rhoBound)) {
    throw std::invalid_argument("refitCurvedRegion: rhoBound must be positive");
  }
  ConeRefitResult result;
  if (reg.apex >= 0) {
    result.skipped = "the region has an apex vertex (a single cone, paper Sec. 5.2)";
    return result;
  }
  if (reg.rulings.size() < 2) {
    result.skipped = "the region has fewer than two rulings";
    return result;
  }
  const int nv = static_cast<int>(g.vertices.size());
  for (const Ruling& r : reg.rulings) {
    if (r.a < 0 || r.b < 0 || r.a >= nv || r.b >= nv || r.a == r.b) {
      throw std::invalid_argument("refitCurvedRegion: invalid ruling");
    }
  }

  RegionContext ctx;
  ctx.g = &g;
  ctx.perimeter = outlinePerimeter(g);
  ctx.spacing = 1.0 / params.rhoBound;
  ctx.tolerance = params.epsBlaschke * paperLength;
  ctx.paperLength = paperLength;
  ctx.cornerS = outlineCornerParameters(g);

  // Orient the rulings: a on the side of r_0.a.
  ctx.rulings = reg.rulings;
  orientRulings(g, ctx.rulings);

  // Vertices that never move: handles, singular vertices, corners and
  // vertices of other regions' faces.
  const std::map<std::vector<int>, int> faceOf = markFixedVertices(g, region, ctx);

  // Tangent plane normals: mean faceNormal of the faces on both sides.
  if (!setRulingNormals(g, faceOf, ctx)) {
    result.skipped = "a ruling has no tangent plane (degenerate faces)";
    return result;
  }

  // Runs of rulings whose endpoints lie on dS, joined by boundary edges.
  const std::vector<std::pair<int, int>> runs = boundaryRuns(g, ctx.rulings);
  if (runs.empty()) {
    result.skipped = "no two consecutive rulings run between boundary chains on dS";
    return result;
  }

  std::vector<RunResult> runResults(runs.size());
  for (std::size_t i = 0; i < runs.size(); ++i) {
    RunRefitter refitter(ctx, runs[i].first, runs[i].second);
    const std::string why = refitter.run(runResults[i]);
    if (!why.empty()) {
      result.skipped = why;
      return result;
    }
  }

  // Apply: create the new vertices and the new ruling list.
  const std::size_t verticesBefore = g.vertices.size();
  std::vector<std::vector<Ruling>> newRunRulings(runs.size());
  for (std::size_t i = 0; i < runs.size(); ++i)
    newRunRulings[i] = runRulings(g, curve, ctx, runs[i], runResults[i]);
  std::vector<Ruling> rulings = spliceRuns(ctx.rulings, runs, newRunRulings);

  // Check every new face (pattern, strictly convex, same orientation as the
  // region's faces) before committing.
  if (!refittedFacesValid(g, ctx.rulings, rulings)) {
    g.vertices.resize(verticesBefore);
    result.skipped = "the refitted faces would be degenerate or non-convex";
    return result;
  }

  // Commit.
  Region& target = g.regions[idx(region)];
  target.rulings = std::move(rulings);
  rebuildCurvedFaces(g, region);
  result.changed = true;
  result.addedVertices = static_cast<int>(g.vertices.size() - verticesBefore);
  for (RunResult& rr : runResults) {
    result.segmentCount += static_cast<int>(rr.segments.size());
    result.junctionCones += rr.junctionCones;
    result.sharedRulings += rr.sharedRulings;
    result.keptJunctions += rr.keptJunctions;
  }
  result.segments = std::move(runResults.back().segments);
  result.apices = std::move(runResults.back().apices);
  return result;
}

double worstRulingCompression(const GeometricMesh& g, int region) {
  double worst = 0.0;
  for (const Ruling& r : g.regions.at(idx(region)).rulings) {
    const GeometricVertex& a = g.vertices.at(idx(r.a));
    const GeometricVertex& b = g.vertices.at(idx(r.b));
    worst = std::max(worst, edgeCompression(a.pattern, b.pattern, a.position, b.position));
  }
  return worst;
}

}  // namespace crumple::paper
