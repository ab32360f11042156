// The path tracer's AOVs (render/aov.hpp) on a flat sheet seen from above:
// depth, normal and position against the camera geometry, albedo against the
// albedo pass, region coverage and handle ids against the labels given, object
// ids, the beauty unchanged by asking for AOVs, thread-count independence,
// the rasteriser's refusal and the list parser.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "crumple/core/parallel.hpp"
#include "crumple/render/aov.hpp"
#include "crumple/render/embree_renderer.hpp"
#include "crumple/render/renderer.hpp"
#include "render_test_scenes.hpp"

namespace crumple::render {
namespace {

using namespace test;

constexpr int kW = 64, kH = 48;
constexpr double kSheetY = 0.1, kCameraY = 0.5;

std::vector<Aov> allAovs() {
  std::vector<Aov> all;
  for (int i = 0; i < kAovCount; ++i) all.push_back(static_cast<Aov>(i));
  return all;
}

RenderScene aovScene(bool ground) {
  RenderScene s;
  s.camera = topCamera(kCameraY, kW, kH);
  s.ground.enabled = ground;
  s.ground.height = 0.0;
  s.paper.transmittance = 0.0;
  return s;
}

// flatSheet at kSheetY, its left half (pattern x < W/2) one flat region and
// its right half one curved region; `sharp` receives the vertex nearest
// pattern (3W/4, H/2) and `handles` the vertices nearest (0, H/2) and (W, H/2).
mesh::SheetMesh labelledSheet(std::vector<int>& sharp, std::vector<int>& handles) {
  mesh::SheetMesh m = flatSheet(kSheetY, 0.02);
  m.regionTypes = {mesh::RegionType::Flat, mesh::RegionType::Curved};
  m.regionOfTriangle.clear();
  for (const auto& t : m.triangles) {
    const double cx = (m.pattern[static_cast<std::size_t>(t[0])].x() +
                       m.pattern[static_cast<std::size_t>(t[1])].x() +
                       m.pattern[static_cast<std::size_t>(t[2])].x()) /
                      3.0;
    m.regionOfTriangle.push_back(cx < 0.5 * kSheetWidth ? 0 : 1);
  }
  const auto nearest = [&](const Vec2& q) {
    int best = 0;
    for (std::size_t i = 0; i < m.pattern.size(); ++i)
      if ((m.pattern[i] - q).norm() < (m.pattern[static_cast<std::size_t>(best)] - q).norm())
        best = static_cast<int>(i);
    return best;
  };
  sharp = {nearest(Vec2(0.75 * kSheetWidth, 0.5 * kSheetHeight))};
  handles = {nearest(Vec2(0.0, 0.5 * kSheetHeight)),
             nearest(Vec2(kSheetWidth, 0.5 * kSheetHeight))};
  return m;
}

// aovScene over labelledSheet with its labels: the singular vertex, the two
// handles and the model's regions.
RenderScene labelledScene(bool ground, mesh::SheetMesh& sheet) {
  std::vector<int> sharp, handles;
  sheet = labelledSheet(sharp, handles);
  RenderScene s = aovScene(ground);
  s.sharpVertices = sharp;
  s.handleVertices = handles;
  s.modelledRegions = true;
  return s;
}

// The pixel whose centre sees world point p (topCamera: +X right, -Z up).
std::size_t pixelOf(const Camera& cam, const Vec3& p) {
  const Vec3 local = cam.rotation.normalized().conjugate() * (p - cam.position);
  const double tanY = std::tan(0.5 * cam.yfov), tanX = tanY * cam.width / cam.height;
  const double sx = local.x() / -local.z() / tanX, sy = local.y() / -local.z() / tanY;
  const int x = static_cast<int>(std::floor(0.5 * (sx + 1.0) * cam.width));
  const int y = static_cast<int>(std::floor(0.5 * (1.0 - sy) * cam.height));
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(cam.width) +
         static_cast<std::size_t>(x);
}

float at(const AovImage& aovs, const char* name, std::size_t pixel) {
  const ImageChannel* c = aovs.find(name);
  EXPECT_NE(c, nullptr) << name;
  return c ? c->pixels[pixel] : 0.0f;
}

struct Rendered {
  ImageRGBAF beauty;
  AovImage aovs;
};

Rendered renderAovs(const RenderScene& scene, const mesh::SheetMesh& sheet,
                    RenderPass pass = RenderPass::Beauty) {
  EmbreeRenderer r;
  PathTraceSettings p;
  p.samplesPerPixel = 8;
  p.maxBounces = 1;
  p.pass = pass;
  p.aovs = allAovs();
  Rendered out;
  out.beauty = r.render(scene, sheet, p, &out.aovs);
  return out;
}

TEST(Aov, ChannelsAreNamedAsCompositorsReadThem) {
  mesh::SheetMesh sheet;
  RenderScene scene = labelledScene(false, sheet);
  const Rendered r = renderAovs(scene, sheet);
  std::vector<std::string> names;
  for (const ImageChannel& c : r.aovs.channels) names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{
                       "Z", "N.X", "N.Y", "N.Z", "albedo.R", "albedo.G", "albedo.B", "P.X", "P.Y",
                       "P.Z", "region.R", "region.G", "region.B", "IndexHandle.X", "IndexOB.X"}));
  EXPECT_EQ(r.aovs.width, kW);
  EXPECT_EQ(r.aovs.height, kH);
  for (const ImageChannel& c : r.aovs.channels)
    EXPECT_EQ(c.pixels.size(), static_cast<std::size_t>(kW * kH)) << c.name;
}

