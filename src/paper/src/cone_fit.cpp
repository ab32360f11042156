#include "crumple/paper/cone_fit.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "crumple/core/error.hpp"
#include "crumple/core/geometry2d.hpp"
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
// Length scale L of the apex fit in refitCurvedRegion, in sheet sizes: an
// apex much closer than L is judged by its plane distances (paper eq. (2)),
// a much farther one by L times the angles (see cone_fit.hpp).
constexpr double kFarApex = 10.0;

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
  const auto fitRange = [&] {
    return fitApex(planes.subspan(static_cast<std::size_t>(f), static_cast<std::size_t>(b - f + 1)),
                   frame);
  };
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
  if (segment.first < 0 || segment.last < segment.first ||
      static_cast<std::size_t>(segment.last) >= rulings.size() ||
      segment.fit.contributions.size() !=
          static_cast<std::size_t>(segment.last - segment.first + 1)) {
    throw std::invalid_argument("patternApex: segment does not match the rulings");
  }
  const std::vector<double>& e = segment.fit.contributions;
  const double eMin = *std::min_element(e.begin(), e.end());
  // Rulings tied with the minimum (plane distances within kTieDistance,
  // e.g. exact data where every e_j is rounding noise): the one whose 3D
  // line passes closest to the apex (most parallel to it at infinity).
  const auto offLine = [&](std::size_t i) {
    const RulingGeometry& r = rulings[static_cast<std::size_t>(segment.first) + i];
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
  const RulingGeometry& r = rulings[static_cast<std::size_t>(out.ruling)];
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
// paragraphs, Fig. 15; thesis 2.5.2, Fig. 2.19).

namespace {

// Outline parameter s taken modulo the perimeter into [0, perimeter).
double wrapPositive(double s, double perimeter) {
  double w = std::fmod(s, perimeter);
  if (w < 0.0) w += perimeter;
  if (w >= perimeter) w = 0.0;
  return w;
}

// One boundary chain of a run of rulings: a piece of dS parametrized by
// t in [0, length], t = sigma (s - s0) modulo the perimeter.
struct Chain {
  const GeometricMesh* g = nullptr;
  double perimeter = 0.0;
  double s0 = 0.0;
  int sigma = 1;
  double length = 0.0;
  std::vector<double> knots;  // 0, corners strictly inside, length

  double sAt(double t) const { return wrapPositive(s0 + sigma * t, perimeter); }
  double tOf(double s) const { return wrapPositive(sigma * (s - s0), perimeter); }
  Vec2 point(double t) const { return outlinePoint(*g, sAt(t)); }

  // The intersection of the line o + mu dir with the chain within [lo, hi]
  // closest to `guess`.
  std::optional<double> hit(const Vec2& o, const Vec2& dir, double lo, double hi, double guess,
                            double eps) const {
    std::optional<double> best;
    for (std::size_t k = 0; k + 1 < knots.size(); ++k) {
      const double t0 = knots[k];
      const double t1 = knots[k + 1];
      if (t1 < lo - eps || t0 > hi + eps || t1 - t0 <= 0.0) continue;
      const Vec2 p = point(t0);
      const Vec2 e = point(t1) - p;
      const double denom = cross2(e, dir);
      if (std::abs(denom) <= 1e-14 * e.norm() * dir.norm()) continue;  // parallel
      const double lambda = cross2(o - p, dir) / denom;
      const double t = t0 + lambda * (t1 - t0);
      if (t < std::max(t0, lo) - eps || t > std::min(t1, hi) + eps) continue;
      const double clamped = std::clamp(t, lo, hi);
      if (!best || std::abs(clamped - guess) < std::abs(*best - guess)) best = clamped;
    }
    return best;
  }
};

// A pencil of pattern lines: through a point (cone apex) or parallel
// (apex at infinity).
struct Pencil {
  bool atInfinity = false;
  Vec2 point = Vec2::Zero();
  Vec2 direction = Vec2::UnitY();

  // Direction of the line of the pencil through p (nullopt when p is the apex).
  std::optional<Vec2> through(const Vec2& p, double eps) const {
    if (atInfinity) return direction;
    const Vec2 d = p - point;
    if (d.norm() <= eps) return std::nullopt;
    return d;
  }
};

// A ruling in chain coordinates: t[c] on chain c, v[c] the S_G vertex when
// the endpoint is an existing vertex (-1: to be created).
struct ChainRuling {
  std::array<double, 2> t{0.0, 0.0};
  std::array<int, 2> v{-1, -1};
};

struct FixedPoint {
  double t = 0.0;
  int v = -1;
};

struct RunResult {
  std::vector<ChainRuling> rulings;  // replaces the run, borders included
  std::array<Chain, 2> chains;
  std::vector<ConeSegment> segments;
  std::vector<PatternApex> apices;
  int junctionCones = 0;
  int sharedRulings = 0;
  int keptJunctions = 0;
};

// The data of the region the runs need.
struct RegionContext {
  GeometricMesh* g = nullptr;
  std::vector<Ruling> rulings;  // oriented: a on side 0
  double perimeter = 0.0;
  double spacing = 0.0;  // 1 / rho_bound
  double tolerance = 0.0;
  double paperLength = 0.0;
  std::vector<double> cornerS;
  std::vector<char> fixedVertex;   // never moves (handle, singular, corner, used by another region)
  std::vector<Vec3> rulingNormal;  // per region ruling
};

// Outline parameter of a boundary vertex (paper Sec. 6.2: the boundary
// curve is parametrized along dS).
double vertexS(const GeometricMesh& g, int v) {
  const GeometricVertex& gv = g.vertices[static_cast<std::size_t>(v)];
  return wrapPositive(outlineParameter(g, gv.pattern, gv.outlineSegment), outlinePerimeter(g));
}

// Normal of the polygon between rulings r0 and r1 (a0, a1, b1, b0), oriented
// like a counter-clockwise face (faceNormal's convention).
Vec3 polygonNormal(const GeometricMesh& g, const Ruling& r0, const Ruling& r1) {
  std::array<int, 4> poly{r0.a, r1.a, r1.b, r0.b};
  std::vector<int> v;
  for (int id : poly) {
    if (!v.empty() && v.back() == id) continue;
    v.push_back(id);
  }
  if (v.size() > 1 && v.back() == v.front()) v.pop_back();
  if (v.size() < 3) return Vec3::Zero();
  const auto P = [&](std::size_t k) -> const Vec3& {
    return g.vertices[static_cast<std::size_t>(v[k])].position;
  };
  const auto Q = [&](std::size_t k) -> const Vec2& {
    return g.vertices[static_cast<std::size_t>(v[k])].pattern;
  };
  Vec3 n = v.size() == 3 ? Vec3((P(1) - P(0)).cross(P(2) - P(0)))
                         : Vec3((P(2) - P(0)).cross(P(3) - P(1)));
  double area = 0.0;
  for (std::size_t k = 0; k < v.size(); ++k) area += cross2(Q(k), Q((k + 1) % v.size()));
  if (area < 0.0) n = -n;
  const double len = n.norm();
  return len > 0.0 ? Vec3(n / len) : Vec3::Zero();
}

// Samples strictly inside [lo, hi] of one chain with spacing <= h, uniform.
std::vector<double> uniformInterior(double lo, double hi, double h) {
  std::vector<double> out;
  const double len = hi - lo;
  if (!(len > h * (1.0 + 1e-9))) return out;
  const int m = static_cast<int>(std::ceil(len / h - 1e-9));
  for (int i = 1; i < m; ++i) out.push_back(lo + len * static_cast<double>(i) / m);
  return out;
}

class RunRefitter {
 public:
  RunRefitter(const RegionContext& ctx, int first, int last)
      : ctx_(ctx), first_(first), last_(last) {}

  // Returns the reason when the run cannot be refitted.
  std::string run(RunResult& out);

 private:
  std::string buildChains();
  std::string fanRun(int apexChain);
  std::string coneRun();
  // thesis 2.5.2 / paper Fig. 15 last row: rulings of a junction cone from
  // the point t on chain c to the other chain over [lo, hi] (exclusive).
  void fanInterior(int c, double t, int v, double lo, double hi,
                   std::vector<ChainRuling>& out) const;
  // paper Sec. 6.2: rulings of cone `pencil` strictly between s and e.
  std::string coneInterior(const Pencil& pencil, const ChainRuling& s, const ChainRuling& e,
                           std::vector<ChainRuling>& out) const;
  std::optional<double> pencilHit(const Pencil& pencil, int c, double t, double lo, double hi,
                                  double guess) const;
  ChainRuling original(int k) const;  // run-local index k

  const RegionContext& ctx_;
  int first_;
  int last_;
  std::array<Chain, 2> chains_;
  std::array<std::vector<FixedPoint>, 2> fixed_;  // fixed vertices strictly inside each chain
  std::vector<std::array<double, 2>> t_;  // chain coordinates of the original rulings (run-local)
  RunResult* out_ = nullptr;
  double eps_ = 0.0;
};

// The current (original) ruling k of the run in chain coordinates.
ChainRuling RunRefitter::original(int k) const {
  const Ruling& r = ctx_.rulings[static_cast<std::size_t>(first_ + k)];
  ChainRuling out;
  out.t = t_[static_cast<std::size_t>(k)];
  out.v = {r.a, r.b};
  return out;
}

// paper Fig. 15: the two boundary chains of dS the rulings of a run end on,
// with the chain coordinates of the current rulings and the fixed vertices.
std::string RunRefitter::buildChains() {
  const GeometricMesh& g = *ctx_.g;
  const int n = last_ - first_ + 1;
  t_.assign(static_cast<std::size_t>(n), {0.0, 0.0});
  for (int c = 0; c < 2; ++c) {
    std::vector<int> verts;
    std::vector<double> s;
    for (int k = 0; k < n; ++k) {
      const Ruling& r = ctx_.rulings[static_cast<std::size_t>(first_ + k)];
      verts.push_back(c == 0 ? r.a : r.b);
      s.push_back(vertexS(g, verts.back()));
    }
    // Direction along dS: the sum of the wrapped steps.
    double total = 0.0;
    for (int k = 0; k + 1 < n; ++k) {
      double d = wrapPositive(s[static_cast<std::size_t>(k + 1)] - s[static_cast<std::size_t>(k)],
                              ctx_.perimeter);
      if (d > 0.5 * ctx_.perimeter) d -= ctx_.perimeter;
      total += d;
    }
    Chain& chain = chains_[static_cast<std::size_t>(c)];
    chain.g = &g;
    chain.perimeter = ctx_.perimeter;
    chain.s0 = s.front();
    chain.sigma = total < 0.0 ? -1 : 1;
    double prev = 0.0;
    for (int k = 0; k < n; ++k) {
      double t = chain.tOf(s[static_cast<std::size_t>(k)]);
      if (verts[static_cast<std::size_t>(k)] == verts.front()) t = 0.0;
      // A vertex at the very start seen across the wrap.
      if (t > ctx_.perimeter - 1e-12 * ctx_.perimeter) t = 0.0;
      if (t < prev - 1e-12 * ctx_.perimeter)
        return "a boundary chain of the region is not monotone along dS";
      t = std::max(t, prev);
      t_[static_cast<std::size_t>(k)][static_cast<std::size_t>(c)] = t;
      prev = t;
    }
    chain.length = prev;
    chain.knots = {0.0};
    for (double sc : ctx_.cornerS) {
      const double tc = chain.tOf(sc);
      if (tc > 0.0 && tc < chain.length) chain.knots.push_back(tc);
    }
    std::sort(chain.knots.begin(), chain.knots.end());
    chain.knots.push_back(chain.length);
    // Fixed vertices strictly inside the chain.
    std::set<int> seen;
    for (int k = 1; k + 1 < n; ++k) {
      const int v = verts[static_cast<std::size_t>(k)];
      if (v == verts.front() || v == verts.back() || !seen.insert(v).second) continue;
      if (ctx_.fixedVertex[static_cast<std::size_t>(v)]) {
        fixed_[static_cast<std::size_t>(c)].push_back(
            {t_[static_cast<std::size_t>(k)][static_cast<std::size_t>(c)], v});
      }
    }
  }
  return {};
}

// paper Sec. 6.2: where the line of a cone's pencil through the point t of
// chain c meets the other chain (the resampled ruling endpoint).
std::optional<double> RunRefitter::pencilHit(const Pencil& pencil, int c, double t, double lo,
                                             double hi, double guess) const {
  const Chain& from = chains_[static_cast<std::size_t>(c)];
  const Chain& to = chains_[static_cast<std::size_t>(1 - c)];
  const Vec2 p = from.point(t);
  const std::optional<Vec2> dir = pencil.through(p, 1e-9 * ctx_.spacing);
  if (!dir) return std::nullopt;
  return to.hit(p, *dir, lo, hi, guess, eps_);
}

// paper Sec. 6.2 / Fig. 15 last row: the rulings of a junction cone, a fan
// from the point t of chain c over [lo, hi] of the other chain, spaced
// <= 1/rho_bound and through the fixed vertices there.
void RunRefitter::fanInterior(int c, double t, int v, double lo, double hi,
                              std::vector<ChainRuling>& out) const {
  const int o = 1 - c;
  std::vector<FixedPoint> stops{{lo, -1}};
  for (const FixedPoint& f : fixed_[static_cast<std::size_t>(o)]) {
    if (f.t > lo + eps_ && f.t < hi - eps_) stops.push_back(f);
  }
  stops.push_back({hi, -1});
  for (std::size_t k = 0; k + 1 < stops.size(); ++k) {
    if (k > 0) {
      ChainRuling r;
      r.t[static_cast<std::size_t>(c)] = t;
      r.v[static_cast<std::size_t>(c)] = v;
      r.t[static_cast<std::size_t>(o)] = stops[k].t;
      r.v[static_cast<std::size_t>(o)] = stops[k].v;
      out.push_back(r);
    }
    for (double tt : uniformInterior(stops[k].t, stops[k + 1].t, ctx_.spacing)) {
      ChainRuling r;
      r.t[static_cast<std::size_t>(c)] = t;
      r.v[static_cast<std::size_t>(c)] = v;
      r.t[static_cast<std::size_t>(o)] = tt;
      out.push_back(r);
    }
  }
}

// paper Sec. 6.2 / Fig. 15 second row: the rulings of a cone between its
// extreme rulings s and e, all through its pattern apex (thesis 2.5.2:
// density >= rho_bound on both chains, rulings added or removed).
std::string RunRefitter::coneInterior(const Pencil& pencil, const ChainRuling& s,
                                      const ChainRuling& e, std::vector<ChainRuling>& out) const {
  const double len0 = e.t[0] - s.t[0];
  const double len1 = e.t[1] - s.t[1];
  if (len0 <= eps_ && len1 <= eps_) return {};
  const int c = len0 >= len1 ? 0 : 1;  // driver: the longer side
  const int o = 1 - c;
  const auto cu = static_cast<std::size_t>(c);
  const auto ou = static_cast<std::size_t>(o);
  if ((o == 0 ? len0 : len1) <= eps_) {
    // The cone degenerates to a fan from a point of the other chain.
    fanInterior(o, s.t[ou], s.v[ou], s.t[cu], e.t[cu], out);
    return {};
  }
  const auto lerpOther = [&](double tc) {
    return s.t[ou] + (e.t[ou] - s.t[ou]) * (tc - s.t[cu]) / (e.t[cu] - s.t[cu]);
  };
  // Rulings through the fixed vertices inside the cone, aimed at its apex.
  std::vector<ChainRuling> stops{s};
  for (int side = 0; side < 2; ++side) {
    const auto su = static_cast<std::size_t>(side);
    for (const FixedPoint& f : fixed_[su]) {
      if (!(f.t > s.t[su] + eps_ && f.t < e.t[su] - eps_)) continue;
      const double guess =
          side == c ? lerpOther(f.t)
                    : s.t[cu] + (e.t[cu] - s.t[cu]) * (f.t - s.t[su]) / (e.t[su] - s.t[su]);
      const std::optional<double> h = pencilHit(pencil, side, f.t, s.t[1 - su], e.t[1 - su], guess);
      if (!h)
        return "a fixed boundary vertex cannot be joined to its cone's apex inside the region";
      ChainRuling r;
      r.t[su] = f.t;
      r.v[su] = f.v;
      r.t[1 - su] = *h;
      stops.push_back(r);
    }
  }
  stops.push_back(e);
  std::sort(stops.begin() + 1, stops.end() - 1,
            [cu](const ChainRuling& a, const ChainRuling& b) { return a.t[cu] < b.t[cu]; });
  for (std::size_t k = 0; k + 1 < stops.size(); ++k) {
    if (stops[k + 1].t[ou] < stops[k].t[ou] - eps_ || stops[k + 1].t[cu] < stops[k].t[cu] - eps_) {
      return "the rulings through fixed boundary vertices cross";
    }
  }
  const double h = ctx_.spacing;
  for (std::size_t k = 0; k + 1 < stops.size(); ++k) {
    const ChainRuling& a = stops[k];
    const ChainRuling& b = stops[k + 1];
    if (k > 0) out.push_back(a);
    const double lc = b.t[cu] - a.t[cu];
    const double lo = b.t[ou] - a.t[ou];
    if (lc <= eps_) continue;
    int m = std::max(1, static_cast<int>(std::ceil(lc / h - 1e-9)));
    const int cap = 4 * static_cast<int>(std::ceil(std::max(lc, lo) / h)) + 16;
    std::vector<ChainRuling> best;
    for (; m <= cap; ++m) {
      std::vector<ChainRuling> samples;
      double prevO = a.t[ou];
      double maxGapO = 0.0;
      for (int i = 1; i < m; ++i) {
        const double tc = a.t[cu] + lc * static_cast<double>(i) / m;
        const double guess = a.t[ou] + lo * static_cast<double>(i) / m;
        const std::optional<double> to = pencilHit(pencil, c, tc, a.t[ou], b.t[ou], guess);
        if (!to || *to < prevO - eps_) continue;
        ChainRuling r;
        r.t[cu] = tc;
        r.t[ou] = std::max(*to, prevO);
        maxGapO = std::max(maxGapO, r.t[ou] - prevO);
        prevO = r.t[ou];
        samples.push_back(r);
      }
      maxGapO = std::max(maxGapO, b.t[ou] - prevO);
      best = std::move(samples);
      if (maxGapO <= h * (1.0 + 1e-9)) break;
    }
    out.insert(out.end(), best.begin(), best.end());
  }
  return {};
}

// thesis 2.5.2 (a region that is already one cone with its apex on dS):
// only the sampling of the other chain.
std::string RunRefitter::fanRun(int apexChain) {
  // All rulings of the run share one vertex of chain `apexChain`: already a
  // cone with its apex on dS; only the density along the other chain.
  const int n = last_ - first_ + 1;
  const ChainRuling s = original(0);
  const ChainRuling e = original(n - 1);
  const auto a = static_cast<std::size_t>(apexChain);
  const int o = 1 - apexChain;
  std::vector<ChainRuling>& out = out_->rulings;
  out.push_back(s);
  fanInterior(apexChain, s.t[a], s.v[a], s.t[static_cast<std::size_t>(o)],
              e.t[static_cast<std::size_t>(o)], out);
  out.push_back(e);
  return {};
}

// paper Sec. 6.2 / thesis 2.5.2, Fig. 2.19: planes, segmentation, apices,
// junction cones and the resampled cones of one run.
std::string RunRefitter::coneRun() {
  const GeometricMesh& g = *ctx_.g;
  const int n = last_ - first_ + 1;
  // 1. Tangent plane per ruling (paper Sec. 6.2: normals constant along the ruling).
  std::vector<RulingPlane> planes(static_cast<std::size_t>(n));
  std::vector<RulingGeometry> geometry(static_cast<std::size_t>(n));
  FitFrame frame;
  frame.centre = Vec3::Zero();
  double lengthSum = 0.0;
  for (int k = 0; k < n; ++k) {
    const Ruling& r = ctx_.rulings[static_cast<std::size_t>(first_ + k)];
    const GeometricVertex& va = g.vertices[static_cast<std::size_t>(r.a)];
    const GeometricVertex& vb = g.vertices[static_cast<std::size_t>(r.b)];
    const Vec3 normal = ctx_.rulingNormal[static_cast<std::size_t>(first_ + k)];
    const Vec3 mid = 0.5 * (va.position + vb.position);
    const Vec3 d = vb.position - va.position;
    if (!(d.norm() > 0.0) || !((vb.pattern - va.pattern).norm() > 0.0))
      return "a ruling has zero length";
    planes[static_cast<std::size_t>(k)] = {normal, -normal.dot(mid), d.normalized()};
    geometry[static_cast<std::size_t>(k)] = {va.position, vb.position, va.pattern, vb.pattern,
                                             normal};
    frame.centre += mid;
    lengthSum += d.norm();
  }
  frame.centre /= n;
  frame.length = kFarApex * ctx_.paperLength;
  if (!(lengthSum > 0.0)) return "the rulings have zero length";

  // 2. paper Sec. 6.2 iterative segmentation (disjoint segments, paper text).
  out_->segments = segmentRulings(planes, ctx_.tolerance, frame, false);
  const std::vector<ConeSegment>& segments = out_->segments;
  const int nseg = static_cast<int>(segments.size());
  // 3. The apices in the pattern.
  std::vector<Pencil> pencils;
  for (const ConeSegment& seg : segments) {
    const PatternApex pa = patternApex(seg, geometry, ApexMapping::InTangentPlane);
    out_->apices.push_back(pa);
    Pencil p;
    p.atInfinity = pa.atInfinity;
    p.point = pa.point;
    p.direction = pa.direction;
    pencils.push_back(p);
  }

  // 4. Junctions J = 0..nseg: before the first cone, between cones, after
  // the last one (paper Fig. 15 last row). L[J] ends the cone before, R[J]
  // starts the cone after; the region's borders are kept.
  struct Junction {
    ChainRuling left, right;
    bool fan = false;
    int fanChain = 0;
    bool shared = false;
  };
  const auto resolve = [&](int J, bool degraded) {
    const int iL = J == 0 ? 0 : segments[static_cast<std::size_t>(J - 1)].last;
    const int iR = J == nseg ? n - 1 : segments[static_cast<std::size_t>(J)].first;
    Junction out;
    out.left = original(iL);
    out.right = original(iR);
    if (degraded) return out;
    const Pencil* pl = J == 0 ? nullptr : &pencils[static_cast<std::size_t>(J - 1)];
    const Pencil* pr = J == nseg ? nullptr : &pencils[static_cast<std::size_t>(J)];
    std::optional<Junction> best;
    double bestGap = 0.0;
    for (int which : {iL, iR}) {
      for (int c = 0; c < 2; ++c) {
        const auto cu = static_cast<std::size_t>(c);
        const auto ou = static_cast<std::size_t>(1 - c);
        const ChainRuling base = original(which);
        const double tb = base.t[cu];
        const Chain& other = chains_[ou];
        // The line of each side through b = (c, tb) and where it meets the other chain.
        const auto sideHit = [&](const Pencil* p, int idx) -> std::optional<double> {
          if (p == nullptr) {
            const ChainRuling orig = original(idx);
            if (std::abs(orig.t[cu] - tb) > eps_) return std::nullopt;  // b not on the kept ruling
            return orig.t[ou];
          }
          return pencilHit(*p, c, tb, 0.0, other.length, original(idx).t[ou]);
        };
        const std::optional<double> hl = sideHit(pl, iL);
        const std::optional<double> hr = sideHit(pr, iR);
        if (!hl || !hr || *hl > *hr + eps_) continue;
        const double gap = std::max(0.0, *hr - *hl);
        if (best && gap >= bestGap) continue;
        Junction j;
        j.left.t[cu] = tb;
        j.left.v[cu] = base.v[cu];
        j.left.t[ou] = *hl;
        j.right = j.left;
        j.right.t[ou] = std::max(*hr, *hl);
        if (pl == nullptr) j.left = original(iL);
        if (pr == nullptr) j.right = original(iR);
        j.fanChain = c;
        j.shared = gap <= 1e-6 * ctx_.spacing;
        if (j.shared) {
          // One ruling joins both cones (a kept border when there is one).
          j.right = pl == nullptr ? j.left : (pr == nullptr ? j.right : j.left);
          j.left = j.right;
        }
        j.fan = !j.shared;
        best = j;
        bestGap = gap;
      }
    }
    return best ? *best : out;
  };
  std::vector<char> degraded(static_cast<std::size_t>(nseg + 1), 0);
  std::vector<Junction> junctions(static_cast<std::size_t>(nseg + 1));
  for (bool again = true; again;) {
    again = false;
    for (int J = 0; J <= nseg; ++J)
      junctions[static_cast<std::size_t>(J)] = resolve(J, degraded[static_cast<std::size_t>(J)]);
    for (int j = 0; j < nseg; ++j) {
      const ChainRuling& s = junctions[static_cast<std::size_t>(j)].right;
      const ChainRuling& e = junctions[static_cast<std::size_t>(j + 1)].left;
      if (s.t[0] <= e.t[0] + eps_ && s.t[1] <= e.t[1] + eps_) continue;
      // The cone between would be inverted: keep the original rulings at
      // both of its junctions (shared with the neighbouring cones).
      bool changedHere = false;
      for (int J : {j, j + 1}) {
        if (!degraded[static_cast<std::size_t>(J)]) {
          degraded[static_cast<std::size_t>(J)] = 1;
          changedHere = true;
        }
      }
      if (!changedHere) return "the original rulings are not ordered along the chains";
      again = true;
    }
  }

  for (char d : degraded) out_->keptJunctions += d ? 1 : 0;

  // 5. Assemble: L0 [fan] R0 [cone 0] L1 [fan] R1 ... L_n [fan] R_n.
  std::vector<ChainRuling>& out = out_->rulings;
  for (int J = 0; J <= nseg; ++J) {
    const Junction& junction = junctions[static_cast<std::size_t>(J)];
    out.push_back(junction.left);
    if (junction.fan) {
      const auto cu = static_cast<std::size_t>(junction.fanChain);
      const auto ou = 1 - cu;
      fanInterior(junction.fanChain, junction.left.t[cu], junction.left.v[cu], junction.left.t[ou],
                  junction.right.t[ou], out);
      ++out_->junctionCones;
    } else if (junction.shared && J > 0 && J < nseg) {
      ++out_->sharedRulings;
    }
    out.push_back(junction.right);
    if (J < nseg) {
      const std::string why = coneInterior(pencils[static_cast<std::size_t>(J)], junction.right,
                                           junctions[static_cast<std::size_t>(J + 1)].left, out);
      if (!why.empty()) return why;
    }
  }
  return {};
}

// paper Sec. 6.2: one run of rulings between two chains of dS, then the
// density (thesis 2.5.2: >= rho_bound) and consistency checks.
std::string RunRefitter::run(RunResult& out) {
  out_ = &out;
  eps_ = 1e-9 * ctx_.spacing;
  if (std::string why = buildChains(); !why.empty()) return why;
  out.chains = chains_;
  const bool zero0 = chains_[0].length <= eps_;
  const bool zero1 = chains_[1].length <= eps_;
  if (zero0 && zero1) return "all rulings of the region coincide";
  std::string why = zero0 ? fanRun(0) : zero1 ? fanRun(1) : coneRun();
  if (!why.empty()) return why;

  // Densify gaps wider than 1 / rho_bound on either chain (degraded gaps):
  // rulings interpolated along both chains.
  std::vector<ChainRuling> dense;
  for (std::size_t k = 0; k < out.rulings.size(); ++k) {
    if (k > 0) {
      const ChainRuling& a = out.rulings[k - 1];
      const ChainRuling& b = out.rulings[k];
      const double gap = std::max(b.t[0] - a.t[0], b.t[1] - a.t[1]);
      if (gap > ctx_.spacing * (1.0 + 1e-9)) {
        const int m = static_cast<int>(std::ceil(gap / ctx_.spacing - 1e-9));
        for (int i = 1; i < m; ++i) {
          const double f = static_cast<double>(i) / m;
          ChainRuling r;
          for (std::size_t c = 0; c < 2; ++c) {
            if (std::abs(b.t[c] - a.t[c]) <= eps_ && a.v[c] >= 0) {
              r.t[c] = a.t[c];
              r.v[c] = a.v[c];
            } else {
              r.t[c] = a.t[c] + f * (b.t[c] - a.t[c]);
            }
          }
          dense.push_back(r);
        }
      }
    }
    dense.push_back(out.rulings[k]);
  }

  // Snap new endpoints within a quarter of the spacing onto kept vertices of
  // the same chain, then drop repeated rulings and new rulings closer than
  // half the spacing to a neighbour on either chain: ends millimetres apart
  // make sliver triangles in S_P that stall the elastic solve.
  std::array<std::vector<FixedPoint>, 2> kept;
  for (const ChainRuling& r : dense) {
    for (std::size_t c = 0; c < 2; ++c) {
      if (r.v[c] >= 0) kept[c].push_back({r.t[c], r.v[c]});
    }
  }
  const double snap = 0.25 * ctx_.spacing;
  for (ChainRuling& r : dense) {
    for (std::size_t c = 0; c < 2; ++c) {
      if (r.v[c] >= 0) continue;
      const FixedPoint* nearest = nullptr;
      for (const FixedPoint& f : kept[c]) {
        if (std::abs(f.t - r.t[c]) <= snap &&
            (!nearest || std::abs(f.t - r.t[c]) < std::abs(nearest->t - r.t[c]))) {
          nearest = &f;
        }
      }
      if (nearest != nullptr) {
        r.t[c] = nearest->t;
        r.v[c] = nearest->v;
      }
    }
  }
  out.rulings.clear();
  for (const ChainRuling& r : dense) {
    if (!out.rulings.empty()) {
      const ChainRuling& p = out.rulings.back();
      if (std::abs(p.t[0] - r.t[0]) <= eps_ && std::abs(p.t[1] - r.t[1]) <= eps_) continue;
    }
    out.rulings.push_back(r);
  }
  {
    const double minGap = 0.5 * ctx_.spacing;
    // A ruling may go when each of its vertices is new or stays a ruling
    // end through a neighbour (the apex of a fan).
    const auto isNew = [&](std::size_t k) {
      const ChainRuling& r = out.rulings[k];
      for (std::size_t c = 0; c < 2; ++c) {
        if (r.v[c] < 0) continue;
        const bool shared = (k > 0 && out.rulings[k - 1].v[c] == r.v[c]) ||
                            (k + 1 < out.rulings.size() && out.rulings[k + 1].v[c] == r.v[c]);
        if (!shared) return false;
      }
      return true;
    };
    const auto spaced = [&](const ChainRuling& a, const ChainRuling& b) {
      for (std::size_t c = 0; c < 2; ++c) {
        const double gap = std::abs(b.t[c] - a.t[c]);
        if (gap > eps_ && gap < minGap) return false;
      }
      return true;
    };
    std::vector<ChainRuling> thinned;
    for (std::size_t k = 0; k < out.rulings.size(); ++k) {
      const ChainRuling& r = out.rulings[k];
      if (isNew(k) && k > 0 && k + 1 < out.rulings.size()) {
        std::size_t next = k + 1;  // the next ruling that will surely stay
        while (next + 1 < out.rulings.size() && isNew(next)) ++next;
        if (!spaced(thinned.back(), r) || !spaced(r, out.rulings[next])) continue;
      }
      thinned.push_back(r);
    }
    out.rulings = std::move(thinned);
  }
  // Order along both chains.
  for (std::size_t k = 1; k < out.rulings.size(); ++k) {
    for (std::size_t c = 0; c < 2; ++c) {
      if (out.rulings[k].t[c] < out.rulings[k - 1].t[c] - eps_)
        return "the refitted rulings would cross";
    }
  }
  // Every fixed vertex is still a ruling endpoint.
  for (std::size_t c = 0; c < 2; ++c) {
    for (const FixedPoint& f : fixed_[c]) {
      const bool found = std::any_of(out.rulings.begin(), out.rulings.end(),
                                     [&](const ChainRuling& r) { return r.v[c] == f.v; });
      if (!found) return "a fixed boundary vertex would no longer be a ruling endpoint";
    }
  }
  return {};
}

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

}  // namespace

// paper Sec. 6.2 (last paragraphs), Fig. 15; thesis 2.5.2, Fig. 2.19.
ConeRefitResult refitCurvedRegion(GeometricMesh& g, int region, const BoundaryCurve& curve,
                                  const CrumpleParams& params, double paperLength) {
  if (region < 0 || static_cast<std::size_t>(region) >= g.regions.size()) {
    throw std::out_of_range("refitCurvedRegion: region index out of range");
  }
  const Region& reg = g.regions[static_cast<std::size_t>(region)];
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
  for (std::size_t k = 1; k < ctx.rulings.size(); ++k) {
    const Ruling& p = ctx.rulings[k - 1];
    Ruling& r = ctx.rulings[k];
    bool flip = false;
    if (r.a == p.a || r.b == p.b) {
      flip = false;
    } else if (r.a == p.b || r.b == p.a) {
      flip = true;
    } else {
      const auto P = [&](int v) -> const Vec2& {
        return g.vertices[static_cast<std::size_t>(v)].pattern;
      };
      flip = (P(r.b) - P(p.a)).norm() + (P(r.a) - P(p.b)).norm() <
             (P(r.a) - P(p.a)).norm() + (P(r.b) - P(p.b)).norm();
    }
    if (flip) std::swap(r.a, r.b);
  }

  // Vertices that never move: handles, singular vertices, corners and
  // vertices of other regions' faces.
  ctx.fixedVertex.assign(static_cast<std::size_t>(nv), 0);
  for (int v = 0; v < nv; ++v) {
    const GeometricVertex& gv = g.vertices[static_cast<std::size_t>(v)];
    ctx.fixedVertex[static_cast<std::size_t>(v)] = gv.handle || gv.singular || gv.corner;
  }
  std::map<std::vector<int>, int> faceOf;  // sorted vertex set -> face of this region
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    const GeometricFace& face = g.faces[f];
    if (face.region != region) {
      for (int k = 0; k < face.size(); ++k)
        ctx.fixedVertex[static_cast<std::size_t>(face.v[k])] = 1;
      continue;
    }
    std::vector<int> key(face.v.begin(), face.v.begin() + face.size());
    std::sort(key.begin(), key.end());
    faceOf[key] = static_cast<int>(f);
  }

  // Tangent plane normals: mean faceNormal of the faces on both sides.
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
    if (!(n.norm() > 1e-12)) {
      result.skipped = "a ruling has no tangent plane (degenerate faces)";
      return result;
    }
    ctx.rulingNormal[k] = n.normalized();
  }

  // Runs of rulings whose endpoints lie on dS, joined by boundary edges.
  std::set<std::pair<int, int>> boundaryEdges;
  for (const GeometricEdge& e : buildEdges(g)) {
    if (!e.interior()) boundaryEdges.insert({e.v[0], e.v[1]});
  }
  const auto onBoundary = [&](int v) {
    const GeometricVertex& gv = g.vertices[static_cast<std::size_t>(v)];
    return gv.onBoundary && gv.outlineSegment >= 0 &&
           gv.outlineSegment < static_cast<int>(g.outline.size());
  };
  const auto sideOnBoundary = [&](int a, int b) {
    return a == b || boundaryEdges.contains({std::min(a, b), std::max(a, b)});
  };
  std::vector<std::pair<int, int>> runs;
  for (int k = 0; k < static_cast<int>(nr);) {
    const Ruling& r = ctx.rulings[static_cast<std::size_t>(k)];
    if (!onBoundary(r.a) || !onBoundary(r.b)) {
      ++k;
      continue;
    }
    int e = k;
    while (e + 1 < static_cast<int>(nr)) {
      const Ruling& p = ctx.rulings[static_cast<std::size_t>(e)];
      const Ruling& q = ctx.rulings[static_cast<std::size_t>(e + 1)];
      if (!onBoundary(q.a) || !onBoundary(q.b) || !sideOnBoundary(p.a, q.a) ||
          !sideOnBoundary(p.b, q.b))
        break;
      ++e;
    }
    if (e > k) runs.emplace_back(k, e);
    k = e + 1;
  }
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
  std::vector<std::vector<Ruling>> runRulings(runs.size());
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const RunResult& rr = runResults[i];
    // Velocities of the old chain vertices, to interpolate along each chain.
    std::array<std::vector<std::pair<double, Vec3>>, 2> velocity;
    for (int k = runs[i].first; k <= runs[i].second; ++k) {
      const Ruling& r = ctx.rulings[static_cast<std::size_t>(k)];
      for (std::size_t c = 0; c < 2; ++c) {
        const int v = c == 0 ? r.a : r.b;
        velocity[c].emplace_back(rr.chains[c].tOf(vertexS(g, v)),
                                 g.vertices[static_cast<std::size_t>(v)].velocity);
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
        const double f =
            std::clamp((t - vel[j].first) / (vel[j + 1].first - vel[j].first), 0.0, 1.0);
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
    for (const ChainRuling& cr : rr.rulings) {
      Ruling r;
      r.a = cr.v[0] >= 0 ? cr.v[0] : vertexAt(0, cr.t[0]);
      r.b = cr.v[1] >= 0 ? cr.v[1] : vertexAt(1, cr.t[1]);
      runRulings[i].push_back(r);
    }
  }
  std::vector<Ruling> rulings;
  std::size_t run = 0;
  for (int k = 0; k < static_cast<int>(nr);) {
    if (run < runs.size() && runs[run].first == k) {
      for (const Ruling& r : runRulings[run]) rulings.push_back(r);
      k = runs[run].second + 1;
      ++run;
      continue;
    }
    rulings.push_back(ctx.rulings[static_cast<std::size_t>(k)]);
    ++k;
  }

  // Check every new face (pattern, strictly convex, same orientation as the
  // region's faces) before committing.
  const auto P = [&](int v) -> const Vec2& {
    return g.vertices[static_cast<std::size_t>(v)].pattern;
  };
  double sign = 0.0;
  for (std::size_t k = 0; k + 1 < nr && sign == 0.0; ++k) {
    const Ruling& r0 = ctx.rulings[k];
    const Ruling& r1 = ctx.rulings[k + 1];
    const double area = cross2(P(r0.a), P(r1.a)) + cross2(P(r1.a), P(r1.b)) +
                        cross2(P(r1.b), P(r0.b)) + cross2(P(r0.b), P(r0.a));
    if (area != 0.0) sign = area > 0.0 ? 1.0 : -1.0;
  }
  const double minArea = 1e-14 * std::abs(outlineArea(g));
  std::set<std::array<int, 4>> originalFaces;
  for (std::size_t k = 0; k + 1 < nr; ++k) {
    const Ruling& r0 = ctx.rulings[k];
    const Ruling& r1 = ctx.rulings[k + 1];
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
  if (!ok) {
    g.vertices.resize(verticesBefore);
    result.skipped = "the refitted faces would be degenerate or non-convex";
    return result;
  }

  // Commit.
  Region& target = g.regions[static_cast<std::size_t>(region)];
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
  for (const Ruling& r : g.regions.at(static_cast<std::size_t>(region)).rulings) {
    const GeometricVertex& a = g.vertices.at(static_cast<std::size_t>(r.a));
    const GeometricVertex& b = g.vertices.at(static_cast<std::size_t>(r.b));
    worst = std::max(worst, edgeCompression(a.pattern, b.pattern, a.position, b.position));
  }
  return worst;
}

}  // namespace crumple::paper
