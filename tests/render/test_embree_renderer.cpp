// EmbreeRenderer tests: radiometry against closed forms (directional, sun
// disc, point and area lights, the environment, back-lit paper), alpha
// cut-outs, light leaks, shading normals, determinism, convergence, the
// albedo pass, depth of field, NaN safety, input validation and toSrgb8.
// CRUMPLE_RENDER_DUMP=1 writes the images as PNG into the build directory;
// CRUMPLE_PT_BENCH=1 also times the 640x480, 16 spp bent scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <iostream>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "crumple/core/parallel.hpp"
#include "crumple/render/embree_renderer.hpp"
#include "png_io.hpp"
#include "render_test_scenes.hpp"

namespace crumple::render {
namespace {

using namespace test;  // the shared scenes and helpers

bool envFlag(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' && std::string(v) != "0";
}

void dump(const std::string& name, const ImageRGBAF& img) {
  if (envFlag("CRUMPLE_RENDER_DUMP"))
    test::writePng(std::string(CRUMPLE_RENDER_OUT_DIR) + "/embree_" + name + ".png",
                   toSrgb8(img, Vec3(0.8, 0.82, 0.86)));
}

ImageRGBA8 solidTexture(std::uint8_t r, std::uint8_t g, std::uint8_t b, std::uint8_t a) {
  ImageRGBA8 t(1, 1);
  t.pixels = {r, g, b, a};
  return t;
}

Light directional(const Vec3& direction, double intensity) {
  Light l;
  l.kind = Light::Kind::Directional;
  l.direction = direction;
  l.intensity = intensity;
  return l;
}

// A white, opaque, untextured sheet seen from straight above; no ground, no
// environment, no lights (tests add them).
RenderScene plainScene(int width, int height) {
  RenderScene s;
  s.camera = topCamera(0.5, width, height);
  s.environment.intensity = 0.0;
  s.ground.enabled = false;
  s.paper.texture = solidTexture(255, 255, 255, 255);
  s.paper.frontColor = Vec3(1.0, 1.0, 1.0);
  s.paper.backColor = Vec3(1.0, 1.0, 1.0);
  s.paper.transmittance = 0.0;
  return s;
}

PathTraceSettings settings(int spp, int maxBounces = 4) {
  PathTraceSettings p;
  p.samplesPerPixel = spp;
  p.maxBounces = maxBounces;
  return p;
}

// Straight (un-premultiplied) colour of a pixel.
Vec3 straight(const ImageRGBAF& img, int x, int y) {
  const float* p = img.at(x, y);
  return p[3] > 0.0f ? Vec3(Vec3(p[0], p[1], p[2]) / p[3]) : Vec3(Vec3::Zero());
}

// Mean straight colour over the fully covered pixels of a centred window
// (half-width w, half-height h pixels).
Vec3 centreMean(const ImageRGBAF& img, int w, int h) {
  Vec3 sum = Vec3::Zero();
  int n = 0;
  for (int y = img.height / 2 - h; y < img.height / 2 + h; ++y)
    for (int x = img.width / 2 - w; x < img.width / 2 + w; ++x)
      if (img.at(x, y)[3] == 1.0f) {
        sum += straight(img, x, y);
        ++n;
      }
  EXPECT_GT(n, 0);
  return n > 0 ? Vec3(sum / n) : sum;
}

// The world point of the plane Y = planeY seen through pixel centre (x + 0.5, y + 0.5).
Vec3 pixelCentreOnPlane(const Camera& cam, int x, int y, double planeY) {
  const double tanY = std::tan(0.5 * cam.yfov);
  const double tanX = tanY * cam.width / cam.height;
  const Vec3 local((2.0 * (x + 0.5) / cam.width - 1.0) * tanX,
                   (1.0 - 2.0 * (y + 0.5) / cam.height) * tanY, -1.0);
  const Vec3 dir = cam.rotation.normalized() * local;
  const double t = (planeY - cam.position.y()) / dir.y();
  return cam.position + t * dir;
}

// Pattern coordinates of a world point on flatSheet(y).
Vec2 flatSheetPattern(const Vec3& p) {
  return Vec2(p.x() + 0.5 * kSheetWidth, 0.5 * kSheetHeight - p.z());
}

double rmse(const ImageRGBAF& a, const ImageRGBAF& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    const double d = double(a.pixels[i]) - double(b.pixels[i]);
    sum += d * d;
  }
  return std::sqrt(sum / static_cast<double>(a.pixels.size()));
}

double meanAbs(const ImageRGBAF& a, const ImageRGBAF& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    sum += std::abs(double(a.pixels[i]) - double(b.pixels[i]));
  return sum / static_cast<double>(a.pixels.size());
}

// Restores the worker count when a test ends.
struct ThreadCountGuard {
  int saved = threadCount();
  ~ThreadCountGuard() { setThreadCount(saved); }
};

// --- radiometry -----------------------------------------------------------------

// An n x n white texture, transparent where both texel coordinates are in
// [lo, hi): a square hole.
ImageRGBA8 textureWithHole(int n, int lo, int hi) {
  ImageRGBA8 tex(n, n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      std::uint8_t* p = tex.at(x, y);
      p[0] = p[1] = p[2] = 255;
      p[3] = (x >= lo && x < hi && y >= lo && y < hi) ? 0 : 255;
    }
  return tex;
}

TEST(EmbreeRenderer, DirectionalLightGivesIntensityTimesCosine) {
  EmbreeRenderer r;
  RenderScene s = plainScene(64, 48);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  s.lights = {directional(Vec3(0.0, -1.0, 0.0), 0.7)};
  const ImageRGBAF normal = r.render(s, sheet, settings(4));
  const Vec3 a = centreMean(normal, 4, 4);
  EXPECT_NEAR(a.x(), 0.7, 0.007);
  EXPECT_NEAR(a.y(), 0.7, 0.007);
  EXPECT_NEAR(a.z(), 0.7, 0.007);
  // 60 degrees from the normal, coloured.
  s.lights = {directional(Vec3(std::sqrt(3.0), -1.0, 0.0), 0.7)};
  s.lights[0].color = Vec3(1.0, 0.5, 0.25);
  const ImageRGBAF oblique = r.render(s, sheet, settings(4));
  const Vec3 b = centreMean(oblique, 4, 4);
  EXPECT_NEAR(b.x(), 0.35, 0.0035);
  EXPECT_NEAR(b.y(), 0.175, 0.00175);
  EXPECT_NEAR(b.z(), 0.0875, 0.000875);
  // From behind an opaque sheet: nothing.
  s.lights = {directional(Vec3(0.0, 1.0, 0.0), 0.7)};
  EXPECT_EQ(centreMean(r.render(s, sheet, settings(4)), 4, 4), Vec3::Zero());
  EXPECT_EQ(r.droppedSamples(), 0u);
}

TEST(EmbreeRenderer, EmptyLightListUsesTheDefaultLight) {
  EmbreeRenderer r;
  RenderScene s = plainScene(32, 24);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  const Light def;
  const double expected = def.intensity * (-def.direction.normalized().y());
  EXPECT_NEAR(centreMean(r.render(s, sheet, settings(2, 0)), 2, 2).x(), expected, 0.01 * expected);
}

TEST(EmbreeRenderer, EnvironmentOnlyGivesAlbedoTimesEnvironment) {
  EmbreeRenderer r;
  RenderScene s = plainScene(64, 48);
  s.lights = {directional(Vec3(0.0, -1.0, 0.0), 0.0)};
  s.environment.color = Vec3(1.0, 0.8, 0.6);
  s.environment.intensity = 0.5;
  s.paper.frontColor = Vec3(0.8, 0.8, 0.8);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  const Vec3 expected = 0.8 * 0.5 * Vec3(1.0, 0.8, 0.6);
  const Vec3 opaque = centreMean(r.render(s, sheet, settings(8)), 6, 6);
  EXPECT_NEAR((opaque - expected).cwiseAbs().maxCoeff(), 0.0, 0.01 * expected.x());
  // Translucent: what is not reflected comes through from the sky below.
  s.paper.transmittance = 0.4;
  s.paper.backColor = Vec3(0.8, 0.8, 0.8);
  const Vec3 translucent = centreMean(r.render(s, sheet, settings(8)), 6, 6);
  EXPECT_NEAR((translucent - expected).cwiseAbs().maxCoeff(), 0.0, 0.01 * expected.x());
}

TEST(EmbreeRenderer, PointLightFallsOffWithInverseSquareDistance) {
  EmbreeRenderer r;
  RenderScene s = plainScene(64, 48);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  Light point;
  point.kind = Light::Kind::Point;
  point.intensity = 0.05;
  for (const double d : {0.2, 0.4}) {
    point.position = Vec3(0.0, d, 0.0);
    s.lights = {point};
    const ImageRGBAF img = r.render(s, sheet, settings(4, 0));
    // Pixel centres around the image centre: I cos / r^2 = I d / r^3.
    for (int y = 22; y < 26; ++y)
      for (int x = 30; x < 34; ++x) {
        const Vec3 p = pixelCentreOnPlane(s.camera, x, y, 0.0);
        const double dist = (point.position - p).norm();
        const double expected = point.intensity * d / (dist * dist * dist);
        EXPECT_NEAR(straight(img, x, y).x(), expected, 0.005 * expected) << x << "," << y;
      }
  }
}

// Irradiance / pi (the radiance of a white Lambertian receiver) at a point
// under the centre of a parallel rectangle a x b at height h, radiance L.
double underRectangle(double a, double b, double h, double L) {
  // Four quadrants with a corner above the point (the classic form factor).
  const double x = 0.5 * a, y = 0.5 * b;
  const double sx = std::sqrt(x * x + h * h), sy = std::sqrt(y * y + h * h);
  const double corner = 0.5 * (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy));
  return 4.0 * corner * L / std::numbers::pi;
}

