// Motion blur from a shot (docs/RENDERING.md "Motion blur"): a scene's
// [camera] shutter stores the sheet's velocities over each frame in the
// cache, and the path tracer blurs the sheet along them. A sheet sliding at
// a known speed smears its leading and trailing edges over the distance it
// moves while the shutter is open; without a shutter the cache and the
// frames are exactly what they were; a blurred frame is the same on one and
// two threads, with its AOVs; animated mesh props blur with their motion.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_look.hpp"
#include "crumple/cache/pcache_motion.hpp"
#include "crumple/core/parallel.hpp"
#include "crumple/exporters/exr.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/render/embree_renderer.hpp"
#include "test_util.hpp"

using namespace crumple;
using namespace crumple::testing;

namespace {

constexpr double kSpeed = 1.0;  // m/s along +x: the handles' and so the sheet's
constexpr double kFps = 24.0;   // frames per second
constexpr int kFrame = 12;      // the frame measured: the sheet at x in [0.45, 0.55]
constexpr int kWidth = 160, kHeight = 120;
constexpr double kCameraHeight = 0.5;  // m above the sheet, looking straight down
constexpr double kYfov = 40.0 * 3.14159265358979323846 / 180.0;
constexpr double kSheet = 0.1;  // m, a square sheet

// A 10 cm sheet lying flat at y = 0.1 m (no gravity), its four corners held
// by handles that slide along +x at kSpeed from t = 0: the whole sheet
// slides with them. Seen from above, image x along world +x. `camera`: extra
// [camera] lines.
void writeSlideScene(const fs::path& dir, const std::string& camera) {
  fs::create_directories(dir);
  std::vector<GltfTrack> corners;
  const std::vector<std::pair<std::string, std::array<float, 3>>> at = {
      {"A", {-0.05f, 0.1f, 0.05f}},
      {"B", {0.05f, 0.1f, 0.05f}},
      {"C", {0.05f, 0.1f, -0.05f}},
      {"D", {-0.05f, 0.1f, -0.05f}}};
  for (const auto& [node, p] : at)
    corners.push_back({node, {0.0f, 1.0f}, {p, {p[0] + static_cast<float>(kSpeed), p[1], p[2]}}});
  writeFile(dir / "slide.gltf", makeGltf(corners));
  writeFile(dir / "scene.toml", R"([scene]
name = "slide"
fps = 24
frames = [0, 12]
substeps = 2
animation = "slide.gltf"
[sheet]
width = 0.1
height = 0.1
max_edge = 0.02
origin = [-0.05, 0.1, 0.05]
[sim]
gravity = [0, 0, 0]
[[handles]]
node = "A"
pattern = [0, 0]
[[handles]]
node = "B"
pattern = [0.1, 0]
[[handles]]
node = "C"
pattern = [0.1, 0.1]
[[handles]]
node = "D"
pattern = [0, 0.1]
[camera]
position = [0.5, 0.6, 0]
look_at = [0.5, 0.1, 0]
up = [0, 0, -1]
fov_deg = 40
resolution = [160, 120]
)" + camera + R"([[lights]]
type = "directional"
direction = [0, -1, 0]
)");
}

pipeline::ShotOptions quiet(const fs::path& out) {
  pipeline::ShotOptions o;
  o.outDir = out.string();
  o.render = false;
  o.log = nullptr;
  o.interactive = 0;
  return o;
}

// Frame `frame` of a cache drawn by the path tracer (direct light only),
// with the cache's own shutter or `shutter`.
ImageRGBAF renderFrame(const std::string& cachePath, int frame, int spp,
                       std::optional<cache::Shutter> shutter = {},
                       pipeline::FrameView* view = nullptr) {
  const cache::CacheReader reader(cachePath);
  const auto& header = reader.header();
  const io::SceneSpec scene =
      io::parseScene(header.sceneText, header.sceneFile,
                     fs::path(header.sceneFile).parent_path().string(), /*checkFiles=*/false);
  pipeline::FrameViewBuilder views(scene, header.extensions);
  if (shutter) views.setShutter(*shutter);
  const pipeline::FrameView fv = views.build(reader.readFrame(static_cast<std::size_t>(frame)));
  if (view) *view = fv;
  render::EmbreeRenderer renderer;
  render::PathTraceSettings settings;
  settings.samplesPerPixel = spp;
  settings.maxBounces = 0;
  settings.frame = frame;
  return renderer.render(fv.scene, fv.sheet, settings);
}

// The mean coverage (alpha) of the rows [y0, y1) per column, or of the
// columns [x0, x1) per row.
std::vector<double> columnProfile(const ImageRGBAF& img, int y0, int y1) {
  std::vector<double> c(static_cast<std::size_t>(img.width), 0.0);
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < img.width; ++x) c[static_cast<std::size_t>(x)] += img.at(x, y)[3];
  for (double& v : c) v /= (y1 - y0);
  return c;
}
std::vector<double> rowProfile(const ImageRGBAF& img, int x0, int x1) {
  std::vector<double> c(static_cast<std::size_t>(img.height), 0.0);
  for (int y = 0; y < img.height; ++y)
    for (int x = x0; x < x1; ++x) c[static_cast<std::size_t>(y)] += img.at(x, y)[3];
  for (double& v : c) v /= (x1 - x0);
  return c;
}

