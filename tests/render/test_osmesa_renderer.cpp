// OsmesaRenderer tests. Set CRUMPLE_RENDER_DUMP=1 to write every rendered
// image as PNG into the build directory (tests/render/*.png) for a look;
// CRUMPLE_BLESS=1 rewrites the golden image instead of comparing with it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "crumple/render/osmesa_renderer.hpp"
#include "png_io.hpp"
#include "render_test_scenes.hpp"
#include "render_test_util.hpp"

namespace crumple::render {
namespace {

using namespace test;  // the shared scenes and helpers

ImageRGBA8 whiteTexture() {
  ImageRGBA8 t(1, 1);
  std::fill(t.pixels.begin(), t.pixels.end(), std::uint8_t{255});
  return t;
}

double luma(const std::uint8_t* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

// Signed distance (pixels, positive inside) of a point to a convex polygon
// given counter-clockwise or clockwise.
double insideDistance(const std::array<Vec2, 4>& poly, const Vec2& q) {
  double area = 0.0;
  for (int i = 0; i < 4; ++i) {
    const Vec2& a = poly[static_cast<std::size_t>(i)];
    const Vec2& b = poly[static_cast<std::size_t>((i + 1) % 4)];
    area += a.x() * b.y() - b.x() * a.y();
  }
  const double orient = area > 0.0 ? 1.0 : -1.0;
  double d = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {
    const Vec2& a = poly[static_cast<std::size_t>(i)];
    const Vec2& b = poly[static_cast<std::size_t>((i + 1) % 4)];
    const Vec2 e = b - a;
    const double cross = e.x() * (q.y() - a.y()) - e.y() * (q.x() - a.x());
    d = std::min(d, orient * cross / e.norm());
  }
  return d;
}

RenderScene simpleScene(const Camera& cam) {
  RenderScene s;
  s.camera = cam;
  Light l;
  l.direction = Vec3(-0.3, -1.0, -0.2);
  s.lights = {l};
  return s;
}

TEST(OsmesaRenderer, FlatSheetCoversItsProjection) {
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  const RenderScene scene = simpleScene(topCamera(0.6, w, h));
  const mesh::SheetMesh sheet = flatSheet(0.0);
  const ImageRGBA8 img = r.render(scene, sheet);
  maybeDump("flat_sheet", img);
  ASSERT_EQ(img.width, w);
  ASSERT_EQ(img.height, h);
  ASSERT_EQ(img.pixels.size(), static_cast<std::size_t>(w * h * 4));

  const double hw = 0.5 * kSheetWidth, hh = 0.5 * kSheetHeight;
  std::array<Vec2, 4> quad{};
  const std::array<Vec3, 4> corners = {Vec3(-hw, 0, hh), Vec3(hw, 0, hh), Vec3(hw, 0, -hh),
                                       Vec3(-hw, 0, -hh)};
  for (std::size_t i = 0; i < 4; ++i) {
    const auto p = projectToPixel(scene.camera, corners[i]);
    ASSERT_TRUE(p.has_value());
    quad[i] = *p;
  }
  const std::array<std::uint8_t, 3> bg = {linearToSrgb8(scene.background.x()),
                                          linearToSrgb8(scene.background.y()),
                                          linearToSrgb8(scene.background.z())};
  int inside = 0, outside = 0, partial = 0;
  double coverage = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::uint8_t* p = img.at(x, y);
      const double d = insideDistance(quad, Vec2(x + 0.5, y + 0.5));
      coverage += p[3] / 255.0;
      if (p[3] != 0 && p[3] != 255) ++partial;
      if (d > 1.0) {
        ++inside;
        EXPECT_EQ(p[3], 255) << x << "," << y;
        EXPECT_GT(luma(p), 100.0) << x << "," << y;  // lit paper, not background
      } else if (d < -1.0) {
        ++outside;
        ASSERT_EQ(p[3], 0) << x << "," << y;
        ASSERT_EQ(p[0], bg[0]);
        ASSERT_EQ(p[1], bg[1]);
        ASSERT_EQ(p[2], bg[2]);
      }
    }
  EXPECT_GT(inside, 3000);
  EXPECT_GT(outside, 10000);
  EXPECT_GT(partial, 0);  // antialiased silhouette (MSAA)
  // Total coverage equals the projected area of the sheet.
  double area = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    const Vec2& a = quad[i];
    const Vec2& b = quad[(i + 1) % 4];
    area += 0.5 * (a.x() * b.y() - b.x() * a.y());
  }
  EXPECT_NEAR(coverage, std::abs(area), 0.01 * std::abs(area));
}

TEST(OsmesaRenderer, FrontAndBackColoursShowFromEachSide) {
  const int w = 96, h = 72;
  OsmesaRenderer r(w, h);
  RenderScene scene;
  Light down, up;
  down.direction = Vec3(0, -1, 0);
  up.direction = Vec3(0, 1, 0);
  down.intensity = up.intensity = 0.8;
  scene.lights = {down, up};
  scene.paper.texture = whiteTexture();
  scene.paper.frontColor = Vec3(0.8, 0.1, 0.1);
  scene.paper.backColor = Vec3(0.1, 0.1, 0.8);
  const mesh::SheetMesh sheet = flatSheet(0.0);

  scene.camera = topCamera(0.6, w, h);
  const ImageRGBA8 above = r.render(scene, sheet);
  maybeDump("front_from_above", above);
  scene.camera = Camera::lookAt(Vec3(0, -0.6, 0), Vec3::Zero(), -Vec3::UnitZ(), 0.7, w, h);
  const ImageRGBA8 below = r.render(scene, sheet);
  maybeDump("back_from_below", below);

  const std::uint8_t* a = above.at(w / 2, h / 2);
  const std::uint8_t* b = below.at(w / 2, h / 2);
  EXPECT_GT(a[0], a[2] + 80) << "front (red) seen from above";
  EXPECT_GT(b[2], b[0] + 80) << "back (blue) seen from below";
}

TEST(OsmesaRenderer, TextureIsUprightAndNotMirroredOnTheFront) {
  const int w = 120, h = 90;
  OsmesaRenderer r(w, h);
  RenderScene scene = simpleScene(topCamera(0.6, w, h));
  scene.lights[0].direction = Vec3(0, -1, 0);
  ImageRGBA8 tex(2, 2);  // top-left red, top-right green, bottom-left blue, bottom-right yellow
  const std::array<std::array<std::uint8_t, 4>, 4> colors = {
      {{255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}, {255, 255, 0, 255}}};
  for (int i = 0; i < 4; ++i)
    std::copy(colors[static_cast<std::size_t>(i)].begin(),
              colors[static_cast<std::size_t>(i)].end(), tex.at(i % 2, i / 2));
  scene.paper.texture = tex;
  scene.paper.frontColor = Vec3(1, 1, 1);
  const ImageRGBA8 img = r.render(scene, flatSheet(0.0));
  maybeDump("texture_orientation", img);
  // Pattern (u, v) -> world (u - W/2, 0, H/2 - v); the camera sees -Z as up.
  auto at = [&](double u, double v) {
    return pixelAt(
        img, scene.camera,
        Vec3(u * kSheetWidth - 0.5 * kSheetWidth, 0, 0.5 * kSheetHeight - v * kSheetHeight));
  };
  const std::uint8_t* tl = at(0.25, 0.75);
  const std::uint8_t* tr = at(0.75, 0.75);
  const std::uint8_t* bl = at(0.25, 0.25);
  const std::uint8_t* br = at(0.75, 0.25);
  EXPECT_GT(tl[0], 150);
  EXPECT_LT(tl[1], 60);
  EXPECT_GT(tr[1], 150);
  EXPECT_LT(tr[0], 60);
  EXPECT_GT(bl[2], 150);
  EXPECT_LT(bl[0], 60);
  EXPECT_GT(br[0], 150);
  EXPECT_GT(br[1], 150);
  EXPECT_LT(br[2], 60);
  // The image keeps that layout: red is upper left of green, above blue.
  const auto ptl = projectToPixel(scene.camera, Vec3(-0.05, 0, -0.07));
  ASSERT_TRUE(ptl.has_value());
  EXPECT_LT(ptl->x(), w / 2.0);
  EXPECT_LT(ptl->y(), h / 2.0);
}

TEST(OsmesaRenderer, RuledTextureShowsAlongV) {
  const int w = 400, h = 300;
  OsmesaRenderer r(w, h);
  RenderScene scene = simpleScene(topCamera(0.4, w, h));
  scene.lights[0].direction = Vec3(0, -1, 0);
  const ImageRGBA8 img = r.render(scene, flatSheet(0.0));  // empty texture = ruled paper
  maybeDump("ruled_texture", img);
  // A column at world x = 0.05 (right of the margin), over the ruled part.
  int blue = 0, white = 0, samples = 0;
  for (double v = 0.05; v < 0.25; v += 0.0005) {
    const std::uint8_t* p = pixelAt(img, scene.camera, Vec3(0.05, 0, 0.5 * kSheetHeight - v));
    ++samples;
    if (p[2] > p[0] + 15) ++blue;
    if (std::abs(int(p[0]) - int(p[2])) < 8 && p[0] > 200) ++white;
  }
  EXPECT_GT(blue, samples / 20);
  EXPECT_GT(white, samples / 3);
  // The red margin 30 mm from the left edge.
  int red = 0;
  for (double u = 0.0; u < 0.06; u += 0.0005) {
    const std::uint8_t* p = pixelAt(img, scene.camera, Vec3(-0.5 * kSheetWidth + u, 0, 0.0));
    if (p[0] > p[1] + 25 && p[0] > p[2] + 25) ++red;
  }
  EXPECT_GE(red, 1);
}

RenderScene shadowScene(bool shadow, const Camera& cam) {
  RenderScene s;
  s.camera = cam;
  Light key;
  key.direction = Vec3(1, -1, 0);
  key.shadow = shadow;
  s.lights = {key};
  s.ground.enabled = true;
  s.ground.size = 2.0;
  s.ground.color = Vec3(0.5, 0.5, 0.5);
  s.paper.texture = whiteTexture();
  return s;
}

TEST(OsmesaRenderer, DirectionalKeyLightShadowsTheGround) {
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  const Camera cam = topCamera(1.0, w, h);
  const mesh::SheetMesh sheet = flatSheet(0.2);  // hovering 0.2 m above the ground
  // Light travels along (1, -1, 0): the shadow is the sheet shifted by +0.2 in x.
  const Vec3 inShadow(0.25, 0, 0), litA(0.25, 0, 0.3), litB(-0.35, 0, 0);

  const ImageRGBA8 with = r.render(shadowScene(true, cam), sheet);
  maybeDump("shadow_directional", with);
  const ImageRGBA8 without = r.render(shadowScene(false, cam), sheet);
  maybeDump("shadow_directional_off", without);

  EXPECT_LT(luma(pixelAt(with, cam, inShadow)), 0.6 * luma(pixelAt(with, cam, litA)));
  EXPECT_LT(luma(pixelAt(with, cam, inShadow)), 0.6 * luma(pixelAt(with, cam, litB)));
  EXPECT_NEAR(luma(pixelAt(with, cam, litA)), luma(pixelAt(with, cam, litB)), 1.0);
  EXPECT_NEAR(luma(pixelAt(without, cam, inShadow)), luma(pixelAt(without, cam, litA)), 1.0);
  EXPECT_NEAR(luma(pixelAt(without, cam, inShadow)), luma(pixelAt(without, cam, litB)), 1.0);
  // Lit ground is identical with and without the shadow map.
  EXPECT_NEAR(luma(pixelAt(with, cam, litA)), luma(pixelAt(without, cam, litA)), 1.0);
}

TEST(OsmesaRenderer, PointKeyLightShadowsTheGround) {
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  const Camera cam = topCamera(1.3, w, h);
  RenderScene s = shadowScene(true, cam);
  s.lights[0].kind = Light::Kind::Point;
  s.lights[0].position = Vec3(-0.2, 0.8, 0.0);
  s.lights[0].intensity = 0.64;
  const mesh::SheetMesh sheet = flatSheet(0.2);
  const ImageRGBA8 img = r.render(s, sheet);
  maybeDump("shadow_point", img);
  // (0.18, 0, 0) is in the shadow; (-0.58, 0, 0) is its mirror image about the
  // light (same distance and angle) and lit.
  EXPECT_LT(luma(pixelAt(img, cam, Vec3(0.18, 0, 0))),
            0.6 * luma(pixelAt(img, cam, Vec3(-0.58, 0, 0))));
  s.lights[0].shadow = false;
  const ImageRGBA8 off = r.render(s, sheet);
  EXPECT_NEAR(luma(pixelAt(off, cam, Vec3(0.18, 0, 0))), luma(pixelAt(off, cam, Vec3(-0.58, 0, 0))),
              1.5);
}

TEST(OsmesaRenderer, NoShadowAcneOnALitFlatSheet) {
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  RenderScene scene = simpleScene(topCamera(0.6, w, h));
  scene.paper.texture = whiteTexture();
  scene.lights[0].shadow = true;
  scene.ground.enabled = true;
  scene.ground.height = -0.1;
  const mesh::SheetMesh sheet = flatSheet(0.0);
  const ImageRGBA8 with = r.render(scene, sheet);
  maybeDump("acne_check", with);
  scene.lights[0].shadow = false;
  const ImageRGBA8 without = r.render(scene, sheet);
  const std::uint8_t* ref = with.at(w / 2, h / 2);
  int checked = 0;
  for (double u = 0.01; u < kSheetWidth - 0.01; u += 0.004)
    for (double v = 0.01; v < kSheetHeight - 0.01; v += 0.004) {
      const Vec3 p(u - 0.5 * kSheetWidth, 0.0, 0.5 * kSheetHeight - v);
      const std::uint8_t* a = pixelAt(with, scene.camera, p);
      const std::uint8_t* b = pixelAt(without, scene.camera, p);
      for (int k = 0; k < 3; ++k) {
        ASSERT_NEAR(a[k], ref[k], 1) << "u=" << u << " v=" << v;
        ASSERT_NEAR(a[k], b[k], 1) << "u=" << u << " v=" << v;
      }
      ++checked;
    }
  EXPECT_GT(checked, 1000);
}

TEST(OsmesaRenderer, RenderingTwiceGivesIdenticalBytes) {
  const int w = 160, h = 120;
  const RenderScene scene = bentScene(w, h);
  const mesh::SheetMesh sheet = bentSceneSheet();
  OsmesaRenderer r(w, h);
  const ImageRGBA8 a = r.render(scene, sheet);
  const ImageRGBA8 b = r.render(scene, sheet);
  EXPECT_EQ(a.pixels, b.pixels);
  // Another renderer alive at the same time, and a fresh one.
  OsmesaRenderer other(64, 48);
  const ImageRGBA8 small = other.render(bentScene(64, 48), sheet);
  EXPECT_EQ(small.width, 64);
  const ImageRGBA8 c = r.render(scene, sheet);
  EXPECT_EQ(a.pixels, c.pixels);
  OsmesaRenderer fresh(w, h);
  const ImageRGBA8 d = fresh.render(scene, sheet);
  EXPECT_EQ(a.pixels, d.pixels);
}

TEST(OsmesaRenderer, ConcurrentRenderersInThreadsMatchSerialRender) {
  const int w = 96, h = 72;
  const RenderScene scene = bentScene(w, h);
  const mesh::SheetMesh sheet = bentSceneSheet();
  OsmesaRenderer serial(w, h);
  const ImageRGBA8 reference = serial.render(scene, sheet);
  std::vector<ImageRGBA8> results(3);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < results.size(); ++t)
    threads.emplace_back([&, t] {
      OsmesaRenderer r(w, h);
      for (int i = 0; i < 2; ++i) results[t] = r.render(scene, sheet);
    });
  for (std::thread& t : threads) t.join();
  for (const ImageRGBA8& img : results) EXPECT_EQ(img.pixels, reference.pixels);
  // The serial renderer can move to another thread afterwards.
  ImageRGBA8 moved;
  std::thread([&] { moved = serial.render(scene, sheet); }).join();
  EXPECT_EQ(moved.pixels, reference.pixels);
}