TEST(EmbreeRenderer, AreaLightMatchesFarFieldPointLightAndNearFieldClosedForm) {
  EmbreeRenderer r;
  RenderScene s = plainScene(64, 48);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  Light area;
  area.kind = Light::Kind::Area;
  area.direction = Vec3(0.0, -1.0, 0.0);
  area.intensity = 0.5;
  // Far field: a 2 cm square 1 m up is a point light of the same intensity.
  area.size = Vec2(0.02, 0.02);
  area.position = Vec3(0.0, 1.0, 0.0);
  s.lights = {area};
  const Vec3 farArea = centreMean(r.render(s, sheet, settings(16, 0)), 2, 2);
  Light point = area;
  point.kind = Light::Kind::Point;
  s.lights = {point};
  const Vec3 farPoint = centreMean(r.render(s, sheet, settings(16, 0)), 2, 2);
  EXPECT_NEAR(farArea.x(), farPoint.x(), 0.02 * farPoint.x());
  EXPECT_NEAR(farPoint.x(), 0.5, 0.005);
  // Near field: a 0.4 x 0.3 m panel 0.1 m above the sheet (both MIS
  // strategies matter): the exact rectangle form factor.
  area.size = Vec2(0.4, 0.3);
  area.position = Vec3(0.0, 0.1, 0.0);
  s.lights = {area};
  const ImageRGBAF near = r.render(s, sheet, settings(32, 0));
  dump("area_near", near);
  const double L = std::numbers::pi * area.intensity / (0.4 * 0.3);
  const double expected = underRectangle(0.4, 0.3, 0.1, L);
  EXPECT_NEAR(centreMean(near, 2, 2).x(), expected, 0.02 * expected);
  // One-sided: nothing when the panel faces away.
  s.lights[0].direction = Vec3(0.0, 1.0, 0.0);
  EXPECT_EQ(centreMean(r.render(s, sheet, settings(4, 0)), 2, 2), Vec3::Zero());
}

