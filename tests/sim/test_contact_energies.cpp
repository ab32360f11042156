// The contact energies of the elastic step (sim/contact_energies.hpp)
// against finite differences over generated inputs: a vertex's penalty
// against a plane and a triangle, its lagged friction on both sides of the
// smoothing width, and a probe's penalty on a triangle's point.
#include <gtest/gtest.h>

#include <functional>

#include "crumple/sim/contact_energies.hpp"
#include "fd_check.hpp"

using namespace crumple;
using namespace crumple::sim;
using namespace crumple::testing;

namespace {

constexpr double kTolerance = 1e-5;
constexpr double kDistance = 1e-4;  // the contact distance (a paper thickness)

// A vertex contact with a random plane, the vertex a little inside it.
VertexContact randomPlane(Random& r) {
  VertexContact c;
  c.point = r.vec3(0.01);
  c.normal = r.vec3(1.0).normalized();
  c.motion = r.vec3(1e-4);
  c.mu = r.uniform(0.1, 0.8);
  c.lambda = r.uniform(0.01, 1.0);
  c.k = r.uniform(10.0, 1e4);
  return c;
}

TEST(ContactEnergies, APlanePenaltyMatchesFiniteDifferencesAndIsZeroOutside) {
  Random r(21);
  for (int trial = 0; trial < 8; ++trial) {
    const VertexContact c = randomPlane(r);
    Vec3 along = r.vec3(1e-3);
    along -= c.normal * c.normal.dot(along);  // anywhere on the plane, inside the distance
    const Vec3 x = c.point + r.uniform(0.1, 0.9) * kDistance * c.normal + along;
    const auto energy = [&](const Vec3& y) {
      double e = 0.0;
      return c.penalty(y, kDistance, e, nullptr, nullptr) ? e : 0.0;
    };
    const auto gradient = [&](const Vec3& y) {
      double e = 0.0;
      Vec3 g = Vec3::Zero();
      (void)c.penalty(y, kDistance, e, &g, nullptr);
      return g;
    };
    double e = 0.0;
    Vec3 g;
    Mat3 h;
    ASSERT_TRUE(c.penalty(x, kDistance, e, &g, &h)) << trial;
    const double gap = kDistance - c.normal.dot(x - c.point);
    EXPECT_NEAR(e, 0.5 * c.k * gap * gap, 1e-15);
    const double eps = 1e-8;
    EXPECT_LT(relativeError(g, fdGradient<3>(energy, x, eps), 1e-12), kTolerance) << trial;
    EXPECT_LT(relativeError(h, fdHessian<3>(gradient, x, eps), 1e-12), kTolerance) << trial;
    // Beyond the contact distance: no energy, nothing written.
    double untouched = -1.0;
    EXPECT_FALSE(c.penalty(c.point + 2.0 * kDistance * c.normal, kDistance, untouched, &g, &h));
    EXPECT_EQ(untouched, -1.0);
  }
}

// Against a triangle the Hessian is Gauss-Newton: its gradient is exact,
// and its Hessian is the outer product of the push direction.
TEST(ContactEnergies, ATrianglePenaltyHasTheExactGradientAndAGaussNewtonHessian) {
  Random r(22);
  for (int trial = 0; trial < 8; ++trial) {
    VertexContact c = randomPlane(r);
    c.toTriangle = true;
    c.triangle = {Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0)};
    // Above the triangle's inside or beside an edge, within the distance.
    const Vec3 x = trial % 2 == 0 ? Vec3(0.002, 0.003, 0.5 * kDistance)
                                  : Vec3(-0.3 * kDistance, 0.004, 0.4 * kDistance);
    const auto energy = [&](const Vec3& y) {
      double e = 0.0;
      return c.penalty(y, kDistance, e, nullptr, nullptr) ? e : 0.0;
    };
    double e = 0.0;
    Vec3 g;
    Mat3 h;
    ASSERT_TRUE(c.penalty(x, kDistance, e, &g, &h)) << trial;
    EXPECT_LT(relativeError(g, fdGradient<3>(energy, x, 1e-9), 1e-14), kTolerance) << trial;
    Vec3 d;
    (void)c.gap(x, kDistance, &d);
    EXPECT_LT((h - c.k * d * d.transpose()).norm(), 1e-9 * c.k) << trial;
    EXPECT_NEAR(d.norm(), 1.0, 1e-12);
  }
}