TEST(OsmesaRenderer, PaperLyingOnTheGroundIsVisible) {
  const int w = 96, h = 72;
  OsmesaRenderer r(w, h);
  RenderScene s = shadowScene(true, topCamera(0.6, w, h));
  s.paper.frontColor = Vec3(0.8, 0.1, 0.1);
  s.ground.color = Vec3(0.1, 0.1, 0.8);
  const ImageRGBA8 img = r.render(s, flatSheet(0.0));  // exactly at ground height
  maybeDump("paper_on_ground", img);
  int reddish = 0, checked = 0;
  for (double u = 0.01; u < kSheetWidth - 0.01; u += 0.005)
    for (double v = 0.01; v < kSheetHeight - 0.01; v += 0.005) {
      const std::uint8_t* p =
          pixelAt(img, s.camera, Vec3(u - 0.5 * kSheetWidth, 0.0, 0.5 * kSheetHeight - v));
      ++checked;
      reddish += p[0] > p[2];
    }
  EXPECT_EQ(reddish, checked);
}

TEST(OsmesaRenderer, IdenticalBytesAcrossProcessesAndThreadCounts) {
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  const ImageRGBA8 here = r.render(bentScene(w, h), bentSceneSheet());
  const std::string dir = std::string(CRUMPLE_RENDER_OUT_DIR);
  for (const char* threads : {"0", "1", "2", "4"}) {
    const std::string out = dir + "/render_dump_threads" + threads + ".rgba";
    std::filesystem::remove(out);
    const std::string cmd = std::string("LP_NUM_THREADS=") + threads + " '" +
                            CRUMPLE_RENDER_DUMP_EXE + "' '" + out + "' " + std::to_string(w) + " " +
                            std::to_string(h);
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    EXPECT_EQ(test::readBytes(out), here.pixels) << "LP_NUM_THREADS=" << threads;
  }
}

