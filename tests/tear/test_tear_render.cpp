// Tear textures drawn (thesis 3.3.4; docs/RENDERING.md "Tears"): a flat
// sheet torn from its bottom edge along a detail path swinging to either
// side of the cut, its right lip moved 4 mm aside, seen from above by both
// renderers: paper shows exactly where the lips' masks
// say, the same in both.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>

#include "crumple/cache/pcache_motion.hpp"
#include "crumple/cache/pcache_tear.hpp"
#include "crumple/core/error.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/mesh/tear_patches.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/render/embree_renderer.hpp"
#include "crumple/render/osmesa_renderer.hpp"
#include "crumple/render/view.hpp"
#include "crumple/tear/cut.hpp"
#include "crumple/tear/lip_masks.hpp"
#include "crumple/tear/tear_atlas.hpp"

namespace crumple::tear {
namespace {

constexpr double kSheet = 0.04;   // m, a square sheet
constexpr double kShift = 0.004;  // m, the right lip moved along +x
constexpr int kPixels = 160;      // image side
constexpr double kView = 0.016;   // m seen across the image (0.1 mm per pixel)
constexpr double kHeight = 0.1;   // m, the camera above the sheet
constexpr double kDepth = 0.002;  // m, the ground below it

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

bool inTriangle(const Vec2& q, const Vec2& a, const Vec2& b, const Vec2& c) {
  const double area = cross(b - a, c - a);
  const double w1 = cross(q - a, c - a) / area, w2 = cross(b - a, q - a) / area;
  return w1 >= 0.0 && w2 >= 0.0 && w1 + w2 <= 1.0;
}

struct TornScene {
  mesh::SheetMesh sheet;
  TearAtlas atlas;
  Vec2 from, to;
  std::vector<Vec2> path;  // the detail path, continued beyond its ends along the cut
};

TornScene tornScene() {
  TornScene s;
  s.sheet = mesh::makeRectangleSheet(kSheet, kSheet, 0.005);
  // Lying flat, front up: pattern (u, v) at world (u, 0, -v).
  mesh::placePattern(s.sheet, Vec3::Zero(), Vec3::UnitX(), -Vec3::UnitZ());
  const int from = mesh::nearestPatternVertex(s.sheet, Vec2(0.02, 0.0));
  s.from = s.sheet.pattern[static_cast<std::size_t>(from)];
  const CutResult cut = cutAlong(s.sheet, from, Vec2(0.0213, 0.026));
  s.to = s.sheet.pattern[static_cast<std::size_t>(cut.tip)];
  TearSegment seg;
  for (int v : cut.chain) seg.cut.push_back(s.sheet.pattern[static_cast<std::size_t>(v)]);
  // A detail path that swings 1.5 mm to either side of the cut, one and a
  // half times (so the test does not hang on one fiber texture's walk).
  const Vec2 normal = Vec2(-(s.to - s.from).y(), (s.to - s.from).x()).normalized();
  for (int k = 0; k <= 400; ++k) {
    const double t = k / 400.0;
    seg.detail.push_back(s.from + t * (s.to - s.from) +
                         0.0015 * std::sin(3.0 * std::numbers::pi * t) * normal);
  }
  seg.detail.back() = s.to;
  s.atlas = bakeTearAtlas(s.sheet, {seg}, TearAtlasParams{});
  const Vec2 along = (s.to - s.from).normalized();
  s.path = seg.detail;
  s.path.insert(s.path.begin(), s.from - along);
  s.path.push_back(s.to + along);
  // Open the tear: the right lip (right of the cut's line, and the chain's
  // right copies) moves by kShift behind the tip, by less ahead of it.
  std::vector<char> right(s.sheet.vertexCount(), 0);
  for (std::size_t v = 0; v < s.sheet.vertexCount(); ++v)
    right[v] = cross(along, s.sheet.pattern[v] - s.from) < -1e-12;
  for (std::size_t i = 0; i + 1 < cut.chain.size(); ++i)
    right[static_cast<std::size_t>(cut.chain[i])] = 1;
  for (std::size_t v = 0; v < s.sheet.vertexCount(); ++v) {
    const double y = s.sheet.pattern[v].y();
    const double g = std::clamp((s.to.y() + 0.004 - y) / 0.006, 0.0, 1.0);
    if (right[v]) s.sheet.positions[v].x() += kShift * g;
  }
  return s;
}

render::RenderScene viewOf(const TornScene& s, const Vec2& centre) {
  render::RenderScene scene;
  const Vec3 target(centre.x(), 0.0, -centre.y());
  scene.camera = render::Camera::lookAt(target + Vec3(0.0, kHeight, 0.0), target, -Vec3::UnitZ(),
                                        2.0 * std::atan(0.5 * kView / kHeight), kPixels, kPixels);
  scene.paper.textureSize = Vec2(kSheet, kSheet);
  scene.tears = s.atlas;
  return scene;
}

// What the test expects at a pattern point w of the view (the left lip's
// pattern; the right lip's is w - kShift): 1 paper, 0 none, -1 undecided
// (within two texels of a change of side, where the bilinear mask's contour
// runs, or off the sheet, or near the tip).
class Expectation {
 public:
  explicit Expectation(const TornScene& s) : s_(s) {
    grid_.pixelSize = s.atlas.texelSize;
    grid_.width = grid_.height = static_cast<int>(std::ceil(kSheet / grid_.pixelSize));
    sides_ = leftOfPath(s.path, grid_);
  }
  // 1 left of the detail path, 0 right, -1 undecided.
  int side(const Vec2& q) const {
    const double texel = grid_.pixelSize;
    const long i = std::lround(q.x() / texel - 0.5), j = std::lround(q.y() / texel - 0.5);
    if (i < 2 || j < 2 || i >= grid_.width - 2 || j >= grid_.height - 2) return -1;
    const int c = sides_[static_cast<std::size_t>(j * grid_.width + i)];
    for (long dj = -2; dj <= 2; ++dj)
      for (long di = -2; di <= 2; ++di)
        if (sides_[static_cast<std::size_t>((j + dj) * grid_.width + i + di)] != c) return -1;
    return c;
  }
  // The left lip shows its side of the path at w; the right lip, moved by
  // kShift, its side at w - kShift.
  int paper(const Vec2& w) const {
    const int l = side(w), r = side(w - Vec2(kShift, 0.0));
    if (l < 0 || r < 0 || w.y() > s_.to.y() - 0.006) return -1;
    return l == 1 || r == 0 ? 1 : 0;
  }
  // Whether w is on one of the lip's patches' triangles.
  bool onLipTriangle(const Vec2& w, LipSide lip) const {
    for (const TearPatch& p : s_.atlas.patches) {
      if (p.side != lip) continue;
      const auto& t = s_.sheet.triangles[static_cast<std::size_t>(p.triangle)];
      if (inTriangle(w, s_.sheet.pattern[static_cast<std::size_t>(t[0])],
                     s_.sheet.pattern[static_cast<std::size_t>(t[1])],
                     s_.sheet.pattern[static_cast<std::size_t>(t[2])]))
        return true;
    }
    return false;
  }

