// The Renderer interface (renderer.hpp) and the render geometry both
// backends draw (src/render/src/render_geometry.hpp): the interface gives
// exactly the backends' own images, and the 8-bit pictures round-trip
// through the float image.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <stdexcept>

#include "crumple/render/embree_renderer.hpp"
#include "crumple/render/osmesa_renderer.hpp"
#include "crumple/render/renderer.hpp"
#include "render_geometry.hpp"
#include "render_test_scenes.hpp"

namespace crumple::render {
namespace {

constexpr int kWidth = 96;
constexpr int kHeight = 72;

RendererOptions smallOptions() {
  RendererOptions o;
  o.width = kWidth;
  o.height = kHeight;
  o.samplesPerPixel = 2;
  o.maxBounces = 1;
  o.seed = 7;
  return o;
}

TEST(RendererInterface, MakesEitherBackend) {
  EXPECT_EQ(makeRenderer(Backend::Osmesa, smallOptions())->backend(), Backend::Osmesa);
  EXPECT_EQ(makeRenderer(Backend::Embree, smallOptions())->backend(), Backend::Embree);
}

TEST(RendererInterface, OsmesaGivesItsOwnBytesAndTheirDecoding) {
  const RenderScene scene = test::bentScene(kWidth, kHeight);
  const mesh::SheetMesh sheet = test::bentSceneSheet();
  const StructureOverlay overlay = test::bentSheetStructure(sheet);
  OsmesaRenderer direct(kWidth, kHeight);
  const std::unique_ptr<Renderer> renderer = makeRenderer(Backend::Osmesa, smallOptions());
  for (const RenderPass pass : {RenderPass::Beauty, RenderPass::Albedo})
    for (const StructureOverlay* o : {static_cast<const StructureOverlay*>(nullptr), &overlay}) {
      const ImageRGBA8 expected = direct.render(scene, sheet, o, pass);
      FrameSettings settings;
      settings.overlay = o;
      const RenderedImage image = renderer->render(scene, sheet, settings, pass);
      EXPECT_EQ(image.srgb8().pixels, expected.pixels);
      EXPECT_EQ(image.linear().pixels, decodeSrgb8(expected, /*premultiply=*/true).pixels);
    }
}

TEST(RendererInterface, EmbreeGivesItsOwnImage) {
  const RenderScene scene = test::bentScene(kWidth, kHeight);
  const mesh::SheetMesh sheet = test::bentSceneSheet();
  const RendererOptions options = smallOptions();
  PathTraceSettings pt;
  pt.samplesPerPixel = options.samplesPerPixel;
  pt.maxBounces = options.maxBounces;
  pt.seed = options.seed;
  pt.frame = 3;
  pt.pass = RenderPass::Beauty;
  EmbreeRenderer direct;
  const ImageRGBAF expected = direct.render(scene, sheet, pt);
  const std::unique_ptr<Renderer> renderer = makeRenderer(Backend::Embree, options);
  FrameSettings settings;
  settings.frame = 3;
  const RenderedImage image = renderer->render(scene, sheet, settings, RenderPass::Beauty);
  EXPECT_EQ(image.linear().pixels, expected.pixels);
  EXPECT_EQ(image.srgb8().pixels, toSrgb8(expected, scene.background).pixels);
  EXPECT_EQ(renderer->droppedSamples(), 0u);
}

TEST(RendererInterface, EmbreeRejectsAStructureView) {
  const RenderScene scene = test::bentScene(kWidth, kHeight);
  const mesh::SheetMesh sheet = test::bentSceneSheet();
  const StructureOverlay overlay = test::bentSheetStructure(sheet);
  FrameSettings settings;
  settings.overlay = &overlay;
  EXPECT_THROW(makeRenderer(Backend::Embree, smallOptions())
                   ->render(scene, sheet, settings, RenderPass::Beauty),
               std::invalid_argument);
}

// Every 8-bit colour at every coverage survives decodeSrgb8 (premultiplied)
// and toSrgb8 unchanged; uncovered pixels come back as the background.
TEST(RendererInterface, EightBitImagesRoundTripThroughLinear) {
  const Vec3 background(0.8, 0.82, 0.86);
  ImageRGBA8 image(256, 256);
  for (int a = 0; a < 256; ++a)
    for (int c = 0; c < 256; ++c) {
      std::uint8_t* p = image.at(c, a);
      p[0] = a == 0 ? linearToSrgb8(background.x()) : static_cast<std::uint8_t>(c);
      p[1] = a == 0 ? linearToSrgb8(background.y()) : static_cast<std::uint8_t>(255 - c);
      p[2] = a == 0 ? linearToSrgb8(background.z()) : static_cast<std::uint8_t>(c ^ 0x5a);
      p[3] = static_cast<std::uint8_t>(a);
    }
  EXPECT_EQ(toSrgb8(decodeSrgb8(image, /*premultiply=*/true), background).pixels, image.pixels);
}

TEST(RenderGeometry, RecentresOnTheSheetsBoundingBox) {
  RenderScene scene = test::bentScene(kWidth, kHeight);
  mesh::SheetMesh sheet = test::flatSheet(0.0);
  const Vec3 shift(10.0, 2.0, -3.0);
  for (Vec3& p : sheet.positions) p += shift;
  scene.camera.position += shift;
  scene.lights.clear();
  PropMesh prop;
  prop.vertices = {shift, shift + Vec3::UnitX(), shift + Vec3::UnitZ()};
  prop.triangles = {{0, 2, 1}};
  scene.props = {prop};
  const detail::RenderGeometry g = detail::buildRenderGeometry(scene, sheet, true);
  EXPECT_TRUE(g.origin.isApprox(shift, 1e-12));
  EXPECT_TRUE(g.camera.position.isApprox(test::bentScene(kWidth, kHeight).camera.position, 1e-9));
  ASSERT_EQ(g.lights.size(), 1u);  // the default light
  EXPECT_EQ(g.positions.size(), sheet.positions.size());
  EXPECT_EQ(g.drawnTriangles.size(), sheet.triangles.size());
  EXPECT_TRUE(g.patchPieces.empty());
  EXPECT_EQ(g.cornerNormals, shadingNormals(sheet.positions, sheet.triangles,
                                            scene.paper.creaseAngle, scene.sharpVertices));
  ASSERT_EQ(g.props.size(), 1u);
  EXPECT_LT(detail::toVec3(g.props[0].vertices[0]).norm(), 1e-9);
  EXPECT_EQ(g.props[0].faceNormals[0], (detail::Float3{0.0f, 1.0f, 0.0f}));
  ASSERT_TRUE(g.ground.has_value());
  EXPECT_DOUBLE_EQ((*g.ground)[0].y(), scene.ground.height - shift.y());
}

}  // namespace
}  // namespace crumple::render