// Where a profile first rises through `level` and where it last falls
// through it, linearly between pixel centres (x + 0.5).
std::pair<double, double> crossings(const std::vector<double>& c, double level) {
  double rise = -1.0, fall = -1.0;
  for (std::size_t x = 1; x < c.size(); ++x) {
    const double a = c[x - 1], b = c[x];
    if (rise < 0.0 && a < level && b >= level) rise = x - 0.5 + (level - a) / (b - a);
    if (a >= level && b < level) fall = x - 0.5 + (a - level) / (a - b);
  }
  return {rise, fall};
}

// The widths of a profile's rising and falling edges, from 10 % to 90 %
// coverage, and its width at half coverage.
struct Edges {
  double rising, falling, halfWidth;
};
Edges edges(const std::vector<double>& c) {
  const auto [r10, f10] = crossings(c, 0.1);
  const auto [r50, f50] = crossings(c, 0.5);
  const auto [r90, f90] = crossings(c, 0.9);
  return {r90 - r10, f10 - f90, f50 - r50};
}

}  // namespace

// The sheet slides kSpeed * (close - open) / fps = 41.7 mm while the shutter
// is open: 13.7 pixels. An edge perpendicular to the motion, swept over D
// pixels and seen through a one-pixel box filter, ramps linearly from 10 %
// to 90 % coverage over 0.8 D exactly (D >= 1); an edge along the motion
// stays sharp, and the sheet's width at half coverage is its own. The
// tolerance, 0.4 px on the ramps, is the sampling noise of 20 rows at 256
// samples (the renderer's own disc test reads its analytic length to 0.08
// px of 24) plus the interpolation between pixel centres.
TEST(MotionBlurShot, ASlidingSheetsEdgesSmearOverTheDistanceItMovesWhileTheShutterIsOpen) {
  TempDir tmp;
  writeSlideScene(tmp / "s", "shutter = [-0.5, 0.5]\n");
  const auto scene = io::loadScene((tmp / "s/scene.toml").string());
  const auto report = pipeline::runShot(scene, quiet(tmp / "out"));
  // The cache's velocities: the sheet's motion over the frame, the handles'.
  const cache::CacheReader reader(report.cachePath);
  const auto velocities = cache::decodeVelocities(reader.readFrame(kFrame).extensions);
  ASSERT_TRUE(velocities.has_value());
  for (const Vec3& v : *velocities) EXPECT_NEAR((v - Vec3(kSpeed, 0, 0)).norm(), 0.0, 1e-6);
  EXPECT_TRUE(cache::decodeVelocities(reader.readFrame(0).extensions)->front().isZero())
      << "the first frame has no frame before it";

  const double metresPerPixel = 2.0 * kCameraHeight * std::tan(0.5 * kYfov) / kHeight;
  const double movePx = kSpeed * (0.5 - -0.5) / kFps / metresPerPixel;
  const double sheetPx = kSheet / metresPerPixel;
  pipeline::FrameView view;
  const ImageRGBAF blurred = renderFrame(report.cachePath, kFrame, 256, {}, &view);
  ASSERT_EQ(view.scene.sheetMotion.size(), 2u) << "the shutter's opening and closing";
  EXPECT_NEAR(view.scene.sheetMotion[1][0].x() - view.scene.sheetMotion[0][0].x(), kSpeed / kFps,
              1e-9);
  const ImageRGBAF sharp = renderFrame(report.cachePath, kFrame, 256, cache::Shutter{});
  // Rows through the sheet's middle (it covers rows 43.5-76.5), columns likewise.
  const Edges moving = edges(columnProfile(blurred, kHeight / 2 - 10, kHeight / 2 + 10));
  const Edges still = edges(columnProfile(sharp, kHeight / 2 - 10, kHeight / 2 + 10));
  const Edges along = edges(rowProfile(blurred, kWidth / 2 - 5, kWidth / 2 + 5));
  std::printf(
      "[ measure ] sheet sliding %.2f px while the shutter is open: edges ramp 10-90 %% over "
      "%.2f (trailing) and %.2f (leading) px (analytic %.2f); sharp %.2f and %.2f px; its width "
      "at half coverage %.2f px (its own %.2f); edges along the motion ramp over %.2f and %.2f "
      "px\n",
      movePx, moving.rising, moving.falling, 0.8 * movePx, still.rising, still.falling,
      moving.halfWidth, sheetPx, along.rising, along.falling);
  EXPECT_NEAR(moving.rising, 0.8 * movePx, 0.4);
  EXPECT_NEAR(moving.falling, 0.8 * movePx, 0.4);
  EXPECT_NEAR(moving.halfWidth, sheetPx, 0.4);
  // Sharp: a step between two pixel centres, 1.6 px at most in this measure.
  EXPECT_LT(still.rising, 1.7);
  EXPECT_LT(still.falling, 1.7);
  EXPECT_NEAR(still.halfWidth, sheetPx, 0.4);
  EXPECT_LT(along.rising, 1.7) << "no blur across the motion";
  EXPECT_LT(along.falling, 1.7);
  // A centred shutter: the blur is centred on the frame's own position.
  const auto [r, f] = crossings(columnProfile(blurred, kHeight / 2 - 10, kHeight / 2 + 10), 0.5);
  const auto [r0, f0] = crossings(columnProfile(sharp, kHeight / 2 - 10, kHeight / 2 + 10), 0.5);
  EXPECT_NEAR(0.5 * (r + f), 0.5 * (r0 + f0), 0.3);
  // A shutter trailing the frame, [-1, 0]: the same blur, half a motion back.
  const ImageRGBAF trailing = renderFrame(report.cachePath, kFrame, 64, cache::Shutter{-1.0, 0.0});
  const auto [rt, ft] = crossings(columnProfile(trailing, kHeight / 2 - 10, kHeight / 2 + 10), 0.5);
  EXPECT_NEAR(0.5 * (rt + ft), 0.5 * (r0 + f0) - 0.5 * movePx, 0.5);
  EXPECT_NEAR(ft - rt, sheetPx, 0.5);
}