 private:
  const TornScene& s_;
  PixelGrid grid_;
  std::vector<std::uint8_t> sides_;
};

// The pattern point (left lip) seen at the centre of pixel (px, py).
Vec2 seenAt(const Vec2& centre, int px, int py) {
  const double metresPerPixel = kView / kPixels;
  return {centre.x() + (px + 0.5 - 0.5 * kPixels) * metresPerPixel,
          centre.y() - (py + 0.5 - 0.5 * kPixels) * metresPerPixel};
}

Vec2 viewCentre(const TornScene& s) {
  return {0.5 * (s.from.x() + s.to.x()) + 0.5 * kShift, 0.012};
}

TEST(TearRender, PaperShowsExactlyWhereTheLipsMasksSayInBothRenderers) {
  const TornScene s = tornScene();
  ASSERT_FALSE(s.atlas.empty());
  const Vec2 centre = viewCentre(s);
  const render::RenderScene scene = viewOf(s, centre);
  const auto corner = render::projectToPixel(
      scene.camera, Vec3(seenAt(centre, 0, 0).x(), 0.0, -seenAt(centre, 0, 0).y()));
  ASSERT_TRUE(corner.has_value());
  ASSERT_NEAR(corner->x(), 0.5, 1e-6);
  ASSERT_NEAR(corner->y(), 0.5, 1e-6);

  render::OsmesaRenderer osmesa(kPixels, kPixels);
  const ImageRGBA8 preview = osmesa.render(scene, s.sheet, nullptr, render::RenderPass::Albedo);
  render::EmbreeRenderer embree;
  render::PathTraceSettings pt;
  pt.samplesPerPixel = 4;
  pt.pass = render::RenderPass::Albedo;
  const ImageRGBAF traced = embree.render(scene, s.sheet, pt);

  const Expectation expect(s);
  long strict = 0, agree = 0, covered = 0, rightOfPathOnLeftLip = 0, leftOfPathOnRightLip = 0;
  for (int py = 0; py < kPixels; ++py)
    for (int px = 0; px < kPixels; ++px) {
      const Vec2 w = seenAt(centre, px, py);
      agree += (preview.at(px, py)[3] > 0) == (traced.at(px, py)[3] > 0.0f);
      const int paper = expect.paper(w);
      if (paper < 0) continue;
      ++strict;
      covered += paper;
      EXPECT_EQ(preview.at(px, py)[3], paper ? 255 : 0) << "preview pixel " << px << ", " << py;
      EXPECT_EQ(traced.at(px, py)[3], paper ? 1.0f : 0.0f) << "traced pixel " << px << ", " << py;
      if (paper == 0 && expect.onLipTriangle(w, LipSide::Left)) ++rightOfPathOnLeftLip;
      if (expect.side(w) == 1 && expect.onLipTriangle(w, LipSide::Right)) ++leftOfPathOnRightLip;
    }
  std::cout << "[ measure ] " << strict << " pixels away from edges (" << covered
            << " paper), preview and path tracer agree on " << agree << " of " << kPixels * kPixels
            << " pixels; " << rightOfPathOnLeftLip
            << " empty pixels on left lip triangles right of the path, " << leftOfPathOnRightLip
            << " paper pixels over right lip triangles left of it\n";
  EXPECT_GT(strict, kPixels * kPixels / 2);
  EXPECT_GT(covered, strict / 4);
  EXPECT_LT(covered, strict - strict / 20) << "the gap";
  // The detail path crosses the cut: some of the left lip's triangles are
  // cut away, some of the left lip's paper lies over the right lip's.
  EXPECT_GT(rightOfPathOnLeftLip, 100);
  EXPECT_GT(leftOfPathOnRightLip, 100);
  EXPECT_GE(agree, kPixels * kPixels - kPixels * kPixels / 100) << "coverage within 1%";
}

TEST(TearRender, LightPassesWhereTheMasksCutThePaper) {
  // A ground 2 mm below, lit from the side at 45 degrees (no sky): the
  // ground seen through the gap at w is lit unless the paper at w - 2 mm
  // (along x) shadows it, patches' masks and quads included.
  const TornScene s = tornScene();
  const Vec2 centre = viewCentre(s);
  render::RenderScene scene = viewOf(s, centre);
  scene.ground.enabled = true;
  scene.ground.height = -kDepth;
  scene.ground.size = 0.2;
  scene.ground.color = Vec3(0.5, 0.5, 0.5);
  scene.environment.intensity = 0.0;
  render::Light sun;
  sun.direction = Vec3(1.0, -1.0, 0.0);
  sun.shadow = true;
  scene.lights = {sun};

  render::OsmesaRenderer osmesa(kPixels, kPixels);
  const ImageRGBA8 preview = osmesa.render(scene, s.sheet);
  render::EmbreeRenderer embree;
  render::PathTraceSettings pt;
  pt.samplesPerPixel = 4;
  pt.maxBounces = 0;
  const ImageRGBAF traced = embree.render(scene, s.sheet, pt);

  const Expectation expect(s);
  const Vec3 eye = scene.camera.position;
  long lit = 0, shadowed = 0;
  for (int py = 0; py < kPixels; ++py)
    for (int px = 0; px < kPixels; ++px) {
      const Vec2 w = seenAt(centre, px, py);
      if (expect.paper(w) != 0) continue;  // the ground is seen through the gap
      // Where the camera ray meets the ground, and where the ray from there
      // to the light crosses the sheet's plane.
      const Vec3 onSheet(w.x(), 0.0, -w.y());
      const Vec3 ground = eye + (onSheet - eye) * ((eye.y() + kDepth) / eye.y());
      const Vec2 shadowPoint(ground.x() - kDepth, -ground.z());
      const int paper = expect.paper(shadowPoint);
      if (paper < 0) continue;
      (paper ? shadowed : lit) += 1;
      // Lit: 0.5 cos 45 degrees = 0.35 (sRGB 160); shadowed: black.
      EXPECT_EQ(preview.at(px, py)[1] > 80, paper == 0) << "preview pixel " << px << ", " << py;
      EXPECT_EQ(traced.at(px, py)[1] > 0.18f, paper == 0) << "traced pixel " << px << ", " << py;
    }
  std::cout << "[ measure ] ground seen through the gap: " << lit << " pixels lit, " << shadowed
            << " in the paper's shadow\n";
  EXPECT_GT(lit, 200);
  EXPECT_GT(shadowed, 200);
}

TEST(TearRender, WithoutTheAtlasTheTearIsTheCut) {
  // The same sheet drawn without its patches parts along the mesh's cut,
  // not along the detail path; a corrupt atlas is refused.
  const TornScene s = tornScene();
  render::RenderScene with = viewOf(s, viewCentre(s)), without = with;
  without.tears = TearAtlas{};
  render::OsmesaRenderer osmesa(kPixels, kPixels);
  const ImageRGBA8 a = osmesa.render(with, s.sheet, nullptr, render::RenderPass::Albedo);
  const ImageRGBA8 b = osmesa.render(without, s.sheet, nullptr, render::RenderPass::Albedo);
  long differ = 0;
  for (int py = 0; py < kPixels; ++py)
    for (int px = 0; px < kPixels; ++px)
      differ += (a.at(px, py)[3] > 127) != (b.at(px, py)[3] > 127);
  EXPECT_GT(differ, 100);
  render::RenderScene bad = with;
  bad.tears.patches.back().triangle = static_cast<int>(s.sheet.triangleCount());
  EXPECT_THROW(osmesa.render(bad, s.sheet), std::invalid_argument);
  render::EmbreeRenderer embree;
  EXPECT_THROW(embree.render(bad, s.sheet, render::PathTraceSettings{}), std::invalid_argument);
}

TEST(TearRender, TheCacheCarriesTheAtlasToTheRenderers) {
  // A frame record with a TEAR block: the view built for the renderers
  // holds the atlas (docs/PCACHE.md); one whose patches do not fit the
  // frame's mesh is corrupt.
  const TornScene s = tornScene();
  cache::FrameRecord frame;
  frame.frame = 3;
  frame.pattern = s.sheet.pattern;
  frame.positions = s.sheet.positions;
  frame.triangles = s.sheet.triangles;
  frame.regionOfTriangle = s.sheet.regionOfTriangle;
  frame.regionTypes = {0};
  frame.extensions = {cache::encodeTearAtlas(s.atlas)};
  const io::SceneSpec spec =
      io::parseScene("[sheet]\nwidth = 0.04\nheight = 0.04\n", "torn.toml", ".");
  const pipeline::FrameViewBuilder views(spec, {});
  EXPECT_EQ(views.build(frame).scene.tears, s.atlas);
  TearAtlas bad = s.atlas;
  bad.patches.back().triangle = static_cast<int>(s.sheet.triangleCount());
  frame.extensions = {cache::encodeTearAtlas(bad)};
  EXPECT_THROW(views.build(frame), CorruptDataError);
  frame.extensions.clear();
  EXPECT_TRUE(views.build(frame).scene.tears.empty());
}

}  // namespace
}  // namespace crumple::tear