TEST(OsmesaRenderer, GoldenBentSheet) {
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  const ImageRGBA8 img = r.render(bentScene(w, h), bentSceneSheet());
  maybeDump("bent_sheet", img);
  test::expectMatchesGolden("bent_sheet", img);
}

TEST(OsmesaRenderer, PngRoundTripIsExact) {
  ImageRGBA8 img(7, 5);
  for (std::size_t i = 0; i < img.pixels.size(); ++i)
    img.pixels[i] = static_cast<std::uint8_t>((i * 37 + 11) % 256);
  const std::string path = std::string(CRUMPLE_RENDER_OUT_DIR) + "/roundtrip.png";
  test::writePng(path, img);
  EXPECT_EQ(test::readPng(path).pixels, img.pixels);
}

TEST(OsmesaRenderer, EmptySheetDrawsGroundOnly) {
  const int w = 64, h = 48;
  OsmesaRenderer r(w, h);
  RenderScene s = shadowScene(true, topCamera(0.5, w, h));
  const ImageRGBA8 img = r.render(s, mesh::SheetMesh{});
  EXPECT_EQ(img.at(w / 2, h / 2)[3], 255);
  s.ground.enabled = false;
  const ImageRGBA8 none = r.render(s, mesh::SheetMesh{});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) ASSERT_EQ(none.at(x, y)[3], 0);
}

