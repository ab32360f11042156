// Golden images of the samples and the agreement of the two renderers
// (tests/golden/README.md). CRUMPLE_BLESS=1 rewrites the golden images
// instead of comparing (the tests then report SKIPPED); a failed comparison
// writes NAME.actual.png and NAME.diff.png into the build folder
// (tests/golden/).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/parallel.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/render/embree_renderer.hpp"
#include "crumple/render/image_compare.hpp"
#include "crumple/render/osmesa_renderer.hpp"

namespace crumple {
namespace {

namespace fs = std::filesystem;

// Golden images are a quarter of the samples' 640 x 480.
constexpr int kWidth = 160;
constexpr int kHeight = 120;
constexpr int kEmbreeSpp = 8;
// The Embree golden tolerance: the path tracer is deterministic (byte-identical
// for any thread count on one machine); the tolerance absorbs libm and
// compiler differences between machines.
constexpr double kEmbreeMaxMae = 0.5;    // mean |difference| over RGBA, 8-bit units
constexpr double kEmbreeMaxFlip = 0.01;  // mean LDR-FLIP
// The agreement of the two backends: albedo passes at 320 x 240.
constexpr int kAgreeWidth = 320;
constexpr int kAgreeHeight = 240;
constexpr int kAgreeSpp = 16;
constexpr double kMinAlphaIoU = 0.99;
constexpr double kMaxAlbedoMae = 2.0;  // mean |RGB difference|, 8-bit units

const std::vector<std::string> kSamples = {"backlit-cutout",    "crumple", "cylinder-fold", "drape",
                                           "first-singularity", "moebius", "unload"};

bool blessing() {
  const char* v = std::getenv("CRUMPLE_BLESS");
  return v != nullptr && *v != '\0' && std::string(v) != "0";
}

// The sample's one-frame cache and its scene at the given resolution.
struct GoldenFrame {
  io::SceneSpec scene;
  std::vector<cache::ExtensionBlock> headerBlocks;
  cache::FrameRecord frame;
};

GoldenFrame loadFrame(const std::string& sample, int width, int height) {
  const std::string path = std::string(CRUMPLE_GOLDEN_DIR) + "/inputs/" + sample + ".pcache";
  const cache::CacheReader reader(path);
  GoldenFrame g;
  g.scene = io::parseScene(reader.header().sceneText, sample + "/scene.toml (in " + path + ")",
                           std::string(CRUMPLE_SOURCE_DIR) + "/samples/" + sample,
                           /*checkFiles=*/true);
  g.scene.camera.width = width;
  g.scene.camera.height = height;
  g.headerBlocks = reader.header().extensions;
  g.frame = reader.readFrame(0);
  return g;
}

// What the renderers draw of the golden frame: by default as `crumple
// render` does for the path tracer, the crumpling model's curved regions
// refined on the frame's camera (pipeline/refine.hpp); the preview draws the
// simulated mesh.
pipeline::FrameView viewOf(const GoldenFrame& g, bool refined = true) {
  return pipeline::FrameViewBuilder(
             g.scene, g.headerBlocks,
             refined ? mesh::RefineOptions{} : pipeline::FrameViewBuilder::offRefinement())
      .build(g.frame);
}

std::string outPath(const std::string& name) {
  return std::string(CRUMPLE_GOLDEN_OUT_DIR) + "/" + name;
}

class Golden : public ::testing::TestWithParam<std::string> {};

TEST_P(Golden, OsmesaIsByteExact) {
  const std::string sample = GetParam();
  const GoldenFrame g = loadFrame(sample, kWidth, kHeight);
  const pipeline::FrameView fv = viewOf(g, /*refined=*/false);
  render::OsmesaRenderer renderer(kWidth, kHeight);
  const ImageRGBA8 image = renderer.render(fv.scene, fv.sheet);
  const std::string golden = std::string(CRUMPLE_GOLDEN_DIR) + "/osmesa/" + sample + ".png";
  if (blessing()) {
    exporters::writePng(golden, image);
    GTEST_SKIP() << "CRUMPLE_BLESS: rewrote " << golden;
  }
  ASSERT_TRUE(fs::exists(golden)) << golden << " is missing: run scripts/bless-golden.sh";
  const ImageRGBA8 expected = exporters::readPng(golden);
  if (expected.pixels != image.pixels) {
    const auto c = render::compareImages(expected, image, render::ImageMetric::Mae);
    exporters::writePng(outPath("osmesa-" + sample + ".actual.png"), image);
    exporters::writePng(outPath("osmesa-" + sample + ".diff.png"), c.diff);
    FAIL() << "OSMesa image of " << sample << " differs from " << golden << " (MAE " << c.value
           << ", max " << c.maxAbs << "); see " << outPath("osmesa-" + sample + ".actual.png")
           << ". If the change is intended: scripts/bless-golden.sh";
  }
}

TEST_P(Golden, EmbreeIsWithinToleranceAndThreadIndependent) {
  const std::string sample = GetParam();
  const GoldenFrame g = loadFrame(sample, kWidth, kHeight);
  const pipeline::FrameView fv = viewOf(g);
  render::EmbreeRenderer renderer;
  render::PathTraceSettings settings;
  settings.samplesPerPixel = kEmbreeSpp;
  settings.seed = g.scene.seed;
  settings.frame = g.frame.frame;
  std::vector<ImageRGBA8> images;
  for (const int threads : {1, 2}) {
    setThreadCount(threads);
    images.push_back(
        render::toSrgb8(renderer.render(fv.scene, fv.sheet, settings), fv.scene.background));
    EXPECT_EQ(renderer.droppedSamples(), 0u);
  }
  setThreadCount(1);
  EXPECT_EQ(images[0].pixels, images[1].pixels) << "1 and 2 threads give different images";
  const std::string golden = std::string(CRUMPLE_GOLDEN_DIR) + "/embree/" + sample + ".png";
  if (blessing()) {
    exporters::writePng(golden, images[0]);
    GTEST_SKIP() << "CRUMPLE_BLESS: rewrote " << golden;
  }
  ASSERT_TRUE(fs::exists(golden)) << golden << " is missing: run scripts/bless-golden.sh";
  const ImageRGBA8 expected = exporters::readPng(golden);
  const auto mae = render::compareImages(expected, images[0], render::ImageMetric::Mae);
  const auto flip = render::compareImages(expected, images[0], render::ImageMetric::Flip);
  if (mae.value > kEmbreeMaxMae || flip.value > kEmbreeMaxFlip) {
    exporters::writePng(outPath("embree-" + sample + ".actual.png"), images[0]);
    exporters::writePng(outPath("embree-" + sample + ".diff.png"), flip.diff);
  }
  EXPECT_LE(mae.value, kEmbreeMaxMae) << sample << ": see " << outPath("embree-" + sample);
  EXPECT_LE(flip.value, kEmbreeMaxFlip) << sample;
}

TEST_P(Golden, BackendsAgreeOnTheAlbedoPass) {
  const std::string sample = GetParam();
  const GoldenFrame g = loadFrame(sample, kAgreeWidth, kAgreeHeight);
  const pipeline::FrameView fv = viewOf(g);
  render::OsmesaRenderer osmesa(kAgreeWidth, kAgreeHeight);
  const ImageRGBA8 a = osmesa.render(fv.scene, fv.sheet, nullptr, render::RenderPass::Albedo);
  render::EmbreeRenderer embree;
  render::PathTraceSettings settings;
  settings.samplesPerPixel = kAgreeSpp;
  settings.pass = render::RenderPass::Albedo;
  setThreadCount(2);
  const ImageRGBA8 b =
      render::toSrgb8(embree.render(fv.scene, fv.sheet, settings), fv.scene.background);
  setThreadCount(1);
  const auto c = render::compareImages(a, b, render::ImageMetric::Mae);
  std::cout << "[ agree  ] " << sample << ": alpha IoU " << c.alphaIoU << ", mean |RGB diff| "
            << c.maeRgb << "/255\n";
  if (c.alphaIoU < kMinAlphaIoU || c.maeRgb > kMaxAlbedoMae) {
    exporters::writePng(outPath("albedo-osmesa-" + sample + ".png"), a);
    exporters::writePng(outPath("albedo-embree-" + sample + ".png"), b);
    exporters::writePng(outPath("albedo-" + sample + ".diff.png"), c.diff);
  }
  EXPECT_GE(c.alphaIoU, kMinAlphaIoU) << sample;
  EXPECT_LE(c.maeRgb, kMaxAlbedoMae) << sample;
}

INSTANTIATE_TEST_SUITE_P(Samples, Golden, ::testing::ValuesIn(kSamples),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& ch : name)
                             if (ch == '-') ch = '_';
                           return name;
                         });

}  // namespace
}  // namespace crumple