TEST(EmbreeRenderer, SunDiscGivesIntensityTimesCosine) {
  EmbreeRenderer r;
  RenderScene s = plainScene(64, 48);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  // A large disc (1.2 rad across) 30 degrees from the normal: entirely above
  // the horizon, so the irradiance is exactly pi * I * cos. BSDF samples
  // carry ~8 % of it (MIS).
  Light sun = directional(Vec3(0.5, -std::sqrt(0.75), 0.0), 0.8);
  sun.angle = 1.2;
  s.lights = {sun};
  const ImageRGBAF img = r.render(s, sheet, settings(16, 0));
  const double expected = 0.8 * std::sqrt(0.75);
  EXPECT_NEAR(centreMean(img, 8, 8).x(), expected, 0.01 * expected);
  // A small disc at normal incidence: I.
  s.lights[0].direction = Vec3(0.0, -1.0, 0.0);
  s.lights[0].angle = 0.0093;
  EXPECT_NEAR(centreMean(r.render(s, sheet, settings(4, 0)), 8, 8).x(), 0.8, 0.008);
}

TEST(EmbreeRenderer, BackLitPaperGlowsWithTransmittance) {
  EmbreeRenderer r;
  RenderScene s = plainScene(64, 48);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  s.paper.frontColor = s.paper.backColor = Vec3(0.9, 0.8, 0.7);
  s.paper.transmittance = 0.25;
  s.lights = {directional(Vec3(0.0, 1.0, 0.0), 0.6)};  // from below, camera above
  const Vec3 front = centreMean(r.render(s, sheet, settings(4)), 6, 6);
  const Vec3 expected = 0.6 * 0.25 * Vec3(0.9, 0.8, 0.7);
  EXPECT_NEAR((front - expected).cwiseAbs().maxCoeff(), 0.0, 0.01 * expected.z());
  // Lit from the camera's side the same sheet reflects a (1 - T).
  s.lights = {directional(Vec3(0.0, -1.0, 0.0), 0.6)};
  const Vec3 lit = centreMean(r.render(s, sheet, settings(4)), 6, 6);
  EXPECT_NEAR((lit - 0.6 * 0.75 * Vec3(0.9, 0.8, 0.7)).cwiseAbs().maxCoeff(), 0.0, 0.005);
  // The back, seen and lit from below, reflects with the back colour; seen
  // from below and lit from above it transmits (the seen side's albedo).
  s.paper.backColor = Vec3(0.3, 0.6, 0.9);
  s.camera = Camera::lookAt(Vec3(0.0, -0.5, 0.0), Vec3::Zero(), -Vec3::UnitZ(), 0.7, 64, 48);
  s.lights = {directional(Vec3(0.0, 1.0, 0.0), 0.6)};
  const Vec3 back = centreMean(r.render(s, sheet, settings(4)), 6, 6);
  EXPECT_NEAR((back - 0.6 * 0.75 * Vec3(0.3, 0.6, 0.9)).cwiseAbs().maxCoeff(), 0.0, 0.005);
  s.lights = {directional(Vec3(0.0, -1.0, 0.0), 0.6)};
  const Vec3 through = centreMean(r.render(s, sheet, settings(4)), 6, 6);
  EXPECT_NEAR((through - 0.6 * 0.25 * Vec3(0.3, 0.6, 0.9)).cwiseAbs().maxCoeff(), 0.0, 0.005);
}