TEST(OsmesaRenderer, RejectsBadInput) {
  EXPECT_THROW(OsmesaRenderer(0, 10), std::invalid_argument);
  OsmesaRenderer r(32, 24);
  RenderScene s = simpleScene(topCamera(0.6, 32, 24));
  mesh::SheetMesh sheet = flatSheet(0.0);
  RenderScene wrongSize = s;
  wrongSize.camera.width = 64;
  EXPECT_THROW(r.render(wrongSize, sheet), std::invalid_argument);
  mesh::SheetMesh badIndex = sheet;
  badIndex.triangles[0][1] = static_cast<int>(sheet.positions.size());
  EXPECT_THROW(r.render(s, badIndex), std::invalid_argument);
  mesh::SheetMesh nan = sheet;
  nan.positions[3].x() = std::nan("");
  EXPECT_THROW(r.render(s, nan), std::invalid_argument);
  RenderScene badTexture = s;
  badTexture.paper.texture.width = 2;
  badTexture.paper.texture.height = 2;
  badTexture.paper.texture.pixels.assign(3, 0);
  EXPECT_THROW(r.render(badTexture, sheet), std::invalid_argument);
  // Still usable after rejected input.
  EXPECT_EQ(r.render(s, sheet).width, 32);
}

// --- materials, lights and passes -----------------------------------------