// A scene without a shutter pays nothing: its cache is the cache of the
// same shot with the shutter given on the command line but for the motion
// blocks, and its frames are that shot's frames rendered with `--shutter 0`
// (and with the preview, which never blurs), byte for byte.
TEST(MotionBlurShot, WithoutAShutterTheCacheAndTheFramesAreTodays) {
  TempDir tmp;
  writeSlideScene(tmp / "s", "");
  const std::string scene = (tmp / "s").string();
  const std::string plain = (tmp / "plain").string(), blur = (tmp / "blur").string();
  ASSERT_EQ(runCrumple("simulate " + scene + " --out " + plain).status, 0);
  const auto r = runCrumple("simulate " + scene + " --shutter -0.5,0.5 --out " + blur);
  ASSERT_EQ(r.status, 0) << r.output;
  const cache::CacheReader plainReader(plain + "/cache.pcache");
  EXPECT_FALSE(cache::decodeShutter(plainReader.header().extensions).has_value());
  for (std::size_t i = 0; i < plainReader.frameCount(); ++i) {
    const auto frame = plainReader.readFrame(i);
    EXPECT_FALSE(cache::decodeVelocities(frame.extensions).has_value());
    EXPECT_FALSE(cache::decodePropVelocities(frame.extensions).has_value());
  }
  // The blurred shot's cache without SHTR, VELO and PRPV, written again.
  {
    const cache::CacheReader blurReader(blur + "/cache.pcache");
    cache::CacheHeader header = blurReader.header();
    EXPECT_EQ(cache::decodeShutter(header.extensions), (cache::Shutter{-0.5, 0.5}));
    const auto motion = [](const cache::ExtensionBlock& b) {
      return b.tag == cache::kShutterTag || b.tag == cache::kVelocitiesTag ||
             b.tag == cache::kPropVelocitiesTag;
    };
    std::erase_if(header.extensions, motion);
    cache::CacheWriter writer(tmp / "stripped.pcache", header);
    for (std::size_t i = 0; i < blurReader.frameCount(); ++i) {
      cache::FrameRecord frame = blurReader.readFrame(i);
      ASSERT_TRUE(cache::decodeVelocities(frame.extensions).has_value());
      std::erase_if(frame.extensions, motion);
      writer.append(frame);
    }
    writer.close();
  }
  EXPECT_EQ(readFile(tmp / "stripped.pcache"), readFile(plain + "/cache.pcache"))
      << "the shot itself is the same with and without a shutter";
  const std::string frames = " --frames 12-12 --spp 4 --out ";
  for (const std::string backend : {"embree", "osmesa"}) {
    SCOPED_TRACE(backend);
    const std::string b = " --backend " + backend;
    ASSERT_EQ(
        runCrumple("render " + plain + "/cache.pcache" + b + frames + (tmp / "a").string()).status,
        0);
    ASSERT_EQ(runCrumple("render " + blur + "/cache.pcache --shutter 0" + b + frames +
                         (tmp / "b").string())
                  .status,
              0);
    ASSERT_EQ(
        runCrumple("render " + blur + "/cache.pcache" + b + frames + (tmp / "c").string()).status,
        0);
    const std::string sharp = readFile(tmp / "a/0012.png");
    EXPECT_FALSE(sharp.empty());
    EXPECT_EQ(readFile(tmp / "b/0012.png"), sharp);
    if (backend == "embree")
      EXPECT_NE(readFile(tmp / "c/0012.png"), sharp) << "the cache's shutter blurs by default";
    else
      EXPECT_EQ(readFile(tmp / "c/0012.png"), sharp) << "the preview never blurs";
  }
  // Blur needs the velocities: a cache without them is exit 2, saying how.
  const auto noMotion = runCrumple("render " + plain + "/cache.pcache --backend embree --shutter " +
                                   "0.5" + frames + (tmp / "d").string());
  EXPECT_EQ(noMotion.status, 2) << noMotion.output;
  EXPECT_NE(noMotion.output.find("--shutter: the cache holds no sub-frame motion"),
            std::string::npos)
      << noMotion.output;
}