TEST(Aov, DepthNormalAndPositionAreTheFirstHitsGeometry) {
  mesh::SheetMesh sheet;
  RenderScene scene = labelledScene(false, sheet);
  const Rendered r = renderAovs(scene, sheet);
  // A pixel inside the flat half: every sample hits the sheet at Y = kSheetY.
  const Vec3 target(-0.05, kSheetY, 0.03);
  const std::size_t px = pixelOf(scene.camera, target);
  EXPECT_NEAR(at(r.aovs, "Z", px), kCameraY - kSheetY, 1e-5);
  EXPECT_NEAR(at(r.aovs, "N.X", px), 0.0, 1e-3);
  EXPECT_NEAR(at(r.aovs, "N.Y", px), 1.0, 1e-3);  // facing the camera above
  EXPECT_NEAR(at(r.aovs, "N.Z", px), 0.0, 1e-3);
  // The mean hit is within the pixel's footprint (0.5 * 2 tan(0.35) / 48 m).
  const double footprint = 2.0 * (kCameraY - kSheetY) * std::tan(0.35) / kH;
  EXPECT_NEAR(at(r.aovs, "P.Y", px), kSheetY, 1e-5);
  EXPECT_NEAR(at(r.aovs, "P.X", px), target.x(), footprint);
  EXPECT_NEAR(at(r.aovs, "P.Z", px), target.z(), footprint);
  // A corner pixel sees nothing: the far depth, zero normal and position.
  EXPECT_EQ(at(r.aovs, "Z", 0), kAovFarDepth);
  EXPECT_EQ(at(r.aovs, "N.Y", 0), 0.0f);
  EXPECT_EQ(at(r.aovs, "P.Y", 0), 0.0f);
  EXPECT_EQ(at(r.aovs, "IndexOB.X", 0), 0.0f);
  EXPECT_EQ(at(r.aovs, "IndexHandle.X", 0), 0.0f);
}

TEST(Aov, RegionsHandlesAndObjectsAreTheSheetsLabels) {
  mesh::SheetMesh sheet;
  RenderScene scene = labelledScene(true, sheet);
  const Rendered r = renderAovs(scene, sheet);
  const auto region = [&](std::size_t px) {
    return Vec3(at(r.aovs, "region.R", px), at(r.aovs, "region.G", px), at(r.aovs, "region.B", px));
  };
  const std::size_t flat = pixelOf(scene.camera, Vec3(-0.06, kSheetY, 0.05));
  const std::size_t curved = pixelOf(scene.camera, Vec3(0.03, kSheetY, 0.1));
  const Vec3 sharpAt = sheet.positions[static_cast<std::size_t>(scene.sharpVertices[0])];
  const std::size_t singular = pixelOf(scene.camera, sharpAt);
  // Half an edge (0.02 m) away the triangles around it are curved paper again.
  const std::size_t besideSingular = pixelOf(scene.camera, sharpAt + Vec3(0.0, 0.0, 0.016));
  EXPECT_EQ(region(flat), Vec3(1.0, 0.0, 0.0));
  EXPECT_EQ(region(curved), Vec3(0.0, 1.0, 0.0));
  // The pixel holding the singular vertex: mostly its neighbourhood (the
  // pixel need not be centred on it), the rest curved paper.
  EXPECT_GT(region(singular).z(), 0.5);
  EXPECT_EQ(region(singular).x(), 0.0);
  EXPECT_EQ(region(singular).sum(), 1.0);
  EXPECT_EQ(region(besideSingular), Vec3(0.0, 1.0, 0.0));
  EXPECT_EQ(at(r.aovs, "IndexHandle.X", flat), 1.0f);    // the left handle's side
  EXPECT_EQ(at(r.aovs, "IndexHandle.X", curved), 2.0f);  // the right handle's
  EXPECT_EQ(at(r.aovs, "IndexOB.X", flat), 1.0f);        // the sheet
  // Beside the sheet: the ground (object 2), no paper, at the ground's depth.
  const std::size_t ground = pixelOf(scene.camera, Vec3(0.2, 0.0, 0.0));
  EXPECT_EQ(at(r.aovs, "IndexOB.X", ground), 2.0f);
  EXPECT_EQ(region(ground), Vec3::Zero());
  EXPECT_EQ(at(r.aovs, "IndexHandle.X", ground), 0.0f);
  EXPECT_NEAR(at(r.aovs, "Z", ground), kCameraY, 1e-5);
  // Without the model's regions (the elastic model) the region channels are empty.
  scene.modelledRegions = false;
  const Rendered p = renderAovs(scene, sheet);
  EXPECT_EQ(
      at(p.aovs, "region.R", flat) + at(p.aovs, "region.G", flat) + at(p.aovs, "region.B", flat),
      0.0f);
}