// Two layers 1 mm apart, lit from above, seen from below: with opaque paper
// and no environment the underside is black (no leak through the sheet,
// whatever the bounces); the ground is black under the paper.
TEST(EmbreeRenderer, NoLightLeaksThroughOpaquePaper) {
  EmbreeRenderer r;
  RenderScene s = plainScene(48, 36);
  s.camera = Camera::lookAt(Vec3(0.05, -0.4, 0.02), Vec3::Zero(), -Vec3::UnitZ(), 0.7, 48, 36);
  mesh::SheetMesh sheet = flatSheet(0.0);
  const mesh::SheetMesh upper = flatSheet(0.001);
  const auto n = static_cast<int>(sheet.positions.size());
  sheet.positions.insert(sheet.positions.end(), upper.positions.begin(), upper.positions.end());
  sheet.pattern.insert(sheet.pattern.end(), upper.pattern.begin(), upper.pattern.end());
  for (const auto& t : upper.triangles) sheet.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  s.lights = {directional(Vec3(0.3, -1.0, 0.2), 1.0)};
  const ImageRGBAF img = r.render(s, sheet, settings(8, 6));
  int covered = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const float* p = img.at(x, y);
      covered += p[3] > 0.0f;
      EXPECT_EQ(p[0] + p[1] + p[2], 0.0f) << x << "," << y;
    }
  EXPECT_GT(covered, 200);
  // A single translucent layer does let light through.
  s.paper.transmittance = 0.3;
  const ImageRGBAF one = r.render(s, flatSheet(0.0), settings(4, 2));
  EXPECT_GT(centreMean(one, 2, 2).x(), 0.2);
}

// --- alpha cut-outs -----------------------------------------------------------------

TEST(EmbreeRenderer, AlphaCutOutShowsTheLitGroundAndNothingElseChanges) {
  EmbreeRenderer r;
  RenderScene s = plainScene(80, 60);
  s.ground.enabled = true;
  s.ground.height = 0.0;
  s.ground.size = 1.0;
  s.ground.color = Vec3(0.5, 0.4, 0.3);
  s.lights = {directional(Vec3(0.0, -1.0, 0.0), 0.9)};
  const mesh::SheetMesh sheet = flatSheet(0.01);
  // A 32x32 texture over the sheet; texels 8..23 in both directions cut.
  const ImageRGBA8 tex = textureWithHole(32, 8, 24);
  const PathTraceSettings ps = settings(4, 0);
  s.paper.texture = tex;
  const ImageRGBAF cut = r.render(s, sheet, ps);
  dump("alpha_cut", cut);
  ImageRGBA8 opaqueTex = tex;
  for (std::size_t i = 3; i < opaqueTex.pixels.size(); i += 4) opaqueTex.pixels[i] = 255;
  s.paper.texture = opaqueTex;
  const ImageRGBAF opaque = r.render(s, sheet, ps);
  ImageRGBA8 noneTex = tex;
  for (std::size_t i = 3; i < noneTex.pixels.size(); i += 4) noneTex.pixels[i] = 0;
  s.paper.texture = noneTex;
  const ImageRGBAF none = r.render(s, sheet, ps);

  // Classify pixels by the pattern point at their centre (with a margin of
  // 2 pixels around the hole's border, ~ 0.5 texel).
  const double texel = kSheetWidth / 32.0, texelV = kSheetHeight / 32.0;
  int inside = 0, outside = 0;
  for (int y = 0; y < s.camera.height; ++y)
    for (int x = 0; x < s.camera.width; ++x) {
      const Vec2 q = flatSheetPattern(pixelCentreOnPlane(s.camera, x, y, 0.01));
      if (q.x() < 0.02 || q.x() > kSheetWidth - 0.02 || q.y() < 0.02 || q.y() > kSheetHeight - 0.02)
        continue;
      const double tu = q.x() / texel, tv = (kSheetHeight - q.y()) / texelV;  // texel coordinates
      const bool inHole = tu > 8.5 && tu < 23.5 && tv > 8.5 && tv < 23.5;
      const bool farFromHole = tu < 7.0 || tu > 25.0 || tv < 7.0 || tv > 25.0;
      const float* c = cut.at(x, y);
      if (inHole) {
        // The ground as if there were no paper: lit (the shadow has a hole too).
        const float* g = none.at(x, y);
        for (int k = 0; k < 4; ++k) EXPECT_FLOAT_EQ(c[k], g[k]) << x << "," << y;
        EXPECT_NEAR(c[0], 0.9 * 0.5, 0.01);
        ++inside;
      } else if (farFromHole) {
        const float* o = opaque.at(x, y);
        for (int k = 0; k < 4; ++k) EXPECT_FLOAT_EQ(c[k], o[k]) << x << "," << y;
        ++outside;
      }
    }
  EXPECT_GT(inside, 50);
  EXPECT_GT(outside, 200);
  EXPECT_EQ(r.droppedSamples(), 0u);
}

