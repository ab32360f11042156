// The path tracer's motion blur (RenderScene::sheetMotion, PropMesh::motion):
// a disc moving across the frame blurs to the analytic length, the sheet's
// edge to the distance it moves, a still "motion" changes nothing but noise,
// the image is the same on any thread count, and bad motion is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "crumple/core/parallel.hpp"
#include "crumple/render/embree_renderer.hpp"
#include "render_test_scenes.hpp"

namespace crumple::render {
namespace {

using namespace test;

constexpr int kW = 160, kH = 48;
constexpr double kCameraY = 0.5, kPlaneY = 0.1;

// Metres per pixel on the plane Y = kPlaneY seen by topCamera(kCameraY).
double metresPerPixel(const Camera& cam) {
  return 2.0 * (kCameraY - kPlaneY) * std::tan(0.5 * cam.yfov) / cam.height;
}

// A disc of radius r facing up at (x, kPlaneY, 0): a fan of 64 triangles.
PropMesh disc(double x, double r) {
  PropMesh p;
  p.name = "disc";
  p.vertices.push_back(Vec3(x, kPlaneY, 0.0));
  constexpr int n = 64;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * std::numbers::pi * i / n;
    p.vertices.push_back(Vec3(x + r * std::cos(a), kPlaneY, -r * std::sin(a)));
  }
  for (int i = 0; i < n; ++i) p.triangles.push_back({0, 1 + i, 1 + (i + 1) % n});
  return p;
}

// The same vertices moved by (dx, 0, 0).
std::vector<Vec3> moved(const std::vector<Vec3>& v, double dx) {
  std::vector<Vec3> out = v;
  for (Vec3& p : out) p.x() += dx;
  return out;
}

RenderScene blurScene() {
  RenderScene s;
  s.camera = topCamera(kCameraY, kW, kH);
  s.ground.enabled = false;
  s.environment.intensity = 1.0;
  return s;
}

ImageRGBAF render(const RenderScene& scene, const mesh::SheetMesh& sheet, int spp) {
  EmbreeRenderer r;
  PathTraceSettings p;
  p.samplesPerPixel = spp;
  p.maxBounces = 0;
  return r.render(scene, sheet, p);
}

// Coverage (alpha) summed over the rows, per column.
std::vector<double> columnCoverage(const ImageRGBAF& img) {
  std::vector<double> c(static_cast<std::size_t>(img.width), 0.0);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) c[static_cast<std::size_t>(x)] += img.at(x, y)[3];
  return c;
}

// Where a profile first rises through `level` and last falls through it,
// linearly between pixel centres (x + 0.5).
std::pair<double, double> crossings(const std::vector<double>& c, double level) {
  double rise = -1.0, fall = -1.0;
  for (std::size_t x = 1; x < c.size(); ++x) {
    const double a = c[x - 1], b = c[x];
    if (rise < 0.0 && a < level && b >= level) rise = x - 0.5 + (level - a) / (b - a);
    if (a >= level && b < level) fall = x - 0.5 + (a - level) / (a - b);
  }
  return {rise, fall};
}

TEST(MotionBlur, AMovingDiscBlursToTheDistanceItMoves) {
  RenderScene scene = blurScene();
  const double m = metresPerPixel(scene.camera);
  const double diameterPx = 10.0, movePx = 60.0;
  const PropMesh still = disc(-0.5 * movePx * m, 0.5 * diameterPx * m);
  PropMesh moving = still;
  // Three steps: the surfaces move linearly between them, so a uniform
  // motion stays uniform.
  moving.motion = {still.vertices, moved(still.vertices, 0.5 * movePx * m),
                   moved(still.vertices, movePx * m)};
  scene.props = {moving};
  const std::vector<double> c = columnCoverage(render(scene, mesh::SheetMesh{}, 512));
  // A disc of diameter d moving D > d: every row's coverage is a trapezoid
  // of plateau chord / D and width D at half of it, so is their sum. The
  // plateau: the mean of the middle 20 columns.
  double plateau = 0.0;
  for (int x = kW / 2 - 10; x < kW / 2 + 10; ++x) plateau += c[static_cast<std::size_t>(x)];
  plateau /= 20.0;
  const double areaPx = std::numbers::pi * 0.25 * diameterPx * diameterPx;
  EXPECT_NEAR(plateau, areaPx / movePx, 0.1 * areaPx / movePx);  // its area, spread over D
  const auto [rise, fall] = crossings(c, 0.5 * plateau);
  std::printf("[ measure ] disc of %.0f px moving %.0f px: blurred %.2f px at half maximum\n",
              diameterPx, movePx, fall - rise);
  EXPECT_NEAR(fall - rise, movePx, 1.0);
  // Still, the disc covers its own diameter.
  scene.props = {still};
  const auto [r0, f0] =
      crossings(columnCoverage(render(scene, mesh::SheetMesh{}, 64)), 0.5 * diameterPx);
  EXPECT_NEAR(f0 - r0, std::sqrt(3.0) * 0.5 * diameterPx, 1.0);  // where the chord is half
}

