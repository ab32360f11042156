// The 3D boundary curve of the sheet outline (paper Sec. 6.2: new ruling
// endpoints are reported on the boundary curve by cubic interpolation).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/paper/boundary_curve.hpp"

using crumple::Vec2;
using crumple::Vec3;
using crumple::paper::BoundaryCurve;
using crumple::paper::BoundarySample;

namespace {

constexpr double kPi = std::numbers::pi;

std::string sci(double v) {
  std::ostringstream out;
  out.precision(3);
  out << std::scientific << v;
  return out.str();
}

// A circle of radius r, tilted, parametrized by arc length.
Vec3 circle(double s, double r) {
  const double a = s / r;
  const Vec3 p(r * std::cos(a), r * std::sin(a), 0.0);
  return Eigen::AngleAxisd(0.3, Vec3(1.0, 0.5, 0.0).normalized()) * p + Vec3(0.2, -0.1, 0.4);
}

// Samples at n parameters of [0, perimeter), jittered deterministically so
// the spacing is not uniform.
template <class F>
std::vector<BoundarySample> sampleCurve(F f, double perimeter, int n, double jitter = 0.3) {
  std::vector<BoundarySample> out;
  for (int k = 0; k < n; ++k) {
    const double u = (k + jitter * std::sin(1.7 * k)) / n;
    const double s = u * perimeter;
    out.push_back({s, f(s)});
  }
  return out;
}

template <class F>
double maxError(const BoundaryCurve& curve, F f, double lo, double hi, int n = 4000) {
  double worst = 0.0;
  for (int k = 0; k <= n; ++k) {
    const double s = lo + (hi - lo) * k / n;
    worst = std::max(worst, (curve.evaluate(s) - f(s)).norm());
  }
  return worst;
}

}  // namespace

TEST(BoundaryCurve, ExactAtSamples) {
  const double r = 0.05;
  const double perimeter = 2.0 * kPi * r;
  const auto f = [r](double s) -> Vec3 {
    return circle(s, r) + Vec3(0.0, 0.0, 0.01 * std::sin(3.0 * s / r));
  };
  const auto samples = sampleCurve(f, perimeter, 17);
  const BoundaryCurve curve(samples, perimeter);
  EXPECT_EQ(curve.sampleCount(), 17u);
  double worst = 0.0;
  for (const BoundarySample& sample : samples)
    worst = std::max(worst, (curve.evaluate(sample.s) - sample.position).norm());
  RecordProperty("max_error_at_samples_m", sci(worst));
  EXPECT_LE(worst, 1e-15);
}

TEST(BoundaryCurve, ReproducesCircleWithThirdOrderConvergence) {
  const double r = 0.05;
  const double perimeter = 2.0 * kPi * r;
  const auto f = [r](double s) { return circle(s, r); };
  std::vector<double> errors;
  for (int n : {32, 64, 128, 256}) {
    const BoundaryCurve curve(sampleCurve(f, perimeter, n), perimeter);
    errors.push_back(maxError(curve, f, 0.0, perimeter));
  }
  RecordProperty("circle_error_256_m", sci(errors.back()));
  // Dense samples (spacing 1.2 mm on a 5 cm circle): well under a micron.
  EXPECT_LT(errors.back(), 1e-7);
  for (std::size_t k = 1; k < errors.size(); ++k) {
    const double order = std::log2(errors[k - 1] / errors[k]);
    EXPECT_GT(order, 2.7) << "n = " << (32 << k);
  }
}

TEST(BoundaryCurve, ReproducesHelixPieceBetweenBreaks) {
  // A helix over [0, 0.3] m of arc length, closed by the wrap chord back to
  // its start; s = 0 is a break (a corner), so the helix is reproduced up to
  // both of its ends.
  const double radius = 0.03;
  const double pitch = 0.02;
  const double c = std::sqrt(radius * radius + pitch * pitch / (4.0 * kPi * kPi));
  const auto helix = [&](double s) {
    const double t = s / c;
    return Vec3(radius * std::cos(t), radius * std::sin(t), pitch * t / (2.0 * kPi));
  };
  const double length = 0.3;
  std::vector<BoundarySample> samples;
  const int n = 200;
  for (int k = 0; k <= n; ++k) samples.push_back({length * k / n, helix(length * k / n)});
  const double perimeter = length + (helix(length) - helix(0.0)).norm();
  const std::vector<double> breaks{0.0, length};
  const BoundaryCurve curve(samples, perimeter, breaks);
  // Spacing 1.5 mm on a helix of curvature radius 3.3 cm: O(h^3) error,
  // largest next to the breaks where the tangents are one-sided.
  const double err = maxError(curve, helix, 0.0, length);
  const double errInterior = maxError(curve, helix, 0.05, length - 0.05);
  RecordProperty("helix_error_m", sci(err));
  RecordProperty("helix_error_interior_m", sci(errInterior));
  EXPECT_LT(err, 1e-6);
  EXPECT_LT(errInterior, 2e-7);
  // The closing piece is the straight chord (both ends are breaks with a
  // single interval between them).
  const Vec3 mid = curve.evaluate(length + 0.5 * (perimeter - length));
  EXPECT_LT((mid - 0.5 * (helix(length) + helix(0.0))).norm(), 1e-12);
}