// The shadow of a cut sheet on the ground, seen from the side below the sheet:
// lit where the light passes through the hole, dark elsewhere under the paper.
TEST(EmbreeRenderer, AlphaCutOutLetsLightThroughOnlyTheHole) {
  EmbreeRenderer r;
  RenderScene s = plainScene(96, 72);
  s.ground.enabled = true;
  s.ground.size = 1.0;
  s.ground.color = Vec3(1.0, 1.0, 1.0);
  s.lights = {directional(Vec3(0.0, -1.0, 0.0), 1.0)};
  // The sheet 5 cm up, a hole in the middle; the camera looks at the ground
  // under it from the side, between sheet and ground.
  const mesh::SheetMesh sheet = flatSheet(0.05);
  const ImageRGBA8 tex = textureWithHole(4, 1, 3);
  s.paper.texture = tex;
  s.camera = Camera::lookAt(Vec3(0.25, 0.04, 0.0), Vec3(0.0, 0.0, 0.0), Vec3::UnitY(), 0.5, 96, 72);
  const ImageRGBAF img = r.render(s, sheet, settings(4, 0));
  dump("alpha_shadow", img);
  // Ground points under the hole (the hole spans the middle half of the
  // bilinear alpha: |x| < 0.21/4, |z| < 0.297/4) and under the paper.
  auto radianceAt = [&](const Vec3& world) {
    const auto p = projectToPixel(s.camera, world);
    EXPECT_TRUE(p.has_value());
    return straight(img, static_cast<int>(p->x()), static_cast<int>(p->y())).x();
  };
  EXPECT_NEAR(radianceAt(Vec3(0.0, 0.0, 0.0)), 1.0, 0.01);
  EXPECT_NEAR(radianceAt(Vec3(0.03, 0.0, 0.03)), 1.0, 0.01);
  EXPECT_EQ(radianceAt(Vec3(-0.08, 0.0, 0.0)), 0.0);
  EXPECT_EQ(radianceAt(Vec3(0.08, 0.0, 0.0)), 0.0);
  EXPECT_EQ(radianceAt(Vec3(0.09, 0.0, -0.06)), 0.0);
  EXPECT_NEAR(radianceAt(Vec3(0.15, 0.0, 0.0)), 1.0, 0.01);  // beyond the sheet
}

// --- shading normals ------------------------------------------------------------

// A sheet folded down by `angle` along the grid line pattern x = 0.09 (a ridge).
mesh::SheetMesh foldedSheet(double angle) {
  mesh::SheetMesh m = flatSheet(0.0);
  const double crease = 0.09 - 0.5 * kSheetWidth;  // world x of the crease
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    Vec3& p = m.positions[i];
    if (p.x() <= crease) continue;
    const double d = p.x() - crease;
    p = Vec3(crease + d * std::cos(angle), -d * std::sin(angle), p.z());
  }
  return m;
}

TEST(EmbreeRenderer, ShadingIsSplitAcrossSharpCreasesAndSmoothAcrossGentleOnes) {
  EmbreeRenderer r;
  RenderScene s = plainScene(160, 120);
  s.lights = {directional(Vec3(0.0, -1.0, 0.0), 1.0)};
  const mesh::SheetMesh sheet = foldedSheet(50.0 * std::numbers::pi / 180.0);
  const double creaseX = 0.09 - 0.5 * kSheetWidth;
  const auto crease = projectToPixel(s.camera, Vec3(creaseX, 0.0, 0.0));
  ASSERT_TRUE(crease.has_value());
  const int cx = static_cast<int>(std::floor(crease->x())), cy = 60;
  // creaseAngle 30 degrees < the 50 degree fold: two flat-shaded faces.
  s.paper.creaseAngle = 30.0 * std::numbers::pi / 180.0;
  const ImageRGBAF sharp = r.render(s, sheet, settings(4, 0));
  dump("crease_sharp", sharp);
  EXPECT_NEAR(straight(sharp, cx - 1, cy).x(), 1.0, 0.002);
  EXPECT_NEAR(straight(sharp, cx - 6, cy).x(), 1.0, 0.002);
  const double tilted = std::cos(50.0 * std::numbers::pi / 180.0);
  EXPECT_NEAR(straight(sharp, cx + 2, cy).x(), tilted, 0.01);
  EXPECT_NEAR(straight(sharp, cx + 6, cy).x(), tilted, 0.01);
  // creaseAngle 70 degrees: the normals are averaged at the crease, so the
  // pixel next to it is darker than the flat face and brighter on the other side.
  s.paper.creaseAngle = 70.0 * std::numbers::pi / 180.0;
  const ImageRGBAF smooth = r.render(s, sheet, settings(4, 0));
  dump("crease_smooth", smooth);
  EXPECT_LT(straight(smooth, cx - 1, cy).x(), 0.98);
  EXPECT_GT(straight(smooth, cx + 2, cy).x(), tilted + 0.02);
}