// Friction: below the smoothing width eps a capped spring, above it mu
// lambda |u|; gradient and Hessian exact on both sides.
TEST(ContactEnergies, LaggedFrictionMatchesFiniteDifferencesOnBothSidesOfItsWidth) {
  Random r(23);
  const double width = 1e-5;
  for (int trial = 0; trial < 12; ++trial) {
    const VertexContact c = randomPlane(r);
    const Vec3 start = r.vec3(0.01);
    // Tangential displacements of 0.3 and 3 widths.
    Vec3 t = r.vec3(1.0);
    t -= c.normal * c.normal.dot(t);
    const double slide = (trial % 2 == 0 ? 0.3 : 3.0) * width;
    const Vec3 x = start + c.motion + slide * t.normalized() + 1e-6 * c.normal;
    const auto energy = [&](const Vec3& y) {
      return c.friction(y, start, width, nullptr, nullptr);
    };
    const auto gradient = [&](const Vec3& y) {
      Vec3 g = Vec3::Zero();
      (void)c.friction(y, start, width, &g, nullptr);
      return g;
    };
    Vec3 g;
    Mat3 h;
    const double e = c.friction(x, start, width, &g, &h);
    if (trial % 2 == 1) {
      EXPECT_NEAR(e, c.mu * c.lambda * slide, 1e-9 * e) << trial;
    }
    const double eps = 1e-9;
    EXPECT_LT(relativeError(g, fdGradient<3>(energy, x, eps), 1e-12), kTolerance) << trial;
    EXPECT_LT(relativeError(h, fdHessian<3>(gradient, x, eps), 1e-9), kTolerance) << trial;
    // Normal motion costs nothing.
    EXPECT_NEAR(c.normal.dot(g), 0.0, 1e-9 * g.norm() + 1e-15);
  }
}

TEST(ContactEnergies, AProbePenaltyOnATrianglesPointMatchesFiniteDifferences) {
  Random r(24);
  for (int trial = 0; trial < 8; ++trial) {
    FaceContact c;
    const double w0 = r.uniform(0.1, 0.8), w1 = r.uniform(0.05, 0.9 - w0);
    c.w = {w0, w1, 1.0 - w0 - w1};
    c.normal = r.vec3(1.0).normalized();
    c.radius = r.uniform(0.001, 0.01);
    c.k = r.uniform(10.0, 1e4);
    Vec9 x;
    for (int a = 0; a < 3; ++a) x.segment<3>(3 * a) = r.vec3(0.01);
    const Vec3 q = c.w[0] * x.segment<3>(0) + c.w[1] * x.segment<3>(3) + c.w[2] * x.segment<3>(6);
    c.probe = q - (c.radius + 0.5 * kDistance) * c.normal;  // half the distance inside
    const auto energy = [&](const Vec9& y) {
      double e = 0.0;
      return c.penalty(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), kDistance, e, nullptr,
                       nullptr)
                 ? e
                 : 0.0;
    };
    const auto gradient = [&](const Vec9& y) {
      double e = 0.0;
      Vec9 g = Vec9::Zero();
      (void)c.penalty(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), kDistance, e, &g, nullptr);
      return g;
    };
    double e = 0.0;
    Vec9 g;
    Mat9 h;
    ASSERT_TRUE(c.penalty(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), kDistance, e, &g, &h));
    EXPECT_NEAR(e, 0.5 * c.k * 0.25 * kDistance * kDistance, 1e-9 * e);
    const double eps = 1e-8;
    EXPECT_LT(relativeError(g, fdGradient<9>(energy, x, eps), 1e-12), kTolerance) << trial;
    EXPECT_LT(relativeError(h, fdHessian<9>(gradient, x, eps), 1e-12), kTolerance) << trial;
  }
}

}  // namespace