TEST(MotionBlurShot, ABlurredFrameAndItsAovsAreTheSameOnOneAndTwoThreads) {
  TempDir tmp;
  writeSlideScene(tmp / "s", "shutter = 0.5\n");
  ASSERT_EQ(
      runCrumple("simulate " + (tmp / "s").string() + " --out " + (tmp / "c").string()).status, 0);
  for (const char* t : {"1", "2"}) {
    const auto r = runCrumple("render " + (tmp / "c/cache.pcache").string() +
                              " --frames 11-12 --backend embree --spp 4 --threads " + t +
                              " --aov depth,normal,albedo,position,region,handle-id,object-id "
                              "--out " +
                              (tmp / (std::string("t") + t)).string());
    ASSERT_EQ(r.status, 0) << r.output;
  }
  for (const char* f : {"0011.png", "0012.png", "0011.exr", "0012.exr"}) {
    const std::string one = readFile(tmp / "t1" / f);
    EXPECT_FALSE(one.empty()) << f;
    EXPECT_EQ(one, readFile(tmp / "t2" / f)) << f << " differs between 1 and 2 threads";
  }
  // The AOVs are the blurred rays': the object id is the most frequent
  // over a pixel's hits (docs/RENDERING.md "AOVs"), the sheet wherever a
  // ray of the pixel met it, and its depth is the sheet's plane there.
  const ImageChannels layers = exporters::readExrChannels((tmp / "t1/0012.exr").string());
  const auto* alpha = layers.find("A");
  const auto* object = layers.find("IndexOB.X");
  const auto* depth = layers.find("Z");
  ASSERT_TRUE(alpha && object && depth);
  long partial = 0, mismatched = 0;
  for (std::size_t i = 0; i < alpha->pixels.size(); ++i) {
    partial += alpha->pixels[i] > 0.0f && alpha->pixels[i] < 1.0f;
    mismatched += (object->pixels[i] == 1.0f) != (alpha->pixels[i] > 0.0f);
    if (alpha->pixels[i] > 0.0f) {
      EXPECT_NEAR(depth->pixels[i], kCameraHeight, 1e-3);
    }
  }
  EXPECT_GT(partial, 100) << "the blurred edges are partly covered";
  EXPECT_EQ(mismatched, 0);
}