TEST(EmbreeRenderer, CurvedSheetIsShadedSmoothly) {
  EmbreeRenderer r;
  RenderScene s = plainScene(160, 120);
  s.lights = {directional(Vec3(0.0, -1.0, 0.0), 1.0)};
  // A valley of radius 0.15 m across the whole width (facets of ~0.1 rad).
  mesh::SheetMesh sheet = flatSheet(0.0);
  for (Vec3& p : sheet.positions) {
    const double a = p.x() / 0.15;
    p = Vec3(0.15 * std::sin(a), 0.15 * (1.0 - std::cos(a)), p.z());
  }
  // Largest jump between horizontal neighbours along the middle rows.
  auto maxJump = [&](const ImageRGBAF& img) {
    double jump = 0.0;
    for (int y = 50; y < 70; ++y)
      for (int x = 1; x < img.width; ++x)
        if (img.at(x, y)[3] == 1.0f && img.at(x - 1, y)[3] == 1.0f)
          jump = std::max(jump, std::abs(straight(img, x, y).x() - straight(img, x - 1, y).x()));
    return jump;
  };
  s.paper.creaseAngle = 0.5;
  const ImageRGBAF smooth = r.render(s, sheet, settings(4, 0));
  s.paper.creaseAngle = 0.0;  // every edge sharp: faceted
  const ImageRGBAF faceted = r.render(s, sheet, settings(4, 0));
  dump("curved_smooth", smooth);
  dump("curved_faceted", faceted);
  EXPECT_LT(maxJump(smooth), 0.02);
  EXPECT_LT(maxJump(smooth), 0.5 * maxJump(faceted));
  // Sharp vertices are faceted too (every vertex listed).
  s.paper.creaseAngle = 0.5;
  for (int v = 0; v < static_cast<int>(sheet.positions.size()); ++v) s.sharpVertices.push_back(v);
  EXPECT_EQ(r.render(s, sheet, settings(4, 0)).pixels, faceted.pixels);
}

// --- sampling -----------------------------------------------------------------

TEST(EmbreeRenderer, IdenticalForAnyThreadCountAndSeedDependent) {
  const ThreadCountGuard guard;
  EmbreeRenderer r;
  const RenderScene s = bentScene(72, 54);
  const mesh::SheetMesh sheet = bentSceneSheet();
  PathTraceSettings ps = settings(4);
  ps.seed = 7;
  ps.frame = 3;
  setThreadCount(1);
  const ImageRGBAF one = r.render(s, sheet, ps);
  setThreadCount(2);
  const ImageRGBAF two = r.render(s, sheet, ps);
  const ImageRGBAF again = r.render(s, sheet, ps);
  EXPECT_EQ(one.pixels, two.pixels);
  EXPECT_EQ(two.pixels, again.pixels);
  ps.seed = 8;
  const ImageRGBAF otherSeed = r.render(s, sheet, ps);
  EXPECT_NE(otherSeed.pixels, one.pixels);
  ps.seed = 7;
  ps.frame = 4;
  const ImageRGBAF otherFrame = r.render(s, sheet, ps);
  EXPECT_NE(otherFrame.pixels, one.pixels);
  // Same expectation, different noise.
  EXPECT_LT(meanAbs(one, otherSeed), 0.05);
}

TEST(EmbreeRenderer, ErrorDecreasesWithSamples) {
  EmbreeRenderer r;
  RenderScene s = bentScene(64, 48);
  s.paper.transmittance = 0.2;
  Light sun = s.lights[0];
  sun.angle = 0.1;
  s.lights[0] = sun;
  const mesh::SheetMesh sheet = bentSceneSheet();
  PathTraceSettings ps = settings(256);
  ps.seed = 100;
  const ImageRGBAF reference = r.render(s, sheet, ps);
  ps.seed = 1;
  ps.samplesPerPixel = 4;
  const double e4 = rmse(r.render(s, sheet, ps), reference);
  ps.samplesPerPixel = 16;
  const double e16 = rmse(r.render(s, sheet, ps), reference);
  ps.samplesPerPixel = 64;
  const double e64 = rmse(r.render(s, sheet, ps), reference);
  std::cout << "RMSE 4/16/64 spp: " << e4 << " " << e16 << " " << e64 << "\n";
  EXPECT_LT(e16, 0.6 * e4);
  EXPECT_LT(e64, 0.6 * e16);
  dump("bent_reference", reference);
}

// --- albedo pass, lens ------------------------------------------------------------