// A white texture with a transparent window over uv [0.375, 0.625]^2: on the
// flat sheet, world |X| < W/8 and |Z| < H/8 around the sheet's centre.
ImageRGBA8 windowTexture() {
  ImageRGBA8 t(64, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      std::uint8_t* p = t.at(x, y);
      p[0] = p[1] = p[2] = 255;
      p[3] = (x >= 24 && x < 40 && y >= 24 && y < 40) ? 0 : 255;
    }
  return t;
}

RenderScene cutScene(const Camera& cam, bool cut) {
  RenderScene s = shadowScene(true, cam);
  s.environment.intensity = 0.1;
  if (cut) s.paper.texture = windowTexture();
  return s;
}

TEST(OsmesaRenderer, CutOutShowsWhatIsBehindAndLetsTheLightThrough) {
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  const Camera cam = topCamera(1.0, w, h);
  const mesh::SheetMesh sheet = flatSheet(0.2);
  const mesh::SheetMesh none;
  const ImageRGBA8 cut = r.render(cutScene(cam, true), sheet);
  const ImageRGBA8 whole = r.render(cutScene(cam, false), sheet);
  const ImageRGBA8 ground = r.render(cutScene(cam, false), none);
  maybeDump("cutout", cut);
  // Through the window: the ground exactly as without the paper (the light,
  // along (1, -1, 0), reaches it past the paper's left edge).
  const Vec3 window(0.0, 0.0, 0.0);
  EXPECT_NEAR(luma(pixelAt(cut, cam, window)), luma(pixelAt(ground, cam, window)), 1.0);
  EXPECT_EQ(pixelAt(cut, cam, window)[3], 255);
  // The window's light spot on the ground, shifted by +0.2 in x: lit like
  // open ground; just beside it, the shadow is as dark as without a window.
  const Vec3 spot(0.2, 0.0, 0.0), beside(0.28, 0.0, 0.0);
  EXPECT_NEAR(luma(pixelAt(cut, cam, spot)), luma(pixelAt(ground, cam, spot)), 1.0);
  EXPECT_LT(luma(pixelAt(whole, cam, spot)), 0.6 * luma(pixelAt(ground, cam, spot)));
  for (int k = 0; k < 4; ++k)
    EXPECT_EQ(pixelAt(cut, cam, beside)[k], pixelAt(whole, cam, beside)[k])
        << "no light leaks beside the cut";
  // Paper outside the window is unchanged.
  for (int k = 0; k < 4; ++k)
    EXPECT_EQ(pixelAt(cut, cam, Vec3(-0.07, 0.2, 0.1))[k],
              pixelAt(whole, cam, Vec3(-0.07, 0.2, 0.1))[k]);
  // The window's edge falls where the texture says, to a pixel: scan along X
  // through the centre; the paper covers |X| >= W/8.
  const auto px = [&](double x) { return projectToPixel(cam, Vec3(x, 0.2, 0.0))->x(); };
  const int row = static_cast<int>(std::floor(projectToPixel(cam, Vec3(0, 0.2, 0))->y()));
  const double edge = px(kSheetWidth / 8.0);
  for (int x = static_cast<int>(px(0.0)); x < w; ++x) {
    const bool paper = luma(cut.at(x, row)) > luma(ground.at(x, row)) + 20.0;
    if (x + 1.0 < edge) {
      EXPECT_FALSE(paper) << "pixel " << x << " inside the window";
    }
    if (x > edge + 1.0 && x < px(0.1)) {
      EXPECT_TRUE(paper) << "pixel " << x << " on the paper";
    }
  }
}