TEST(MotionBlur, TheSheetsEdgeSmearsOverTheDistanceItMoves) {
  RenderScene scene = blurScene();
  const double m = metresPerPixel(scene.camera);
  const double movePx = 30.0;
  // A flat sheet whose right edge is in view: moving right by D, its edge's
  // coverage ramps from 0 to 1 over D pixels (10 % to 90 %: 0.8 D).
  mesh::SheetMesh sheet = flatSheet(kPlaneY, 0.03);
  const double shift = -0.5 * kSheetWidth - 0.25 * movePx * m;  // right edge left of centre
  sheet.positions = moved(sheet.positions, shift);
  scene.sheetMotion = {sheet.positions, moved(sheet.positions, movePx * m)};
  const ImageRGBAF img = render(scene, sheet, 256);
  std::vector<double> row(static_cast<std::size_t>(kW), 0.0);
  for (int y = kH / 2 - 8; y < kH / 2 + 8; ++y)
    for (int x = 0; x < kW; ++x) row[static_cast<std::size_t>(x)] += img.at(x, y)[3] / 16.0;
  // Coverage falls from 1 to 0 left to right: cross 0.9 and 0.1 falling.
  const double at90 = crossings(row, 0.9).second, at10 = crossings(row, 0.1).second;
  std::printf("[ measure ] sheet edge moving %.0f px: 90 %% to 10 %% coverage over %.2f px\n",
              movePx, at10 - at90);
  EXPECT_NEAR(at10 - at90, 0.8 * movePx, 1.0);
  for (const float v : img.pixels) ASSERT_TRUE(std::isfinite(v));
}

TEST(MotionBlur, StillStepsChangeOnlyTheNoiseAndThreadsChangeNothing) {
  RenderScene scene = bentScene(64, 48);
  const mesh::SheetMesh sheet = bentSceneSheet();
  EmbreeRenderer r;
  PathTraceSettings p;
  p.samplesPerPixel = 64;
  const ImageRGBAF sharp = r.render(scene, sheet, p);
  scene.sheetMotion = {sheet.positions, sheet.positions};
  const ImageRGBAF still = r.render(scene, sheet, p);
  double diff = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < sharp.pixels.size(); ++i) {
    diff += std::abs(still.pixels[i] - sharp.pixels[i]);
    sum += sharp.pixels[i];
  }
  EXPECT_NE(still.pixels, sharp.pixels);  // other sample streams (the time pair)
  EXPECT_LT(diff / sum, 0.05);            // the same picture
  scene.sheetMotion = {sheet.positions, moved(sheet.positions, 0.01)};
  const int saved = threadCount();
  setThreadCount(1);
  const ImageRGBAF one = r.render(scene, sheet, p);
  setThreadCount(2);
  const ImageRGBAF two = r.render(scene, sheet, p);
  setThreadCount(saved);
  EXPECT_EQ(one.pixels, two.pixels);
}

TEST(MotionBlur, InconsistentMotionIsRefused) {
  RenderScene scene = blurScene();
  const mesh::SheetMesh sheet = flatSheet(kPlaneY, 0.05);
  EmbreeRenderer r;
  PathTraceSettings p;
  scene.sheetMotion = {sheet.positions};  // one step: no motion to blur
  EXPECT_THROW(r.render(scene, sheet, p), std::invalid_argument);
  scene.sheetMotion = {sheet.positions, std::vector<Vec3>(sheet.positions.size() - 1)};
  EXPECT_THROW(r.render(scene, sheet, p), std::invalid_argument);
  scene.sheetMotion = {sheet.positions, sheet.positions};
  scene.sheetMotion[1][3].x() = std::nan("");
  EXPECT_THROW(r.render(scene, sheet, p), std::invalid_argument);
  scene.sheetMotion = {sheet.positions, sheet.positions};
  PropMesh prop = disc(0.0, 0.01);
  prop.motion = {prop.vertices, prop.vertices, prop.vertices};  // 3 steps against the sheet's 2
  scene.props = {prop};
  EXPECT_THROW(r.render(scene, sheet, p), std::invalid_argument);
}

}  // namespace
}  // namespace crumple::render
