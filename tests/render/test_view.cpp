#include <gtest/gtest.h>

#include <cmath>

#include "crumple/render/view.hpp"

namespace crumple::render {
namespace {

TEST(CameraLookAt, TargetProjectsToImageCentre) {
  const Camera c =
      Camera::lookAt(Vec3(0.3, 0.4, 0.5), Vec3(0.0, 0.05, 0.0), Vec3::UnitY(), 0.7, 320, 200);
  EXPECT_EQ(c.width, 320);
  EXPECT_EQ(c.height, 200);
  EXPECT_DOUBLE_EQ(c.yfov, 0.7);
  EXPECT_NEAR(c.rotation.norm(), 1.0, 1e-12);
  const auto p = projectToPixel(c, Vec3(0.0, 0.05, 0.0));
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->x(), 160.0, 1e-9);
  EXPECT_NEAR(p->y(), 100.0, 1e-9);
  // World up appears up in the image (smaller row index), and the camera's
  // local -Z points at the target.
  const auto above = projectToPixel(c, Vec3(0.0, 0.15, 0.0));
  ASSERT_TRUE(above.has_value());
  EXPECT_LT(above->y(), 100.0);
  const Vec3 forward = c.rotation * -Vec3::UnitZ();
  EXPECT_NEAR(forward.dot((Vec3(0.0, 0.05, 0.0) - c.position).normalized()), 1.0, 1e-12);
}

TEST(CameraLookAt, RightHandedImageAxes) {
  // Looking down -Z from +Z with +Y up: world +X is to the right.
  const Camera c = Camera::lookAt(Vec3(0, 0, 1), Vec3::Zero(), Vec3::UnitY(), 0.7, 100, 100);
  EXPECT_TRUE(c.rotation.isApprox(Quat::Identity(), 1e-12));
  const auto right = projectToPixel(c, Vec3(0.1, 0, 0));
  ASSERT_TRUE(right.has_value());
  EXPECT_GT(right->x(), 50.0);
  EXPECT_NEAR(right->y(), 50.0, 1e-9);
}

TEST(CameraLookAt, UpParallelToViewStillWellDefined) {
  const Camera c = Camera::lookAt(Vec3(0, 1, 0), Vec3::Zero(), Vec3::UnitY(), 0.7, 64, 48);
  EXPECT_TRUE(c.rotation.coeffs().allFinite());
  const auto p = projectToPixel(c, Vec3::Zero());
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->x(), 32.0, 1e-9);
  EXPECT_NEAR(p->y(), 24.0, 1e-9);
  EXPECT_THROW(Camera::lookAt(Vec3::Zero(), Vec3::Zero(), Vec3::UnitY(), 0.7, 64, 48),
               std::invalid_argument);
}

TEST(CameraMath, PointBehindCameraDoesNotProject) {
  const Camera c = Camera::lookAt(Vec3(0, 0, 1), Vec3::Zero(), Vec3::UnitY(), 0.7, 64, 48);
  EXPECT_FALSE(projectToPixel(c, Vec3(0, 0, 2)).has_value());
}

TEST(CameraMath, FieldOfViewEdgesMapToImageEdges) {
  const double fov = 0.9;
  const Camera c = Camera::lookAt(Vec3(0, 0, 1), Vec3::Zero(), Vec3::UnitY(), fov, 200, 100);
  const double y = std::tan(0.5 * fov);  // at distance 1
  const auto top = projectToPixel(c, Vec3(0, y, 0));
  ASSERT_TRUE(top.has_value());
  EXPECT_NEAR(top->y(), 0.0, 1e-9);
  const auto rightEdge = projectToPixel(c, Vec3(2.0 * y, 0, 0));  // aspect 2
  ASSERT_TRUE(rightEdge.has_value());
  EXPECT_NEAR(rightEdge->x(), 200.0, 1e-9);
}

TEST(Srgb, EncodeDecode) {
  EXPECT_EQ(linearToSrgb8(0.0), 0);
  EXPECT_EQ(linearToSrgb8(1.0), 255);
  EXPECT_EQ(linearToSrgb8(2.0), 255);
  EXPECT_EQ(linearToSrgb8(-1.0), 0);
  EXPECT_EQ(linearToSrgb8(0.18), 118);
  EXPECT_EQ(linearToSrgb8(0.5), 188);
  for (int i = 0; i < 256; ++i)
    EXPECT_EQ(linearToSrgb8(srgb8ToLinear(static_cast<std::uint8_t>(i))), i);
}