TEST(OsmesaRenderer, BackLitPaperGlowsByItsTransmittance) {
  const int w = 64, h = 48;
  OsmesaRenderer r(w, h);
  const Camera cam = topCamera(1.0, w, h);
  const mesh::SheetMesh sheet = flatSheet(0.2);
  RenderScene s;
  s.camera = cam;
  Light below;
  below.direction = Vec3(0.0, 1.0, 0.0);  // travels up: lights the back
  s.lights = {below};
  s.environment.intensity = 0.0;
  s.paper.texture = whiteTexture();
  s.paper.frontColor = s.paper.backColor = Vec3(1.0, 1.0, 1.0);
  for (const double t : {0.0, 0.1, 0.3}) {
    s.paper.transmittance = t;
    const ImageRGBA8 img = r.render(s, sheet);
    const std::uint8_t* p = pixelAt(img, cam, Vec3(0.0, 0.2, 0.0));
    EXPECT_NEAR(p[0], linearToSrgb8(t), 1.0) << "T = " << t;
  }
  // Lit from the front, the paper reflects (1 - T).
  s.lights[0].direction = Vec3(0.0, -1.0, 0.0);
  s.paper.transmittance = 0.3;
  EXPECT_NEAR(pixelAt(r.render(s, sheet), cam, Vec3(0.0, 0.2, 0.0))[0], linearToSrgb8(0.7), 1.0);
}