TEST(EmbreeRenderer, AlbedoPassShowsTextureTimesSideColour) {
  EmbreeRenderer r;
  RenderScene s = plainScene(80, 60);
  // A smooth 4x4 texture (bilinear across the whole sheet).
  ImageRGBA8 tex(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      std::uint8_t* p = tex.at(x, y);
      p[0] = static_cast<std::uint8_t>(60 + 60 * x);
      p[1] = static_cast<std::uint8_t>(40 + 70 * y);
      p[2] = static_cast<std::uint8_t>(200 - 20 * x - 20 * y);
      p[3] = 255;
    }
  s.paper.texture = tex;
  s.paper.frontColor = Vec3(0.9, 0.8, 0.7);
  s.paper.backColor = Vec3(0.3, 0.6, 0.9);
  s.ground.enabled = true;
  s.ground.height = -0.01;
  s.ground.color = Vec3(0.2, 0.3, 0.4);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  PathTraceSettings ps = settings(16);
  ps.pass = RenderPass::Albedo;
  for (const bool fromBelow : {false, true}) {
    if (fromBelow) {
      s.ground.enabled = false;
      s.camera = Camera::lookAt(Vec3(0.0, -0.5, 0.0), Vec3::Zero(), -Vec3::UnitZ(), 0.7, 80, 60);
    }
    const ImageRGBAF img = r.render(s, sheet, ps);
    dump(fromBelow ? "albedo_back" : "albedo_front", img);
    int checked = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const Vec2 q = flatSheetPattern(pixelCentreOnPlane(s.camera, x, y, 0.0));
        const bool onSheet = q.x() > 0.005 && q.x() < kSheetWidth - 0.005 && q.y() > 0.005 &&
                             q.y() < kSheetHeight - 0.005;
        const bool offSheet = q.x() < -0.005 || q.x() > kSheetWidth + 0.005 || q.y() < -0.005 ||
                              q.y() > kSheetHeight + 0.005;
        const float* p = img.at(x, y);
        if (onSheet) {
          const Vec4 t = sampleTexture(tex, patternToUv(q, s.paper.textureSize));
          const Vec3 expected =
              t.head<3>().cwiseProduct(fromBelow ? s.paper.backColor : s.paper.frontColor);
          EXPECT_EQ(p[3], 1.0f);
          for (int k = 0; k < 3; ++k) EXPECT_NEAR(p[k], expected[k], 2.0 / 255.0) << x << "," << y;
          ++checked;
        } else if (offSheet) {
          if (fromBelow) {
            EXPECT_EQ(p[3], 0.0f);  // background
          } else {
            for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(p[k], s.ground.color[k]);
          }
        }
      }
    EXPECT_GT(checked, 1000);
  }
}

TEST(EmbreeRenderer, ThinLensIsSharpInTheFocusPlaneOnly) {
  EmbreeRenderer r;
  RenderScene s = plainScene(64, 48);
  s.paper.texture = makeRuledPaperTexture(256, 362);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  PathTraceSettings ps = settings(16);
  ps.pass = RenderPass::Albedo;
  const ImageRGBAF pinhole = r.render(s, sheet, ps);
  s.camera.apertureRadius = 0.02;
  s.camera.focusDistance = 0.5;  // the sheet
  const ImageRGBAF focused = r.render(s, sheet, ps);
  s.camera.focusDistance = 0.25;
  const ImageRGBAF blurred = r.render(s, sheet, ps);
  dump("lens_blurred", blurred);
  const double sharpDiff = meanAbs(focused, pinhole), blurDiff = meanAbs(blurred, pinhole);
  EXPECT_LT(sharpDiff, 0.004);
  EXPECT_GT(blurDiff, 4.0 * sharpDiff);
}

// --- robustness -----------------------------------------------------------------

TEST(EmbreeRenderer, NonFiniteSamplesAreDroppedAndCounted) {
  EmbreeRenderer r;
  RenderScene s = plainScene(16, 12);
  // Finite in double, infinite in the renderer's float arithmetic.
  s.lights = {directional(Vec3(0.0, -1.0, 0.0), 1e39)};
  const ImageRGBAF img = r.render(s, flatSheet(0.0), settings(2, 0));
  EXPECT_GT(r.droppedSamples(), 0u);
  for (const float v : img.pixels) EXPECT_TRUE(std::isfinite(v));
  s.lights = {directional(Vec3(0.0, -1.0, 0.0), 1.0)};
  r.render(s, flatSheet(0.0), settings(2, 0));
  EXPECT_EQ(r.droppedSamples(), 0u);
}

TEST(EmbreeRenderer, EmptySheetAndPropsRender) {
  EmbreeRenderer r;
  RenderScene s = plainScene(32, 24);
  s.lights = {directional(Vec3(0.0, -1.0, 0.0), 1.0)};
  // No sheet, no ground: everything is background.
  const ImageRGBAF empty = r.render(s, mesh::SheetMesh{}, settings(2));
  for (const float v : empty.pixels) EXPECT_EQ(v, 0.0f);
  // A prop square (two-sided Lambert) under the camera.
  PropMesh prop;
  prop.name = "board";
  prop.vertices = {Vec3(-1, 0, -1), Vec3(1, 0, -1), Vec3(1, 0, 1), Vec3(-1, 0, 1)};
  prop.triangles = {{0, 1, 2}, {0, 2, 3}};  // facing down: two-sided anyway
  prop.color = Vec3(0.5, 0.25, 0.125);
  s.props = {prop};
  const Vec3 c = centreMean(r.render(s, mesh::SheetMesh{}, settings(2)), 4, 4);
  EXPECT_NEAR((c - prop.color).cwiseAbs().maxCoeff(), 0.0, 1e-5);
}

