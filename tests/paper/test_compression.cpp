#include <gtest/gtest.h>

#include <cmath>

#include "crumple/paper/compression.hpp"

using crumple::Vec2;
using crumple::Vec3;
using crumple::paper::analyzeCompression;
using crumple::paper::edgeCompression;

namespace {

const std::array<Vec2, 3> kPattern{Vec2(0.0, 0.0), Vec2(0.02, 0.0), Vec2(0.005, 0.015)};

// Embeds a 2D point of a linearly deformed pattern in 3D with a rotation.
Vec3 embed(const Eigen::Matrix2d& f, const Vec2& p, const Eigen::Matrix3d& rot) {
  const Vec2 q = f * p;
  return rot * Vec3(q.x(), q.y(), 0.0);
}

}  // namespace

TEST(Compression, RigidMotionIsNotCompressed) {
  const Eigen::Matrix3d rot =
      Eigen::AngleAxisd(0.7, Vec3(1.0, 2.0, 0.5).normalized()).toRotationMatrix();
  std::array<Vec3, 3> x;
  for (int k = 0; k < 3; ++k)
    x[k] = rot * Vec3(kPattern[k].x(), kPattern[k].y(), 0.0) + Vec3(1.0, -2.0, 3.0);
  const auto c = analyzeCompression(kPattern, x);
  EXPECT_NEAR(c.lambdaMin, 1.0, 1e-12);
  EXPECT_NEAR(c.lambdaMax, 1.0, 1e-12);
  EXPECT_NEAR(c.ratio(), 0.0, 1e-12);
}

TEST(Compression, FindsDirectionAndRatioOfAnyUniaxialCompression) {
  const Eigen::Matrix3d rot =
      Eigen::AngleAxisd(-1.1, Vec3(0.3, -0.2, 1.0).normalized()).toRotationMatrix();
  for (double angle : {0.0, 0.4, 1.2, 2.0, 2.9}) {
    const Vec2 d(std::cos(angle), std::sin(angle));
    // Compress by 3% along d, stretch nothing across.
    const Eigen::Matrix2d f = Eigen::Matrix2d::Identity() - 0.03 * d * d.transpose();
    std::array<Vec3, 3> x;
    for (int k = 0; k < 3; ++k) x[k] = embed(f, kPattern[k], rot);
    const auto c = analyzeCompression(kPattern, x);
    EXPECT_NEAR(c.ratio(), 0.03, 1e-12) << angle;
    EXPECT_NEAR(c.lambdaMax, 1.0, 1e-12) << angle;
    EXPECT_NEAR(std::abs(c.v.dot(d)), 1.0, 1e-9) << angle;      // v: maximal compression
    EXPECT_NEAR(std::abs(c.vPerp.dot(d)), 0.0, 1e-9) << angle;  // v-perp orthogonal
    EXPECT_NEAR(c.v.norm(), 1.0, 1e-12);
  }
}

TEST(Compression, BiaxialTakesTheLargerCompression) {
  Eigen::Matrix2d f;
  f << 0.99, 0.0, 0.0, 0.95;
  std::array<Vec3, 3> x;
  for (int k = 0; k < 3; ++k) x[k] = embed(f, kPattern[k], Eigen::Matrix3d::Identity());
  const auto c = analyzeCompression(kPattern, x);
  EXPECT_NEAR(c.ratio(), 0.05, 1e-12);
  EXPECT_NEAR(std::abs(c.v.y()), 1.0, 1e-9);
  EXPECT_NEAR(c.lambdaMax, 0.99, 1e-12);
}

TEST(Compression, DegeneratePatternThrows) {
  const std::array<Vec2, 3> flat{Vec2(0, 0), Vec2(1, 0), Vec2(2, 0)};
  EXPECT_THROW(analyzeCompression(flat, {Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY()}),
               std::invalid_argument);
}

TEST(Compression, EdgeCompressionSign) {
  EXPECT_NEAR(edgeCompression(Vec2(0, 0), Vec2(1, 0), Vec3(0, 0, 0), Vec3(0, 0.99, 0)), 0.01,
              1e-12);
  EXPECT_NEAR(edgeCompression(Vec2(0, 0), Vec2(1, 0), Vec3(0, 0, 0), Vec3(0, 0, 1.02)), -0.02,
              1e-12);
}