TEST(OsmesaRenderer, AreaLightIsAPointLightWithCosineFalloff) {
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  const Camera cam = Camera::lookAt(Vec3(0.0, 3.0, 0.0), Vec3::Zero(), -Vec3::UnitZ(), 0.5, w, h);
  RenderScene s;
  s.camera = cam;
  s.environment.intensity = 0.0;
  s.ground.enabled = true;
  s.ground.size = 2.0;
  s.ground.color = Vec3(0.5, 0.5, 0.5);
  Light area;
  area.kind = Light::Kind::Area;
  area.position = Vec3(0.0, 1.0, 0.0);
  area.direction = Vec3(0.0, -1.0, 0.0);
  area.size = Vec2(0.05, 0.05);
  s.lights = {area};
  const mesh::SheetMesh none;
  const ImageRGBA8 img = r.render(s, none);
  maybeDump("area_light", img);
  // Below the light: 0.5 * I / d^2; at x = 0.5: cos^2 = 0.8 (both ends), d^2 = 1.25.
  EXPECT_NEAR(pixelAt(img, cam, Vec3(0.0, 0.0, 0.0))[0], linearToSrgb8(0.5), 1.0);
  EXPECT_NEAR(pixelAt(img, cam, Vec3(0.5, 0.0, 0.0))[0], linearToSrgb8(0.5 * 0.8 / 1.25), 1.0);
}

TEST(OsmesaRenderer, AlbedoPassIsUnlitTextureTimesColour) {
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  const Camera cam = topCamera(1.0, w, h);
  RenderScene s = shadowScene(true, cam);
  s.paper.frontColor = Vec3(0.5, 0.25, 1.0);
  s.ground.color = Vec3(0.2, 0.4, 0.6);
  PropMesh box;
  box.name = "box";
  box.color = Vec3(0.9, 0.1, 0.1);
  box.vertices = {{0.15, 0.0, 0.15},  {0.25, 0.0, 0.15},  {0.25, 0.0, 0.25},  {0.15, 0.0, 0.25},
                  {0.15, 0.05, 0.15}, {0.25, 0.05, 0.15}, {0.25, 0.05, 0.25}, {0.15, 0.05, 0.25}};
  box.triangles = {{4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4}};
  s.props = {box};
  const mesh::SheetMesh sheet = flatSheet(0.2);
  const ImageRGBA8 img = r.render(s, sheet, nullptr, RenderPass::Albedo);
  maybeDump("albedo_pass", img);
  const std::uint8_t* paper = pixelAt(img, cam, Vec3(0.0, 0.2, 0.0));
  EXPECT_EQ(paper[0], linearToSrgb8(0.5));
  EXPECT_EQ(paper[1], linearToSrgb8(0.25));
  EXPECT_EQ(paper[2], linearToSrgb8(1.0));
  const std::uint8_t* g = pixelAt(img, cam, Vec3(-0.3, 0.0, 0.3));
  EXPECT_EQ(g[0], linearToSrgb8(0.2));
  EXPECT_EQ(g[2], linearToSrgb8(0.6));
  const std::uint8_t* b = pixelAt(img, cam, Vec3(0.2, 0.05, 0.2));
  EXPECT_EQ(b[0], linearToSrgb8(0.9));
  EXPECT_EQ(b[1], linearToSrgb8(0.1));
}