TEST(EmbreeRenderer, InvalidInputThrows) {
  EmbreeRenderer r;
  const RenderScene good = plainScene(16, 12);
  const mesh::SheetMesh sheet = flatSheet(0.0);
  const PathTraceSettings ps = settings(1);
  EXPECT_NO_THROW(r.render(good, sheet, ps));
  auto throwsWith =
      [&](const std::function<void(RenderScene&, mesh::SheetMesh&, PathTraceSettings&)>& breakIt) {
        RenderScene s = good;
        mesh::SheetMesh m = sheet;
        PathTraceSettings p = ps;
        breakIt(s, m, p);
        EXPECT_THROW(r.render(s, m, p), std::invalid_argument);
      };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  throwsWith([](RenderScene&, mesh::SheetMesh&, PathTraceSettings& p) { p.samplesPerPixel = 0; });
  throwsWith([](RenderScene&, mesh::SheetMesh&, PathTraceSettings& p) { p.maxBounces = -1; });
  throwsWith([](RenderScene& s, mesh::SheetMesh&, PathTraceSettings&) { s.camera.width = 0; });
  throwsWith([](RenderScene& s, mesh::SheetMesh&, PathTraceSettings&) { s.camera.height = -3; });
  throwsWith([](RenderScene& s, mesh::SheetMesh&, PathTraceSettings&) { s.camera.yfov = 0.0; });
  throwsWith([](RenderScene& s, mesh::SheetMesh&, PathTraceSettings&) {
    s.camera.yfov = std::numbers::pi;
  });
  throwsWith(
      [&](RenderScene& s, mesh::SheetMesh&, PathTraceSettings&) { s.camera.position.x() = nan; });
  throwsWith([](RenderScene& s, mesh::SheetMesh&, PathTraceSettings&) {
    s.camera.apertureRadius = 0.01;
    s.camera.focusDistance = 0.0;
  });
  throwsWith([&](RenderScene& s, mesh::SheetMesh&, PathTraceSettings&) {
    s.lights = {directional(Vec3(0.0, -1.0, 0.0), nan)};
  });
  throwsWith([](RenderScene& s, mesh::SheetMesh&, PathTraceSettings&) {
    s.lights = {directional(Vec3::Zero(), 1.0)};
  });
  throwsWith([](RenderScene& s, mesh::SheetMesh&, PathTraceSettings&) {
    Light a;
    a.kind = Light::Kind::Area;
    a.size = Vec2(0.1, 0.0);
    s.lights = {a};
  });
  throwsWith(
      [](RenderScene& s, mesh::SheetMesh&, PathTraceSettings&) { s.paper.transmittance = 1.5; });
  throwsWith([](RenderScene&, mesh::SheetMesh& m, PathTraceSettings&) {
    m.triangles[3][1] = static_cast<int>(m.positions.size());
  });
  throwsWith([](RenderScene&, mesh::SheetMesh& m, PathTraceSettings&) { m.triangles[0][0] = -1; });
  throwsWith([&](RenderScene&, mesh::SheetMesh& m, PathTraceSettings&) {
    m.positions[5].y() = std::numeric_limits<double>::infinity();
  });
  throwsWith([](RenderScene&, mesh::SheetMesh& m, PathTraceSettings&) { m.pattern.pop_back(); });
  throwsWith([](RenderScene& s, mesh::SheetMesh&, PathTraceSettings&) {
    PropMesh p;
    p.vertices = {Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY()};
    p.triangles = {{0, 1, 3}};
    s.props = {p};
  });
}

TEST(EmbreeRenderer, ToSrgb8UnpremultipliesAndFillsTheBackground) {
  ImageRGBAF img(4, 1);
  const float a[16] = {0.25f,  0.1f, 0.05f, 0.5f,     // half covered
                       0.0f,   0.0f, 0.0f,  0.0f,     // background
                       0.3f,   2.0f, 0.0f,  1.0f,     // clamped
                       0.001f, 0.0f, 0.0f,  0.001f};  // alpha rounds to 0: background
  std::copy(a, a + 16, img.pixels.begin());
  const Vec3 bg(0.8, 0.2, 0.1);
  const ImageRGBA8 out = toSrgb8(img, bg);
  const std::uint8_t* p = out.at(0, 0);
  EXPECT_EQ(p[0], linearToSrgb8(0.5));
  EXPECT_EQ(p[1], linearToSrgb8(0.2));
  EXPECT_EQ(p[2], linearToSrgb8(0.1));
  EXPECT_EQ(p[3], 128);
  const std::uint8_t* q = out.at(1, 0);
  EXPECT_EQ(q[0], linearToSrgb8(0.8));
  EXPECT_EQ(q[1], linearToSrgb8(0.2));
  EXPECT_EQ(q[2], linearToSrgb8(0.1));
  EXPECT_EQ(q[3], 0);
  const std::uint8_t* w = out.at(2, 0);
  EXPECT_EQ(w[0], linearToSrgb8(0.3));
  EXPECT_EQ(w[1], 255);
  EXPECT_EQ(w[2], 0);
  EXPECT_EQ(w[3], 255);
  const std::uint8_t* t = out.at(3, 0);
  EXPECT_EQ(t[0], q[0]);
  EXPECT_EQ(t[3], 0);
}

// --- timing (CRUMPLE_PT_BENCH=1) ----------------------------------------------------

}  // namespace
}  // namespace crumple::render