TEST(BoundaryCurve, PeriodicWrap) {
  const double r = 0.04;
  const double perimeter = 2.0 * kPi * r;
  const auto f = [r](double s) { return circle(s, r); };
  const BoundaryCurve curve(sampleCurve(f, perimeter, 64), perimeter);
  for (double s : {0.0, 0.01, 0.1, 0.2, perimeter - 1e-4}) {
    EXPECT_LT((curve.evaluate(s + perimeter) - curve.evaluate(s)).norm(), 1e-13) << s;
    EXPECT_LT((curve.evaluate(s - 3.0 * perimeter) - curve.evaluate(s)).norm(), 1e-13) << s;
  }
  // Across the wrap (between the last sample and the first) the curve is
  // as accurate and as smooth as anywhere else.
  const double err = maxError(curve, f, perimeter - 0.02, perimeter + 0.02);
  EXPECT_LT(err, 2e-6);
  const Vec3 left = curve.derivative(perimeter - 1e-9);
  const Vec3 right = curve.derivative(1e-9);
  EXPECT_LT((left - right).norm(), 1e-6);
  // Samples given with s outside [0, perimeter) are wrapped.
  std::vector<BoundarySample> shifted = sampleCurve(f, perimeter, 64);
  for (BoundarySample& sample : shifted) sample.s += 2.0 * perimeter;
  const BoundaryCurve again(shifted, perimeter);
  for (double s : {0.0, 0.05, 0.2})
    EXPECT_LT((again.evaluate(s) - curve.evaluate(s)).norm(), 1e-12);
}

TEST(BoundaryCurve, BreaksKeepCornersSharpAndSidesExact) {
  // A 10 cm square bent in 3D: every side is a parabola in s. With the
  // corners as breaks each side is reproduced exactly (the one-sided and
  // Bessel tangents are exact on parabolas); without, the kink rings.
  const double side = 0.1;
  const double perimeter = 4.0 * side;
  const auto f = [side](double s) {
    const int k = std::min(3, static_cast<int>(s / side));
    const double u = s - k * side;
    const Vec3 origin[4] = {Vec3(0, 0, 0), Vec3(side, 0, 0), Vec3(side, side, 0), Vec3(0, side, 0)};
    const Vec3 dir[4] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0)};
    return Vec3(origin[k] + u * dir[k] + Vec3(0.0, 0.0, 2.0 * u * (side - u)));
  };
  std::vector<BoundarySample> samples;
  for (int k = 0; k < 4; ++k) {
    for (double u : {0.0, 0.03, 0.07}) samples.push_back({k * side + u, f(k * side + u)});
  }
  const std::vector<double> corners{0.0, side, 2.0 * side, 3.0 * side};
  const BoundaryCurve sharp(samples, perimeter, corners);
  const BoundaryCurve smooth(samples, perimeter);
  const double errSharp = maxError(sharp, f, 0.0, perimeter - 1e-12);
  const double errSmooth = maxError(smooth, f, 0.0, perimeter - 1e-12);
  RecordProperty("square_error_with_breaks_m", sci(errSharp));
  RecordProperty("square_error_without_breaks_m", sci(errSmooth));
  EXPECT_LT(errSharp, 1e-12);
  EXPECT_GT(errSmooth, 1e-4);
}

TEST(BoundaryCurve, FromMeshTakesOutlineVerticesOnly) {
  crumple::paper::GeometricMesh g;
  g.outline = {Vec2(0, 0), Vec2(0.1, 0), Vec2(0.1, 0.1), Vec2(0, 0.1)};
  std::vector<Vec2> pattern{Vec2(0, 0),      Vec2(0.05, 0),   Vec2(0.1, 0), Vec2(0.1, 0.05),
                            Vec2(0.1, 0.1),  Vec2(0.05, 0.1), Vec2(0, 0.1), Vec2(0, 0.05),
                            Vec2(0.05, 0.05)};  // the last one is interior
  std::vector<Vec3> positions;
  for (const Vec2& p : pattern) positions.emplace_back(p.x(), p.y(), 0.01 * p.x());
  const BoundaryCurve curve = crumple::paper::boundaryCurveFromMesh(g, pattern, positions);
  EXPECT_EQ(curve.sampleCount(), 8u);
  EXPECT_DOUBLE_EQ(curve.perimeter(), 0.4);
  // Linear along each side between corners.
  EXPECT_LT((curve.evaluate(0.025) - Vec3(0.025, 0.0, 0.00025)).norm(), 1e-15);
  EXPECT_LT((curve.evaluate(0.125) - Vec3(0.1, 0.025, 0.001)).norm(), 1e-15);
  EXPECT_LT((curve.evaluate(0.375) - Vec3(0.0, 0.025, 0.0)).norm(), 1e-15);
}

TEST(BoundaryCurve, RejectsBadInput) {
  EXPECT_THROW(BoundaryCurve({}, 1.0), std::invalid_argument);
  EXPECT_THROW(BoundaryCurve({{0.0, Vec3::Zero()}}, 0.0), std::invalid_argument);
  EXPECT_THROW(BoundaryCurve({{0.0, Vec3::Zero()}, {1.0, Vec3(1, 0, 0)}}, 1.0),
               std::invalid_argument);  // s = 0 twice, two positions
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(BoundaryCurve({{0.0, Vec3(nan, 0, 0)}}, 1.0), crumple::NumericalError);
  const BoundaryCurve one({{0.3, Vec3(1, 2, 3)}}, 1.0);
  EXPECT_EQ(one.evaluate(0.7), Vec3(1, 2, 3));
  EXPECT_THROW(one.evaluate(nan), crumple::NumericalError);
}