namespace crumple::tear {
namespace {

// Motion blur (docs/RENDERING.md "Motion blur"): the torn sheet sliding
// along +x while the shutter is open, from the cache's frame (its TEAR and
// VELO blocks, a shot's shutter), is the average of the still sheet at the
// places it passes: the masks cut the paper where the moving triangles
// carry them.
TEST(TearRender, AMovingTornSheetIsTheAverageOfItsPlacesWhileTheShutterIsOpen) {
  const TornScene s = tornScene();
  constexpr double kMove = 0.002;  // m while the shutter is open: 20 pixels
  cache::FrameRecord frame;
  frame.frame = 3;
  frame.pattern = s.sheet.pattern;
  frame.positions = s.sheet.positions;
  frame.triangles = s.sheet.triangles;
  frame.regionOfTriangle = s.sheet.regionOfTriangle;
  frame.regionTypes = {0};
  frame.extensions = {cache::encodeTearAtlas(s.atlas),
                      cache::encodeVelocities(
                          std::vector<Vec3>(s.sheet.vertexCount(), Vec3(kMove * 24.0, 0.0, 0.0)))};
  const io::SceneSpec spec =
      io::parseScene("[scene]\nfps = 24\n[sheet]\nwidth = 0.04\nheight = 0.04\n", "torn.toml", ".");
  const pipeline::FrameViewBuilder views(spec, {cache::encodeShutter({-0.5, 0.5})});
  const pipeline::FrameView fv = views.build(frame);
  ASSERT_EQ(fv.scene.sheetMotion.size(), 2u);
  EXPECT_EQ(fv.scene.tears, s.atlas);
  const Vec2 centre = viewCentre(s);
  render::RenderScene scene = viewOf(s, centre);
  render::EmbreeRenderer embree;
  render::PathTraceSettings pt;
  pt.pass = render::RenderPass::Albedo;
  const auto render = [&](const render::RenderScene& sc, const mesh::SheetMesh& sheet, int spp) {
    pt.samplesPerPixel = spp;
    return embree.render(sc, sheet, pt);
  };
  const ImageRGBAF sharp = render(scene, s.sheet, 16);
  scene.sheetMotion = fv.scene.sheetMotion;
  const ImageRGBAF blurred = render(scene, s.sheet, 256);
  // The still sheet at 41 places evenly over the motion (half a pixel apart).
  scene.sheetMotion.clear();
  std::vector<double> mean(static_cast<std::size_t>(kPixels * kPixels), 0.0);
  constexpr int kPlaces = 41;
  for (int k = 0; k < kPlaces; ++k) {
    mesh::SheetMesh moved = s.sheet;
    for (Vec3& p : moved.positions) p.x() += kMove * (static_cast<double>(k) / (kPlaces - 1) - 0.5);
    const ImageRGBAF still = render(scene, moved, 4);
    for (int y = 0; y < kPixels; ++y)
      for (int x = 0; x < kPixels; ++x)
        mean[static_cast<std::size_t>(y * kPixels + x)] += still.at(x, y)[3] / kPlaces;
  }
  double toMean = 0.0, toSharp = 0.0;
  for (int y = 0; y < kPixels; ++y)
    for (int x = 0; x < kPixels; ++x) {
      const double b = blurred.at(x, y)[3];
      toMean += std::abs(b - mean[static_cast<std::size_t>(y * kPixels + x)]);
      toSharp += std::abs(b - sharp.at(x, y)[3]);
    }
  toMean /= kPixels * kPixels;
  toSharp /= kPixels * kPixels;
  std::cout << "[ measure ] blurred torn sheet: mean |alpha difference| to the average of its "
            << kPlaces << " places " << toMean << ", to the still sheet " << toSharp << "\n";
  // Measured 0.0020 against 0.059: the sampling noise of the partly covered
  // pixels (256 samples blurred, 41 x 4 averaged) and the places' spacing.
  EXPECT_LT(toMean, 0.006);
  EXPECT_GT(toSharp, 10.0 * toMean);
}

}  // namespace
}  // namespace crumple::tear