TEST(OsmesaRenderer, PropsCastTheKeyLightsShadow) {
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  const Camera cam = topCamera(1.0, w, h);
  RenderScene s = shadowScene(true, cam);
  PropMesh slab;  // a horizontal square hovering at y = 0.1 over x in [0.25, 0.35]
  slab.name = "slab";
  slab.vertices = {{0.25, 0.1, -0.05}, {0.35, 0.1, -0.05}, {0.35, 0.1, 0.05}, {0.25, 0.1, 0.05}};
  slab.triangles = {{0, 2, 1}, {0, 3, 2}};
  const mesh::SheetMesh sheet = flatSheet(0.2);
  const ImageRGBA8 without = r.render(s, sheet);
  s.props = {slab};
  const ImageRGBA8 with = r.render(s, sheet);
  maybeDump("prop_shadow", with);
  // Light along (1, -1, 0): the slab's shadow lands 0.1 further in +x.
  const Vec3 shadow(0.42, 0.0, 0.0);
  EXPECT_LT(luma(pixelAt(with, cam, shadow)), 0.6 * luma(pixelAt(without, cam, shadow)));
}

TEST(OsmesaRenderer, ShadingIsSplitAcrossACreaseAndSmoothWithinACurl) {
  // Two flat halves meeting at a 90 degree fold (the crease) seen from above
  // at 45 degrees: each half is evenly lit, the two halves differ, and the
  // transition is one pixel wide.
  mesh::SheetMesh m = flatSheet(0.0, 0.02);
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const double u = m.pattern[i].x() - 0.5 * kSheetWidth;
    m.positions[i] = u <= 0.0 ? Vec3(u, 0.0, m.positions[i].z())
                              : Vec3(0.0, u, m.positions[i].z());  // the right half stands up
  }
  const int w = 160, h = 120;
  OsmesaRenderer r(w, h);
  RenderScene s;
  s.camera = Camera::lookAt(Vec3(-0.3, 0.3, 0.0), Vec3::Zero(), Vec3::UnitY(), 0.9, w, h);
  Light l;
  l.direction = Vec3(1.0, -0.3, 0.0);
  s.lights = {l};
  s.environment.intensity = 0.1;
  s.paper.texture = whiteTexture();
  const ImageRGBA8 img = r.render(s, m);
  maybeDump("crease", img);
  const double floor1 = luma(pixelAt(img, s.camera, Vec3(-0.03, 0.0, 0.0)));
  const double floor2 = luma(pixelAt(img, s.camera, Vec3(-0.006, 0.0, 0.0)));
  const double wall1 = luma(pixelAt(img, s.camera, Vec3(0.0, 0.03, 0.0)));
  const double wall2 = luma(pixelAt(img, s.camera, Vec3(0.0, 0.006, 0.0)));
  EXPECT_NEAR(floor1, floor2, 1.0) << "no smoothing bleeds across the crease";
  EXPECT_NEAR(wall1, wall2, 1.0);
  EXPECT_GT(std::abs(floor1 - wall1), 30.0);
}

TEST(OsmesaRenderer, Timing640x480) {
  const int w = 640, h = 480;
  const mesh::SheetMesh sheet = test::bentSheet(0.015, 0.011);
  const RenderScene scene = bentScene(w, h);
  const auto t0 = std::chrono::steady_clock::now();
  OsmesaRenderer r(w, h);
  const auto t1 = std::chrono::steady_clock::now();
  ImageRGBA8 img = r.render(scene, sheet);
  const auto t2 = std::chrono::steady_clock::now();
  constexpr int kRuns = 3;
  for (int i = 0; i < kRuns; ++i) img = r.render(scene, sheet);
  const auto t3 = std::chrono::steady_clock::now();
  maybeDump("bent_sheet_640", img);
  using ms = std::chrono::duration<double, std::milli>;
  std::cout << "[ timing ] " << sheet.triangleCount() << " triangles at 640x480: context "
            << ms(t1 - t0).count() << " ms, first frame " << ms(t2 - t1).count() << " ms, then "
            << ms(t3 - t2).count() / kRuns << " ms per frame\n";
  EXPECT_EQ(img.width, w);
}

}  // namespace
}  // namespace crumple::render