TEST(MotionBlurShot, BadShuttersOnTheCommandLineAreExit2) {
  TempDir tmp;
  writeSlideScene(tmp / "s", "");
  const std::string scene = (tmp / "s").string() + " --out " + (tmp / "o").string();
  for (const std::string bad : {"0.3,0.1", "0.1,0.1", "-1.5,0", "0,2", "3", "-0.5", "abc", ",",
                                "0.25,", "nan", "0.1,0.2,0.3"}) {
    SCOPED_TRACE(bad);
    const auto r = runCrumple("simulate " + scene + " --shutter=" + bad);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--shutter"), std::string::npos) << r.output;
  }
  ASSERT_EQ(runCrumple("simulate " + scene + " --shutter 0").status, 0);
  EXPECT_FALSE(cache::decodeShutter(
                   cache::CacheReader((tmp / "o/cache.pcache").string()).header().extensions)
                   .has_value())
      << "--shutter 0 is no motion blur";
  EXPECT_EQ(runCrumple("render " + (tmp / "o/cache.pcache").string() + " --shutter=-2,0").status,
            2);
  const auto help = runCrumple("render --help");
  EXPECT_NE(help.output.find("--shutter"), std::string::npos) << help.output;
}

// An animated mesh prop (a triangle moving along +x at 1 m/s) blurs with
// its motion: its vertices at the shutter's opening and closing are its
// frame positions a quarter of a frame either side along its velocity.
TEST(MotionBlurShot, AnimatedMeshPropsMoveOverTheShutter) {
  TempDir tmp;
  fs::create_directories(tmp / "s");
  writeFile(tmp / "s/props.gltf", movingPropGltf());
  writeFile(tmp / "s/scene.toml", R"([scene]
fps = 24
frames = [1, 4]
animation = "props.gltf"
[sheet]
width = 0.1
height = 0.1
max_edge = 0.025
[camera]
shutter = [-0.25, 0.25]
[[props]]
node = "Cup"
[[props]]
name = "table"
shape = "box"
size = [1.0, 0.1, 1.0]
position = [0.0, -0.5, 0.0]
)");
  const auto scene = io::loadScene((tmp / "s/scene.toml").string());
  const auto report = pipeline::runShot(scene, quiet(tmp / "out"));
  const cache::CacheReader reader(report.cachePath);
  const auto frame = reader.readFrame(2);  // frame 3, t = 0.125 s
  const pipeline::FrameViewBuilder views(scene, reader.header().extensions);
  const pipeline::FrameView fv = views.build(frame);
  ASSERT_EQ(fv.scene.props.size(), 2u);
  EXPECT_TRUE(fv.scene.props[0].motion.empty()) << "a box stands still";
  const render::PropMesh& cup = fv.scene.props[1];
  ASSERT_EQ(cup.motion.size(), 2u);
  const double quarter = 0.25 / 24.0;  // s
  for (std::size_t v = 0; v < cup.vertices.size(); ++v) {
    EXPECT_NEAR(cup.vertices[v].x(), 0.125 + (v == 1 ? 0.1 : 0.0), 1e-6);
    EXPECT_NEAR((cup.motion[0][v] - cup.vertices[v] + Vec3(quarter, 0, 0)).norm(), 0.0, 1e-6);
    EXPECT_NEAR((cup.motion[1][v] - cup.vertices[v] - Vec3(quarter, 0, 0)).norm(), 0.0, 1e-6);
  }
  // The falling sheet moves too; with the shutter closed nothing does.
  EXPECT_EQ(fv.scene.sheetMotion.size(), 2u);
  pipeline::FrameViewBuilder sharp(scene, reader.header().extensions);
  sharp.setShutter({});
  const pipeline::FrameView still = sharp.build(frame);
  EXPECT_TRUE(still.scene.sheetMotion.empty());
  EXPECT_TRUE(still.scene.props[1].motion.empty());
  EXPECT_EQ(still.scene.motionSteps(), 0u);
}
