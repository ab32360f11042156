// A run cut into sub-cells along its ruling pencil, shaped by the paper's
// cubic boundary curve and folded isometrically (developable.hpp).
#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "crumple/core/index.hpp"
#include "developable_detail.hpp"

namespace crumple::mesh::developable {

namespace {

double cross2(const Vec2& u, const Vec2& v) { return u.x() * v.y() - u.y() * v.x(); }

// The line through p and q as (n, c) with n . x + c = 0, n a unit normal
// turned +90 degrees from q - p.
Eigen::Vector3d patternLine(const Vec2& p, const Vec2& q) {
  Vec2 n(p.y() - q.y(), q.x() - p.x());
  n.normalize();
  return {n.x(), n.y(), -n.dot(p)};
}
double onLine(const Eigen::Vector3d& l, const Vec2& p) {
  return l.x() * p.x() + l.y() * p.y() + l.z();
}

// The parameter t in [0, 1] where the segment p0-p1 meets the line.
double meet(const Eigen::Vector3d& l, const Vec2& p0, const Vec2& p1) {
  const double f0 = onLine(l, p0), f1 = onLine(l, p1);
  if (!(std::abs(f0 - f1) > 0.0)) return 0.0;
  return std::clamp(f0 / (f0 - f1), 0.0, 1.0);
}

// A rigid motion of the pattern plane into space: x = R (p, 0) + t.
struct Rigid {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
  Vec3 operator()(const Vec2& p) const { return R.col(0) * p.x() + R.col(1) * p.y() + t; }
  // This motion followed by the rotation by `angle` about the line through
  // `point` along the unit `axis`.
  Rigid thenRotate(const Vec3& point, const Vec3& axis, double angle) const {
    const Mat3 Q = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    return {Q * R, Q * (t - point) + point};
  }
};

// The unit normal of sub-cell j (between sub-rulings j and j + 1) on the
// image of the pattern's +z: the cross product of its diagonals, signed by
// the pattern's (as paper::faceNormal does for an S_G quad).
Vec3 cellNormal(std::span<const SubRuling> s, std::size_t j) {
  const double sign = cross2(s[j + 1].pb - s[j].pa, s[j].pb - s[j + 1].pa) >= 0.0 ? 1.0 : -1.0;
  return (sign * (s[j + 1].xb - s[j].xa).cross(s[j].xb - s[j + 1].xa)).normalized();
}

}  // namespace

// Paper Sec. 3.2 and Fig. 15: the sub-rulings of a quad are lines of the
// pencil spanned by its two rulings (through their pattern apex when they
// converge, parallel when they do not), at even steps along its longer side;
// a fan's go from the apex to even steps along its opposite side. 3D ends
// on dS from the cubic boundary curve (paper Sec. 6.2).
std::vector<SubRuling> subRulings(const SheetMesh& sheet, const Run& run,
                                  std::span<const int> cells, const BoundaryCurves& boundary) {
  std::vector<SubRuling> out;
  const auto P = [&](int v) { return sheet.pattern[idx(v)]; };
  const auto X = [&](int v) { return sheet.positions[idx(v)]; };
  for (std::size_t k = 0; k < run.faces.size(); ++k) {
    const Face& f = run.faces[k];
    const auto [a0, b0] = f.r0;
    const auto [a1, b1] = f.r1;
    const int n = std::max(1, cells[k]);
    const Eigen::Vector3d la = patternLine(P(a0), P(b0)), lb = patternLine(P(a1), P(b1));
    const bool alongA = (P(a1) - P(a0)).norm() >= (P(b1) - P(b0)).norm();
    for (int j = k == 0 ? 0 : 1; j <= n; ++j) {
      SubRuling s;
      s.face = static_cast<int>(k);
      if (j == 0 || j == n) {
        s.va = j == 0 ? a0 : a1;
        s.vb = j == 0 ? b0 : b1;
        s.pa = P(s.va), s.pb = P(s.vb), s.xa = X(s.va), s.xb = X(s.vb);
        out.push_back(s);
        continue;
      }
      const double t = static_cast<double>(j) / n;
      double ta = t, tb = t;
      if (f.fanSide < 0) {
        const Vec2 q =
            alongA ? Vec2((1 - t) * P(a0) + t * P(a1)) : Vec2((1 - t) * P(b0) + t * P(b1));
        const double fa = onLine(la, q), fb = onLine(lb, q);
        const double mu = std::abs(fa - fb) > 0.0 ? fa / (fa - fb) : t;
        const Eigen::Vector3d l = (1.0 - mu) * la + mu * lb;
        if (alongA)
          tb = meet(l, P(b0), P(b1));
        else
          ta = meet(l, P(a0), P(a1));
      }
      if (f.fanSide == 0) {
        s.va = a0, s.pa = P(a0), s.xa = X(a0);
      } else {
        s.pa = (1.0 - ta) * P(a0) + ta * P(a1);
        s.xa = boundary.sidePoint(sheet, a0, a1, ta);
      }
      if (f.fanSide == 1) {
        s.vb = b0, s.pb = P(b0), s.xb = X(b0);
      } else {
        s.pb = (1.0 - tb) * P(b0) + tb * P(b1);
        s.xb = boundary.sidePoint(sheet, b0, b1, tb);
      }
      out.push_back(s);
    }
  }
  if (!out.empty()) out.back().face = static_cast<int>(run.faces.size()) - 1;
  return out;
}

std::vector<double> foldAngles(std::span<const SubRuling> strip) {
  std::vector<double> angles;
  if (strip.size() < 3) return angles;
  Vec3 before = cellNormal(strip, 0);
  for (std::size_t j = 1; j + 1 < strip.size(); ++j) {
    const Vec3 after = cellNormal(strip, j);
    const Vec3 axis = (strip[j].xb - strip[j].xa).normalized();
    angles.push_back(std::atan2(before.cross(after).dot(axis), before.dot(after)));
    before = after;
  }
  return angles;
}

namespace {

// The rigid motion of every cell for the given fold angles (cell j's is
// motions[j]), from the first cell's `start`.
std::vector<Rigid> foldMotions(std::span<const SubRuling> s, const Rigid& start,
                               std::span<const double> angles) {
  std::vector<Rigid> motions{start};
  for (std::size_t j = 1; j + 1 < s.size(); ++j) {
    const Rigid& T = motions.back();
    const Vec3 qa = T(s[j].pa);
    motions.push_back(T.thenRotate(qa, (T(s[j].pb) - qa).normalized(), angles[j - 1]));
  }
  return motions;
}

// Where the last ruling's ends should be minus where the folds put them.
Eigen::Matrix<double, 6, 1> closureResidual(std::span<const SubRuling> s, const Rigid& last) {
  Eigen::Matrix<double, 6, 1> r;
  r.head<3>() = s.back().xa - last(s.back().pa);
  r.tail<3>() = s.back().xb - last(s.back().pb);
  return r;
}

}  // namespace

// Paper Sec. 3.2 / thesis 2.2.1 (a developable surface's tangent plane is
// constant along each ruling): every sub-cell a rigid copy of its pattern
// polygon, folded about the sub-rulings by the naive cubic surface's
// dihedral angles; the closure onto S_P's last ruling by minimum-norm
// Levenberg-Marquardt steps on the angles (Levenberg 1944, Marquardt 1963).
FoldResult foldStrip(std::vector<SubRuling>& s) {
  FoldResult result;
  const std::size_t m = s.size();
  if (m < 3) return result;
  // The start: the first ruling on S_P's (anchored at the apex of a fan at
  // b, else at its a end), rolled into the first naive cell's plane.
  const bool anchorB = s[0].vb >= 0 && s[0].vb == s[1].vb;
  const Vec2 u2 = (s[0].pb - s[0].pa).normalized();
  const Vec2 v2(-u2.y(), u2.x());
  const Vec3 u3 = (s[0].xb - s[0].xa).normalized();
  const Vec3 n0 = cellNormal(s, 0);
  const Vec3 w3 = n0.cross(u3).normalized();
  Rigid start;
  start.R.col(0) = u3 * u2.x() + w3 * v2.x();
  start.R.col(1) = u3 * u2.y() + w3 * v2.y();
  start.R.col(2) = start.R.col(0).cross(start.R.col(1));
  start.t = anchorB ? Vec3(s[0].xb - start(s[0].pb)) : Vec3(s[0].xa - start(s[0].pa));

  std::vector<double> angles = foldAngles(s);

  std::vector<Rigid> motions = foldMotions(s, start, angles);
  Eigen::Matrix<double, 6, 1> r = closureResidual(s, motions.back());
  double lambda = 1e-6;
  for (int iteration = 0; iteration < 8 && r.norm() > 1e-12; ++iteration) {
    const Vec3 endA = motions.back()(s.back().pa), endB = motions.back()(s.back().pb);
    std::vector<Eigen::Matrix<double, 6, 1>> columns;
    Eigen::Matrix<double, 6, 6> JJt = Eigen::Matrix<double, 6, 6>::Zero();
    for (std::size_t j = 1; j + 1 < m; ++j) {
      const Vec3 q = motions[j](s[j].pa);
      const Vec3 u = (motions[j](s[j].pb) - q).normalized();
      Eigen::Matrix<double, 6, 1> c;
      c.head<3>() = u.cross(endA - q);
      c.tail<3>() = u.cross(endB - q);
      columns.push_back(c);
      JJt += c * c.transpose();
    }
    const double scale = std::max(JJt.trace() / 6.0, 1e-30);
    bool improved = false;
    while (lambda <= 1e6) {
      const Eigen::Matrix<double, 6, 6> A =
          JJt + lambda * scale * Eigen::Matrix<double, 6, 6>::Identity();
      const Eigen::Matrix<double, 6, 1> y = A.ldlt().solve(r);
      std::vector<double> trial = angles;
      for (std::size_t j = 0; j < columns.size(); ++j) trial[j] += columns[j].dot(y);
      std::vector<Rigid> trialMotions = foldMotions(s, start, trial);
      const Eigen::Matrix<double, 6, 1> rt = closureResidual(s, trialMotions.back());
      if (rt.allFinite() && rt.norm() < r.norm()) {
        angles = std::move(trial), motions = std::move(trialMotions), r = rt;
        lambda = std::max(lambda / 10.0, 1e-9);
        improved = true;
        break;
      }
      lambda *= 10.0;
    }
    if (!improved) break;
  }
  // What the folds cannot reach, blended linearly along the run: the first
  // ruling's length error and the closure left at the last.
  const Vec3 e0a = s[0].xa - start(s[0].pa), e0b = s[0].xb - start(s[0].pb);
  const Vec3 ema = r.head<3>(), emb = r.tail<3>();
  for (std::size_t j = 1; j + 1 < m; ++j) {
    const double w = static_cast<double>(j) / static_cast<double>(m - 1);
    s[j].xa = motions[j](s[j].pa) + (1.0 - w) * e0a + w * ema;
    s[j].xb = motions[j](s[j].pb) + (1.0 - w) * e0b + w * emb;
    if (!s[j].xa.allFinite() || !s[j].xb.allFinite()) {
      result.closure = std::numeric_limits<double>::infinity();
      return result;
    }
  }
  result.closure = std::max({e0a.norm(), e0b.norm(), ema.norm(), emb.norm()});
  for (double a : angles) result.largestFold = std::max(result.largestFold, std::abs(a));
  result.angles = std::move(angles);
  return result;
}

}  // namespace crumple::mesh::developable