TEST(Aov, AlbedoIsTheAlbedoPassAndTheBeautyIsUnchanged) {
  mesh::SheetMesh sheet;
  RenderScene scene = labelledScene(true, sheet);
  const Rendered withAovs = renderAovs(scene, sheet);
  EmbreeRenderer r;
  PathTraceSettings p;
  p.samplesPerPixel = 8;
  p.maxBounces = 1;
  // Asking for AOVs changes no sample of the beauty.
  EXPECT_EQ(r.render(scene, sheet, p).pixels, withAovs.beauty.pixels);
  p.pass = RenderPass::Albedo;
  const ImageRGBAF albedo = r.render(scene, sheet, p);
  for (std::size_t i = 0; i < static_cast<std::size_t>(kW * kH); ++i) {
    EXPECT_NEAR(at(withAovs.aovs, "albedo.R", i), albedo.pixels[4 * i], 1e-6) << i;
    EXPECT_NEAR(at(withAovs.aovs, "albedo.G", i), albedo.pixels[4 * i + 1], 1e-6) << i;
    EXPECT_NEAR(at(withAovs.aovs, "albedo.B", i), albedo.pixels[4 * i + 2], 1e-6) << i;
  }
}

TEST(Aov, IdenticalForAnyThreadCount) {
  mesh::SheetMesh sheet;
  RenderScene scene = labelledScene(true, sheet);
  const int saved = threadCount();
  setThreadCount(1);
  const Rendered one = renderAovs(scene, sheet);
  setThreadCount(2);
  const Rendered two = renderAovs(scene, sheet);
  setThreadCount(saved);
  ASSERT_EQ(one.aovs.channels.size(), two.aovs.channels.size());
  for (std::size_t c = 0; c < one.aovs.channels.size(); ++c)
    EXPECT_EQ(one.aovs.channels[c].pixels, two.aovs.channels[c].pixels)
        << one.aovs.channels[c].name;
}

TEST(Aov, TheRendererInterfaceCarriesThemAndTheRasteriserRefuses) {
  mesh::SheetMesh sheet;
  const RenderScene scene = labelledScene(false, sheet);
  FrameSettings settings;
  settings.aovs = {Aov::Depth, Aov::ObjectId};
  RendererOptions options;
  options.width = kW;
  options.height = kH;
  options.samplesPerPixel = 2;
  const RenderedImage image =
      makeRenderer(Backend::Embree, options)->render(scene, sheet, settings, RenderPass::Beauty);
  ASSERT_NE(image.aovs(), nullptr);
  EXPECT_EQ(image.aovs()->channels.size(), 2u);
  EXPECT_EQ(makeRenderer(Backend::Embree, options)
                ->render(scene, sheet, FrameSettings{}, RenderPass::Beauty)
                .aovs(),
            nullptr);
  EXPECT_THROW(
      makeRenderer(Backend::Osmesa, options)->render(scene, sheet, settings, RenderPass::Beauty),
      std::invalid_argument);
}

TEST(Aov, TheListParserTakesEachNameOnceInAovOrder) {
  EXPECT_EQ(parseAovList("object-id,depth,normal"),
            (std::vector<Aov>{Aov::Depth, Aov::Normal, Aov::ObjectId}));
  EXPECT_EQ(parseAovList("handle-id"), (std::vector<Aov>{Aov::HandleId}));
  for (int i = 0; i < kAovCount; ++i)
    EXPECT_EQ(parseAov(aovName(static_cast<Aov>(i))), static_cast<Aov>(i));
  EXPECT_THROW(parseAovList("depth,depth"), std::invalid_argument);
  EXPECT_THROW(parseAovList("depth,,normal"), std::invalid_argument);
  EXPECT_THROW(parseAovList("beauty"), std::invalid_argument);
  EXPECT_THROW(parseAovList(""), std::invalid_argument);
}

}  // namespace
}  // namespace crumple::render
