// The structure overlay of the OSMesa preview (the --debug-structure view):
// region colours per triangle, rulings and borders as lines, singular,
// junction and handle vertices as points. CRUMPLE_RENDER_DUMP=1 writes the
// images into the build directory; CRUMPLE_BLESS=1 rewrites the golden image.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "crumple/render/osmesa_renderer.hpp"
#include "render_test_scenes.hpp"
#include "render_test_util.hpp"

namespace crumple::render {
namespace {

using namespace test;  // the shared scenes and helpers

// Pattern (u, v) on flatSheet(y) -> world.
Vec3 onFlatSheet(double u, double v, double y = 0.0) {
  return Vec3(u - 0.5 * kSheetWidth, y, 0.5 * kSheetHeight - v);
}

// The sheet seen from straight above, lit from above, plain white paper.
RenderScene topScene(int w, int h) {
  RenderScene s;
  s.camera = topCamera(0.6, w, h);
  Light l;
  l.direction = Vec3(-0.2, -1.0, -0.1);
  s.lights = {l};
  ImageRGBA8 white(1, 1);
  std::fill(white.pixels.begin(), white.pixels.end(), std::uint8_t{255});
  s.paper.texture = white;
  return s;
}

std::array<int, 3> srgb(const Vec3& c) {
  return {linearToSrgb8(c.x()), linearToSrgb8(c.y()), linearToSrgb8(c.z())};
}

// Largest channel difference between a pixel and an 8-bit sRGB colour.
int colorDistance(const std::uint8_t* p, const std::array<int, 3>& c) {
  int d = 0;
  for (std::size_t k = 0; k < 3; ++k) d = std::max(d, std::abs(int(p[k]) - c[k]));
  return d;
}

double luma(const std::uint8_t* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

// Distance from q to the segment a-b (pixels).
double segmentDistance(const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - q).norm();
}

const StructurePalette kPalette;

// The ruling drawn horizontally from a to b covers lineWidthPx (4) pixels
// across, column by column: img against the plain render.
void expectRulingLineWidth(const Camera& camera, const Vec3& a, const Vec3& b,
                           const ImageRGBA8& plain, const ImageRGBA8& img) {
  const auto pa = projectToPixel(camera, a), pb = projectToPixel(camera, b);
  ASSERT_TRUE(pa && pb);
  const int y0 = static_cast<int>(pa->y());
  const auto line = srgb(kPalette.ruling);
  for (int x = static_cast<int>(pa->x()) + 3; x < static_cast<int>(pb->x()) - 3; x += 5) {
    double coverage = 0.0;
    for (int y = y0 - 6; y <= y0 + 6; ++y) {
      const double base = plain.at(x, y)[1], drawn = img.at(x, y)[1];
      coverage += (base - drawn) / (base - line[1]);  // green: paper high, line 0
    }
    EXPECT_NEAR(coverage, 4.0, 0.3) << "column " << x;
  }
}

// The 200 x 150 view from above onto the flat test sheet that most property
// tests below share, with an empty overlay to fill in.
class StructureOverlayTopView : public ::testing::Test {
 protected:
  static constexpr int w = 200, h = 150;
  OsmesaRenderer r{w, h};
  RenderScene scene = topScene(w, h);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  StructureOverlay o;
};

TEST_F(StructureOverlayTopView, PointPixelHasThePointsColour) {
  const std::array<Vec3, 3> where = {onFlatSheet(0.05, 0.10), onFlatSheet(0.15, 0.20),
                                     onFlatSheet(0.10, 0.05)};
  const std::array<Vec3, 3> colors = {kPalette.singular, kPalette.junction, kPalette.handle};
  for (std::size_t i = 0; i < 3; ++i) o.points.push_back({where[i], colors[i]});
  const ImageRGBA8 img = r.render(scene, sheet, &o);
  maybeDump("overlay_points", img);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_LE(colorDistance(pixelAt(img, scene.camera, where[i]), srgb(colors[i])), 1) << i;

  // Its size: the black (handle) disc covers pi r^2 pixels.
  const ImageRGBA8 plain = r.render(scene, sheet);
  const auto c = projectToPixel(scene.camera, where[2]);
  ASSERT_TRUE(c.has_value());
  double coverage = 0.0;
  for (int y = static_cast<int>(c->y()) - 8; y <= static_cast<int>(c->y()) + 8; ++y)
    for (int x = static_cast<int>(c->x()) - 8; x <= static_cast<int>(c->x()) + 8; ++x)
      coverage += 1.0 - luma(img.at(x, y)) / luma(plain.at(x, y));
  const double radius = 0.5 * o.pointSizePx;
  EXPECT_NEAR(coverage, std::numbers::pi * radius * radius, 2.0);
}

TEST_F(StructureOverlayTopView, PointsBehindThePaperAreHidden) {
  const Vec3 below = onFlatSheet(0.10, 0.15, -0.02);  // 2 cm under the sheet
  const Vec3 above = onFlatSheet(0.05, 0.15, 0.0);    // on it
  o.points = {{below, kPalette.singular}, {above, kPalette.singular}};
  const ImageRGBA8 img = r.render(scene, sheet, &o);
  const ImageRGBA8 plain = r.render(scene, sheet);
  const std::uint8_t* p = pixelAt(img, scene.camera, below);
  const std::uint8_t* q = pixelAt(plain, scene.camera, below);
  EXPECT_TRUE(std::equal(p, p + 4, q)) << "hidden point drawn";
  EXPECT_LE(colorDistance(pixelAt(img, scene.camera, above), srgb(kPalette.singular)), 1);
}

TEST_F(StructureOverlayTopView, LineMidpointHasTheLinesColourAndItsWidth) {
  o.lineWidthPx = 4.0;
  // Horizontal in the image (world X), and a diagonal one.
  const Vec3 a = onFlatSheet(0.03, 0.2), b = onFlatSheet(0.18, 0.2);
  const Vec3 c = onFlatSheet(0.03, 0.03), d = onFlatSheet(0.18, 0.15);
  o.lines = {{a, b, kPalette.ruling}, {c, d, kPalette.border}};
  const ImageRGBA8 img = r.render(scene, sheet, &o);
  const ImageRGBA8 plain = r.render(scene, sheet);
  maybeDump("overlay_lines", img);
  EXPECT_LE(colorDistance(pixelAt(img, scene.camera, 0.5 * (a + b)), srgb(kPalette.ruling)), 1);
  EXPECT_LE(colorDistance(pixelAt(img, scene.camera, 0.5 * (c + d)), srgb(kPalette.border)), 1);

  // Coverage across the horizontal line, column by column: lineWidthPx.
  expectRulingLineWidth(scene.camera, a, b, plain, img);
}

TEST(StructureOverlay, LinesStayWholeOnATiltedSurfaceAndHiddenBehindThePaper) {
  const int w = 200, h = 150;
  OsmesaRenderer r(w, h);
  const RenderScene scene = topScene(w, h);
  // The sheet turned 65 degrees about X: its depth changes fast across a line
  // along X, the worst case for a line's depth offset.
  mesh::SheetMesh sheet = flatSheet(0.0);
  const double angle = 65.0 * std::numbers::pi / 180.0;
  const Mat3 rot = Eigen::AngleAxisd(angle, Vec3::UnitX()).toRotationMatrix();
  for (Vec3& p : sheet.positions) p = rot * p;
  StructureOverlay o;
  o.lineWidthPx = 4.0;
  const Vec3 a = rot * Vec3(-0.06, 0.0, 0.05), b = rot * Vec3(0.06, 0.0, 0.05);
  // 3 cm under the sheet, seen through it.
  const Vec3 hiddenA = rot * Vec3(-0.06, -0.03, -0.05), hiddenB = rot * Vec3(0.06, -0.03, -0.05);
  o.lines = {{a, b, kPalette.ruling}, {hiddenA, hiddenB, kPalette.ruling}};
  const ImageRGBA8 img = r.render(scene, sheet, &o);
  const ImageRGBA8 plain = r.render(scene, sheet);
  maybeDump("overlay_tilted", img);
  expectRulingLineWidth(scene.camera, a, b, plain, img);
  const auto ph = projectToPixel(scene.camera, 0.5 * (hiddenA + hiddenB));
  ASSERT_TRUE(ph.has_value());
  for (int y = static_cast<int>(ph->y()) - 4; y <= static_cast<int>(ph->y()) + 4; ++y)
    for (int x = static_cast<int>(ph->x()) - 20; x <= static_cast<int>(ph->x()) + 20; ++x)
      ASSERT_TRUE(std::equal(img.at(x, y), img.at(x, y) + 4, plain.at(x, y)))
          << "hidden line drawn at " << x << "," << y;
}

TEST_F(StructureOverlayTopView, TriangleColoursReplaceThePaperAndKeepTheShading) {
  o.triangleColors.assign(sheet.triangleCount(), kPalette.flat);
  const ImageRGBA8 img = r.render(scene, sheet, &o);
  maybeDump("overlay_green", img);
  int checked = 0;
  for (double u = 0.01; u < kSheetWidth - 0.01; u += 0.005)
    for (double v = 0.01; v < kSheetHeight - 0.01; v += 0.005) {
      const std::uint8_t* p = pixelAt(img, scene.camera, onFlatSheet(u, v));
      ASSERT_GT(p[1], p[0] + 40) << u << "," << v;
      ASSERT_GT(p[1], p[2] + 40) << u << "," << v;
      ++checked;
    }
  EXPECT_GT(checked, 1000);

  // Two-sided: green from below too.
  RenderScene below = scene;
  below.camera = Camera::lookAt(Vec3(0, -0.6, 0), Vec3::Zero(), -Vec3::UnitZ(), 0.7, w, h);
  below.lights[0].direction = Vec3(0.1, 1.0, 0.2);
  const ImageRGBA8 fromBelow = r.render(below, sheet, &o);
  const std::uint8_t* p = fromBelow.at(w / 2, h / 2);
  EXPECT_GT(p[1], p[0] + 40);
  EXPECT_GT(p[1], p[2] + 40);

  // Still lit: a grazing light darkens it.
  const double lit = luma(img.at(w / 2, h / 2));
  scene.lights[0].direction = Vec3(1.0, -0.3, 0.0);
  const double grazing = luma(r.render(scene, sheet, &o).at(w / 2, h / 2));
  EXPECT_LT(grazing, lit - 30.0);
}

TEST(StructureOverlay, EachTriangleGetsItsOwnColour) {
  const int w = 320, h = 240;
  OsmesaRenderer r(w, h);
  const RenderScene scene = topScene(w, h);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  StructureOverlay o;
  const std::array<Vec3, 3> rgb = {Vec3(0.8, 0.05, 0.05), Vec3(0.05, 0.8, 0.05),
                                   Vec3(0.05, 0.05, 0.8)};
  for (std::size_t t = 0; t < sheet.triangleCount(); ++t) o.triangleColors.push_back(rgb[t % 3]);
  const ImageRGBA8 img = r.render(scene, sheet, &o);
  maybeDump("overlay_triangle_ids", img);
  for (std::size_t t = 0; t < sheet.triangleCount(); ++t) {
    Vec3 centroid = Vec3::Zero();
    for (const int v : sheet.triangles[t]) centroid += sheet.positions[std::size_t(v)] / 3.0;
    const std::uint8_t* p = pixelAt(img, scene.camera, centroid);
    const auto dominant = static_cast<std::size_t>(std::max_element(p, p + 3) - p);
    ASSERT_EQ(dominant, t % 3) << "triangle " << t;
  }
}

TEST(StructureOverlay, EmptyOverlayGivesTheNormalRenderByteForByte) {
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  const RenderScene scene = bentScene(w, h);
  const mesh::SheetMesh sheet = bentSceneSheet();
  const ImageRGBA8 plain = r.render(scene, sheet);
  StructureOverlay empty;
  EXPECT_EQ(r.render(scene, sheet, &empty).pixels, plain.pixels);
  EXPECT_EQ(r.render(scene, sheet, nullptr).pixels, plain.pixels);
  // Also after an overlay render (no GL state leaks into the next frame).
  const StructureOverlay full = bentSheetStructure(sheet);
  EXPECT_NE(r.render(scene, sheet, &full).pixels, plain.pixels);
  EXPECT_EQ(r.render(scene, sheet).pixels, plain.pixels);
}

TEST(StructureOverlay, LinesAndPointsLeaveTheRestOfTheImageUntouched) {
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  const RenderScene scene = bentScene(w, h);
  const mesh::SheetMesh sheet = bentSceneSheet();
  StructureOverlay o = bentSheetStructure(sheet);
  o.triangleColors.clear();
  const ImageRGBA8 plain = r.render(scene, sheet);
  const ImageRGBA8 img = r.render(scene, sheet, &o);
  maybeDump("overlay_lines_points_only", img);
  std::vector<std::array<Vec2, 2>> segments;
  for (const auto& l : o.lines) {
    const auto a = projectToPixel(scene.camera, l.a), b = projectToPixel(scene.camera, l.b);
    ASSERT_TRUE(a && b);
    segments.push_back({*a, *b});
  }
  std::vector<Vec2> points;
  for (const auto& p : o.points) {
    const auto q = projectToPixel(scene.camera, p.p);
    ASSERT_TRUE(q.has_value());
    points.push_back(*q);
  }
  int far = 0, near = 0, changedNear = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Vec2 q(x + 0.5, y + 0.5);
      double d = std::numeric_limits<double>::infinity();
      for (const auto& s : segments) d = std::min(d, segmentDistance(q, s[0], s[1]));
      bool nearPoint = false;
      for (const Vec2& p : points) nearPoint |= (q - p).norm() < 0.5 * o.pointSizePx + 1.5;
      const bool same = std::equal(img.at(x, y), img.at(x, y) + 4, plain.at(x, y));
      if (d > 0.5 * o.lineWidthPx + 1.5 && !nearPoint) {
        ++far;
        ASSERT_TRUE(same) << "pixel " << x << "," << y << " changed away from the overlay";
      } else {
        ++near;
        changedNear += !same;
      }
    }
  EXPECT_GT(far, w * h / 2);
  EXPECT_GT(changedNear, near / 4);
}

TEST_F(StructureOverlayTopView, PointsAreDrawnOverLines) {
  o.lineWidthPx = 6.0;
  const Vec3 a = onFlatSheet(0.03, 0.15), b = onFlatSheet(0.18, 0.15);
  o.points = {{0.5 * (a + b), kPalette.junction}};  // listed first, drawn last
  o.lines = {{a, b, kPalette.ruling}};
  const ImageRGBA8 img = r.render(scene, sheet, &o);
  EXPECT_LE(colorDistance(pixelAt(img, scene.camera, 0.5 * (a + b)), srgb(kPalette.junction)), 1);
  EXPECT_LE(colorDistance(pixelAt(img, scene.camera, 0.25 * a + 0.75 * b), srgb(kPalette.ruling)),
            1);
}

TEST(StructureOverlay, RenderingIsDeterministic) {
  const int w = 160, h = 120;
  const RenderScene scene = bentScene(w, h);
  const mesh::SheetMesh sheet = bentSceneSheet();
  const StructureOverlay o = bentSheetStructure(sheet);
  OsmesaRenderer r(w, h);
  const ImageRGBA8 a = r.render(scene, sheet, &o);
  EXPECT_EQ(r.render(scene, sheet, &o).pixels, a.pixels);
  OsmesaRenderer fresh(w, h);
  EXPECT_EQ(fresh.render(scene, sheet, &o).pixels, a.pixels);
  const std::string dir = std::string(CRUMPLE_RENDER_OUT_DIR);
  for (const char* threads : {"1", "3"}) {
    const std::string out = dir + "/render_dump_structure_threads" + threads + ".rgba";
    std::filesystem::remove(out);
    const std::string cmd = std::string("LP_NUM_THREADS=") + threads + " '" +
                            CRUMPLE_RENDER_DUMP_EXE + "' '" + out + "' " + std::to_string(w) + " " +
                            std::to_string(h) + " structure";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    EXPECT_EQ(test::readBytes(out), a.pixels) << "LP_NUM_THREADS=" << threads;
  }
}

TEST(StructureOverlay, RejectsBadOverlays) {
  const int w = 32, h = 24;
  OsmesaRenderer r(w, h);
  const RenderScene scene = topScene(w, h);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  const StructureOverlay good = [&] {
    StructureOverlay o;
    o.triangleColors.assign(sheet.triangleCount(), kPalette.flat);
    o.lines = {{onFlatSheet(0.0, 0.0), onFlatSheet(0.1, 0.1), kPalette.ruling}};
    o.points = {{onFlatSheet(0.1, 0.1), kPalette.singular}};
    return o;
  }();
  const double nan = std::nan("");
  StructureOverlay bad = good;
  bad.triangleColors.pop_back();
  EXPECT_THROW(r.render(scene, sheet, &bad), std::invalid_argument);
  bad = good;
  bad.triangleColors[3].y() = nan;
  EXPECT_THROW(r.render(scene, sheet, &bad), std::invalid_argument);
  bad = good;
  bad.lines[0].b.x() = nan;
  EXPECT_THROW(r.render(scene, sheet, &bad), std::invalid_argument);
  bad = good;
  bad.points[0].color.z() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(r.render(scene, sheet, &bad), std::invalid_argument);
  bad = good;
  bad.lineWidthPx = 0.0;
  EXPECT_THROW(r.render(scene, sheet, &bad), std::invalid_argument);
  bad = good;
  bad.pointSizePx = nan;
  EXPECT_THROW(r.render(scene, sheet, &bad), std::invalid_argument);
  // Still usable after rejected input.
  EXPECT_EQ(r.render(scene, sheet, &good).width, w);
}

TEST(StructureOverlay, GoldenBentSheetStructure) {
  const int w = 320, h = 240;
  OsmesaRenderer r(w, h);
  const mesh::SheetMesh sheet = bentSceneSheet();
  const StructureOverlay o = bentSheetStructure(sheet);
  const ImageRGBA8 img = r.render(bentScene(w, h), sheet, &o);
  maybeDump("structure_overlay", img);
  test::expectMatchesGolden("structure_overlay", img);
}

}  // namespace
}  // namespace crumple::render