TEST(RuledPaperTexture, DeterministicWithRulesAndMargin) {
  const ImageRGBA8 a = makeRuledPaperTexture(210, 297);
  const ImageRGBA8 b = makeRuledPaperTexture(210, 297);
  ASSERT_EQ(a.width, 210);
  ASSERT_EQ(a.height, 297);
  EXPECT_EQ(a.pixels, b.pixels);
  // Column well right of the margin: white paper and blue rules alternate,
  // none in the 30 mm header band.
  int ruleRows = 0, paperRows = 0;
  for (int y = 0; y < 297; ++y) {
    const std::uint8_t* p = a.at(150, y);
    EXPECT_EQ(p[3], 255);
    const bool blue = p[2] > p[0] + 30;
    if (blue) ++ruleRows;
    if (p[0] > 245 && p[1] > 245) ++paperRows;
    if (y < 28) {
      EXPECT_FALSE(blue) << "row " << y;
    }
  }
  EXPECT_GE(ruleRows, 30);
  EXPECT_GE(paperRows, 200);
  // The margin: a red line 30 mm from the left edge, ~1 mm wide.
  const ImageRGBA8 big = makeRuledPaperTexture(1050, 1485);  // 5 texels per mm
  int redCols = 0;
  for (int x = 0; x < big.width; ++x) {
    const std::uint8_t* p = big.at(x, 10);
    if (p[0] > p[1] + 60 && p[0] > p[2] + 60) {
      ++redCols;
      EXPECT_NEAR(x, 150, 3);
    }
  }
  EXPECT_GE(redCols, 4);
  EXPECT_LE(redCols, 6);
  EXPECT_THROW(makeRuledPaperTexture(0, 10), std::invalid_argument);
}

}  // namespace
}  // namespace crumple::render

namespace crumple::render {
namespace {

// Two triangles sharing the edge (0, 1) along X, the second one folded up by
// `fold` radians about it.
std::vector<Vec3> foldedPair(double fold) {
  return {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 0, -1),
          Vec3(0.5, std::sin(fold), std::cos(fold))};
}
const std::vector<std::array<int, 3>> kPair = {{0, 1, 2}, {1, 0, 3}};

TEST(ShadingNormals, SmoothBelowTheCreaseAngleSplitAboveIt) {
  // A 20 degree fold: below the 30 degree crease angle, the shared corners get
  // one normal halfway between the faces.
  const auto smooth = shadingNormals(foldedPair(0.349), kPair, 0.5236, {});
  EXPECT_TRUE(smooth[0][0].isApprox(smooth[1][1], 1e-12)) << "vertex 0 shared";
  EXPECT_TRUE(smooth[0][1].isApprox(smooth[1][0], 1e-12)) << "vertex 1 shared";
  EXPECT_NEAR(smooth[0][0].norm(), 1.0, 1e-12);
  const Vec3 face0(0, 1, 0);
  EXPECT_NEAR(std::acos(smooth[0][0].dot(face0)), 0.5 * 0.349, 1e-6);
  // The unshared corners keep their face normal.
  EXPECT_TRUE(smooth[0][2].isApprox(face0, 1e-12));
  // A 40 degree fold is a crease: every corner keeps its face normal.
  const auto sharp = shadingNormals(foldedPair(0.698), kPair, 0.5236, {});
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(sharp[0][static_cast<std::size_t>(k)].isApprox(face0, 1e-12));
    EXPECT_NEAR(std::acos(sharp[1][static_cast<std::size_t>(k)].dot(face0)), 0.698, 1e-6);
  }
}

TEST(ShadingNormals, NoSmoothingAroundASharpVertex) {
  const auto n = shadingNormals(foldedPair(0.349), kPair, 0.5236, {0});
  EXPECT_TRUE(n[0][0].isApprox(Vec3(0, 1, 0), 1e-12)) << "vertex 0 is sharp";
  EXPECT_FALSE(n[1][1].isApprox(n[0][0], 1e-6));
  EXPECT_TRUE(n[0][1].isApprox(n[1][0], 1e-12)) << "vertex 1 is still smooth";
}

TEST(SampleTexture, BilinearLikeGlWithRepeatAndSrgbDecodedTexels) {
  ImageRGBA8 t(2, 1);
  const std::uint8_t px[8] = {0, 0, 0, 0, 255, 255, 255, 255};
  std::copy(px, px + 8, t.pixels.begin());
  // Texel centres at u = 0.25 and 0.75.
  EXPECT_NEAR(sampleTexture(t, Vec2(0.25, 0.5)).x(), 0.0, 1e-12);
  EXPECT_NEAR(sampleTexture(t, Vec2(0.75, 0.5)).x(), 1.0, 1e-12);
  const Vec4 mid = sampleTexture(t, Vec2(0.5, 0.5));
  EXPECT_NEAR(mid.x(), 0.5, 1e-6) << "filtered in linear light";
  EXPECT_NEAR(mid.w(), 0.5, 1e-6);
  // Repeat: u = 0 lies halfway between the last texel and the first.
  EXPECT_NEAR(sampleTexture(t, Vec2(0.0, 0.5)).w(), 0.5, 1e-6);
  EXPECT_NEAR(sampleTexture(t, Vec2(1.25, 0.5)).w(), 0.0, 1e-6);
}

TEST(PaperTransmittance, FallsWithThickness) {
  EXPECT_NEAR(paperTransmittance(1e-4), std::exp(-1e-4 / 62e-6), 1e-15);
  EXPECT_GT(paperTransmittance(7e-5), paperTransmittance(1.1e-4));
  EXPECT_DOUBLE_EQ(paperTransmittance(0.0), 1.0);
  EXPECT_THROW(paperTransmittance(-1.0), std::invalid_argument);
}

}  // namespace
}  // namespace crumple::render
