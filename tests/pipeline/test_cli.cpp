// The `crumple` command line as a user and a farm see it: help, exit codes,
// bad inputs, progress lines, determinism across thread counts.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "crumple/exporters/exr.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/render/view.hpp"
#include "test_util.hpp"

using namespace crumple::testing;

TEST(Cli, HelpForEverySubcommand) {
  const auto top = runCrumple("--help");
  EXPECT_EQ(top.status, 0);
  for (const char* sub :
       {"run", "simulate", "render", "sound", "export", "farm", "inspect", "compare", "init"}) {
    EXPECT_NE(top.output.find(sub), std::string::npos) << sub;
    const auto r = runCrumple(std::string(sub) + " --help");
    EXPECT_EQ(r.status, 0) << sub;
    EXPECT_NE(r.output.find("--"), std::string::npos) << sub;
  }
  EXPECT_EQ(runCrumple("").status, 2) << "a subcommand is required";
  EXPECT_EQ(runCrumple("frobnicate").status, 2);
  EXPECT_EQ(runCrumple("run").status, 2) << "SCENE is required";
  EXPECT_EQ(runCrumple("sound").status, 2) << "CACHE is required";
}

// `crumple init DIR` writes a starter shot that `crumple run` takes as is:
// frames, cache, a soundtrack with crumpling events; a second init into the
// same folder is refused unless --force.
TEST(Cli, InitWritesAStarterShotThatRuns) {
  const TempDir tmp;
  const fs::path dir = tmp.path() / "starter";
  const auto init = runCrumple("init " + dir.string());
  ASSERT_EQ(init.status, 0) << init.output;
  EXPECT_TRUE(fs::exists(dir / "scene.toml"));
  EXPECT_TRUE(fs::exists(dir / "gather.gltf"));
  EXPECT_NE(readFile(dir / "scene.toml").find("# "), std::string::npos) << "commented";
  const auto run = runCrumple("run " + dir.string() + " --out " + (dir / "out").string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_TRUE(fs::exists(dir / "out" / "cache.pcache"));
  EXPECT_TRUE(fs::exists(dir / "out" / "frames" / "0072.png"));
  EXPECT_TRUE(fs::exists(dir / "out" / "sound.wav"));
  EXPECT_EQ(run.output.find("sound    0 crumpling"), std::string::npos) << run.output;
  const auto again = runCrumple("init " + dir.string());
  EXPECT_EQ(again.status, 2) << again.output;
  EXPECT_NE(again.output.find("--force"), std::string::npos) << again.output;
  EXPECT_EQ(runCrumple("init " + dir.string() + " --force").status, 0);
}

TEST(Cli, RunWritesCacheFramesSummaryAndProgressLines) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  const auto r = runCrumple("run " + (tmp / "scene").string() + " --out " + (tmp / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(tmp / "out/cache.pcache"));
  EXPECT_TRUE(fs::exists(tmp / "out/summary.json"));
  for (int f = 1; f <= 6; ++f) {
    char name[16];
    std::snprintf(name, sizeof name, "%04d.png", f);
    EXPECT_TRUE(fs::exists(tmp / "out/frames" / name)) << name;
  }
  // Not a terminal: one PROGRESS line per frame, ending at 100.
  std::size_t lines = 0, pos = 0;
  while ((pos = r.output.find("PROGRESS ", pos)) != std::string::npos) {
    ++lines;
    ++pos;
  }
  EXPECT_EQ(lines, 6u);
  EXPECT_NE(r.output.find("PROGRESS 100"), std::string::npos);
  // The closing summary says where things went and what each stage cost.
  EXPECT_NE(r.output.find("cache.pcache"), std::string::npos);
  EXPECT_NE(r.output.find("ms/frame"), std::string::npos);
  const auto summary = readFile(tmp / "out/summary.json");
  EXPECT_NE(summary.find("\"elastic\""), std::string::npos);
  // For a farm's log: the same JSON on one `SUMMARY` line after the progress.
  const auto line = r.output.find("SUMMARY {");
  ASSERT_NE(line, std::string::npos) << r.output;
  EXPECT_GT(line, r.output.rfind("PROGRESS "));
  EXPECT_EQ(r.output.substr(line + 8, summary.size()), summary);
  EXPECT_NE(summary.find("\"tearing\":false"), std::string::npos);
  // The derived stiffnesses of the preset: E h / (1 - nu^2), E h^3 / (12 (1 - nu^2)).
  EXPECT_NE(summary.find("\"stretch_stiffness_N_m\":384000"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"bending_stiffness_N_m\":0.0002592"), std::string::npos) << summary;
}

TEST(Cli, InspectJsonHasTheDocumentedKeys) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  ASSERT_EQ(runCrumple("simulate " + (tmp / "scene").string() + " --out " + (tmp / "out").string())
                .status,
            0);
  EXPECT_FALSE(fs::exists(tmp / "out/frames")) << "simulate renders nothing";
  const auto r = runCommand(std::string(CRUMPLE_BIN) + " inspect --json " +
                            (tmp / "out/cache.pcache").string() + " 2>/dev/null");
  ASSERT_EQ(r.status, 0);
  for (const char* key : {"\"format_version\"",
                          "\"fps\"",
                          "\"frame_count\":6",
                          "\"frames\"",
                          "\"frame\"",
                          "\"time\"",
                          "\"vertices\"",
                          "\"triangles\"",
                          "\"c_mean\"",
                          "\"n_comp\"",
                          "\"max_strain\"",
                          "\"max_dihedral\"",
                          "\"handle_error\"",
                          "\"handles\"",
                          "\"name\":\"left\"",
                          "\"position\"",
                          "\"singular_vertices\":0",
                          "\"junction_vertices\":0",
                          "\"tears\":0",
                          "\"popping\""})
    EXPECT_NE(r.output.find(key), std::string::npos) << key;
  EXPECT_EQ(r.output.front(), '{');
  const auto text = runCrumple("inspect " + (tmp / "out/cache.pcache").string());
  EXPECT_EQ(text.status, 0);
  EXPECT_NE(text.output.find("c_mean"), std::string::npos);
  EXPECT_NE(text.output.find("dihedral"), std::string::npos);
  EXPECT_NE(text.output.find("popping"), std::string::npos);
}

// `crumple compare A.pcache B.pcache`: the shapes of two shots frame by
// frame. The same shot measures 0; the same motion on a mesh twice as fine
// hangs a little differently (more than a micrometre, less than 5 mm) and
// fails a micrometre's tolerance with exit 1; an image beside a cache, or
// a frame range the caches do not share, is bad input (2).
TEST(Cli, CompareTwoCachesByTheirShapes) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  fs::create_directories(tmp / "fine");
  std::string fine = smallSceneToml();
  fine.replace(fine.find("max_edge = 2.5"), 14, "max_edge = 1.25");
  writeFile(tmp / "fine/scene.toml", fine);
  fs::copy_file(tmp / "scene/anim.gltf", tmp / "fine/anim.gltf");
  for (const char* shot : {"scene", "fine"})
    ASSERT_EQ(runCrumple("simulate " + (tmp / shot).string() + " --out " +
                         (tmp / (std::string(shot) + "-out")).string())
                  .status,
              0)
        << shot;
  const std::string coarse = (tmp / "scene-out/cache.pcache").string();
  const std::string finer = (tmp / "fine-out/cache.pcache").string();
  auto r = runCrumple("compare " + coarse + " " + coarse + " --shape-tolerance 1e-12");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("PASS largest mean distance 0 m"), std::string::npos) << r.output;
  r = runCommand(std::string(CRUMPLE_BIN) + " compare --json " + coarse + " " + finer +
                 " --frames 2-3 2>/dev/null");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.output.find("{\"frame\": 2, \"mean\": "), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("\"frame\": 4"), std::string::npos) << r.output;
  const auto worst = r.output.find("\"worst_mean\": ");
  ASSERT_NE(worst, std::string::npos) << r.output;
  const double mean = std::stod(r.output.substr(worst + 14));
  EXPECT_GT(mean, 1e-6);
  EXPECT_LT(mean, 5e-3);
  EXPECT_EQ(runCrumple("compare " + coarse + " " + finer + " --shape-tolerance 1e-6").status, 1);
  EXPECT_EQ(runCrumple("compare " + coarse + " " + (tmp / "missing.png").string()).status, 2);
  EXPECT_EQ(runCrumple("compare " + coarse + " " + finer + " --frames 50-60").status, 2);
  EXPECT_EQ(runCrumple("compare " + coarse + " " + finer + " --shape-tolerance nan").status, 2);
  EXPECT_EQ(runCrumple("compare " + coarse + " " + finer + " --shape-tolerance -1").status, 2);
}

TEST(Cli, RenderAFrameRangeFromTheCacheAlone) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  ASSERT_EQ(runCrumple("run " + (tmp / "scene").string() + " --out " + (tmp / "a").string()).status,
            0);
  // The render command needs only the cache: move the scene away.
  fs::remove_all(tmp / "scene");
  const auto r = runCrumple("render " + (tmp / "a/cache.pcache").string() +
                            " --frames 3-4 --backend osmesa --out " + (tmp / "b").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_FALSE(fs::exists(tmp / "b/0002.png"));
  EXPECT_TRUE(fs::exists(tmp / "b/0005.png") == false);
  for (const char* f : {"0003.png", "0004.png"})
    EXPECT_EQ(readFile(tmp / "b" / f), readFile(tmp / "a/frames" / f))
        << f << " re-rendered identically";
  EXPECT_EQ(runCrumple("render " + (tmp / "a/cache.pcache").string() + " --frames 5-9").status, 2);
  EXPECT_EQ(runCrumple("render " + (tmp / "a/cache.pcache").string() + " --backend vulkan").status,
            2);
}

TEST(Cli, SameSeedGivesIdenticalBytesOnOneAndTwoThreads) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  ASSERT_EQ(
      runCrumple("run " + (tmp / "scene").string() + " --threads 1 --out " + (tmp / "t1").string())
          .status,
      0);
  ASSERT_EQ(
      runCrumple("run " + (tmp / "scene").string() + " --threads 2 --out " + (tmp / "t2").string())
          .status,
      0);
  ASSERT_EQ(
      runCrumple("run " + (tmp / "scene").string() + " --threads 1 --out " + (tmp / "t3").string())
          .status,
      0);
  const auto c1 = readFile(tmp / "t1/cache.pcache");
  ASSERT_FALSE(c1.empty());
  EXPECT_EQ(c1, readFile(tmp / "t2/cache.pcache"));
  EXPECT_EQ(c1, readFile(tmp / "t3/cache.pcache"));
  for (int f = 1; f <= 6; ++f) {
    char name[16];
    std::snprintf(name, sizeof name, "%04d.png", f);
    const auto png = readFile(tmp / "t1/frames" / name);
    ASSERT_FALSE(png.empty());
    EXPECT_EQ(png, readFile(tmp / "t2/frames" / name)) << name;
    EXPECT_EQ(png, readFile(tmp / "t3/frames" / name)) << name;
  }
}

TEST(Cli, RenderWithEmbreeWritesPngAndExrIdenticallyOnAnyThreadCount) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  ASSERT_EQ(
      runCrumple("simulate " + (tmp / "scene").string() + " --out " + (tmp / "a").string()).status,
      0);
  const std::string cache = (tmp / "a/cache.pcache").string();
  for (const char* t : {"1", "2"}) {
    const auto r =
        runCrumple("render " + cache + " --frames 2-3 --backend embree --spp 2 --exr " +
                   "--threads " + t + " --out " + (tmp / (std::string("e") + t)).string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("(embree)"), std::string::npos) << r.output;
  }
  for (const char* f : {"0002.png", "0003.png", "0002.exr", "0003.exr"}) {
    const auto one = readFile(tmp / "e1" / f);
    EXPECT_FALSE(one.empty()) << f;
    EXPECT_EQ(one, readFile(tmp / "e2" / f)) << f << " differs between 1 and 2 threads";
  }
  EXPECT_FALSE(fs::exists(tmp / "e1/0001.png")) << "only the asked frames";
  // The preview's EXR is its PNG in linear light, premultiplied; --no-png
  // writes the EXR alone.
  ASSERT_EQ(
      runCrumple("render " + cache + " --frames 2-2 --exr --out " + (tmp / "o").string()).status,
      0);
  ASSERT_EQ(
      runCrumple("render " + cache + " --frames 2-2 --exr --no-png --out " + (tmp / "x").string())
          .status,
      0);
  EXPECT_FALSE(fs::exists(tmp / "x/0002.png"));
  EXPECT_EQ(readFile(tmp / "x/0002.exr"), readFile(tmp / "o/0002.exr"));
  const auto png = crumple::exporters::readPng((tmp / "o/0002.png").string());
  const auto exr = crumple::exporters::readExr((tmp / "o/0002.exr").string());
  ASSERT_EQ(exr.width, png.width);
  for (const auto& [x, y] : {std::pair{0, 0}, std::pair{png.width / 2, png.height / 2}}) {
    const float a = png.at(x, y)[3] / 255.0f;
    EXPECT_NEAR(exr.at(x, y)[3], a, 1e-3);
    EXPECT_NEAR(exr.at(x, y)[1], crumple::render::srgb8ToLinear(png.at(x, y)[1]) * a, 2e-3);
  }
  EXPECT_FALSE(fs::exists(tmp / "e1/0002.png.tmp")) << "no temporary left behind";
  // Options that make no sense are refused with exit 2.
  EXPECT_EQ(runCrumple("render " + cache + " --backend embree --spp 0").status, 2);
  EXPECT_EQ(runCrumple("render " + cache + " --pass normals").status, 2);
  EXPECT_EQ(runCrumple("render " + cache + " --no-png").status, 2);
  EXPECT_EQ(runCrumple("render " + cache + " --backend embree --debug-structure").status, 2);
}

TEST(Cli, CompareExitsZeroWithinToleranceOneOutsideAndWritesADiff) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  ASSERT_EQ(runCrumple("run " + (tmp / "scene").string() + " --out " + (tmp / "a").string()).status,
            0);
  const std::string f2 = (tmp / "a/frames/0002.png").string();
  const std::string f6 = (tmp / "a/frames/0006.png").string();
  for (const char* metric : {"mae", "psnr", "flip"}) {
    const auto same = runCrumple("compare " + f2 + " " + f2 + " --metric " + metric +
                                 " --tolerance " + (std::string(metric) == "psnr" ? "60" : "0") +
                                 " --diff " + (tmp / "d.png").string());
    EXPECT_EQ(same.status, 0) << same.output;
    EXPECT_NE(same.output.find("PASS"), std::string::npos);
    EXPECT_TRUE(fs::exists(tmp / "d.png"));
  }
  // Frames 2 and 6 differ (the sheet moves): a tight tolerance fails with 1,
  // the default diff image lands beside B.
  const auto differ = runCrumple("compare " + f2 + " " + f6 + " --metric mae --tolerance 0.001");
  EXPECT_EQ(differ.status, 1) << differ.output;
  EXPECT_NE(differ.output.find("FAIL"), std::string::npos);
  EXPECT_TRUE(fs::exists(tmp / "a/frames/0006.diff.png"));
  EXPECT_EQ(runCrumple("compare " + f2 + " " + f6 + " --metric mae --tolerance 255").status, 0);
  EXPECT_EQ(runCrumple("compare " + f2 + " " + (tmp / "missing.png").string()).status, 2);
  EXPECT_EQ(runCrumple("compare " + f2 + " " + f6 + " --metric ssim").status, 2);
}

TEST(Cli, ContactSheetAndMovie) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  const auto r = runCrumple("run " + (tmp / "scene").string() + " --contact-sheet --movie --out " +
                            (tmp / "a").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(tmp / "a/contact_sheet.png"));
  EXPECT_NE(r.output.find("contact_sheet.png"), std::string::npos) << r.output;
  const bool haveFfmpeg = runCommand("command -v ffmpeg").status == 0;
  if (haveFfmpeg) {
    EXPECT_TRUE(fs::exists(tmp / "a/preview.mp4")) << r.output;
    EXPECT_GT(fs::file_size(tmp / "a/preview.mp4"), 1000u);
    EXPECT_NE(r.output.find("silent"), std::string::npos) << "no sound.wav yet: " << r.output;
  } else {
    EXPECT_FALSE(fs::exists(tmp / "a/preview.mp4"));
    EXPECT_NE(r.output.find("ffmpeg is not installed"), std::string::npos) << r.output;
  }
  // The movie is muxed with the shot's soundtrack when there is one.
  if (haveFfmpeg &&
      runCommand("ffmpeg -nostdin -loglevel error -f lavfi -i sine=frequency=440:duration=1 -y " +
                 (tmp / "a/sound.wav").string())
              .status == 0) {
    const auto m = runCrumple("render " + (tmp / "a/cache.pcache").string() + " --movie");
    ASSERT_EQ(m.status, 0) << m.output;
    const auto probe = runCommand("ffprobe -v error -show_entries stream=codec_type -of csv=p=0 " +
                                  (tmp / "a/preview.mp4").string());
    EXPECT_NE(probe.output.find("audio"), std::string::npos) << probe.output;
    EXPECT_NE(probe.output.find("video"), std::string::npos) << probe.output;
  }
}

TEST(Cli, TheCacheCarriesTheTextureSoRenderingNeedsNothingElse) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  // A texture with a transparent window, and a box prop.
  crumple::ImageRGBA8 tex(16, 16);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      std::uint8_t* p = tex.at(x, y);
      p[0] = static_cast<std::uint8_t>(16 * x);
      p[1] = static_cast<std::uint8_t>(16 * y);
      p[2] = 200;
      p[3] = (x >= 6 && x < 10 && y >= 6 && y < 10) ? 0 : 255;
    }
  crumple::exporters::writePng((tmp / "scene/print.png").string(), tex);
  auto scene = readFile(tmp / "scene/scene.toml");
  scene.replace(scene.find("[paper]\n"), 8, "[paper]\ntexture = \"print.png\"\n");
  scene += "[[props]]\nshape = \"box\"\nsize = [5, 5, 5]\nposition = [8, 2.5, 0]\n";
  writeFile(tmp / "scene/scene.toml", scene);
  ASSERT_EQ(runCrumple("run " + (tmp / "scene").string() + " --out " + (tmp / "a").string()).status,
            0);
  fs::remove_all(tmp / "scene");  // the texture file is gone too
  const auto r = runCrumple("render " + (tmp / "a/cache.pcache").string() + " --frames 4-4 --out " +
                            (tmp / "b").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(readFile(tmp / "b/0004.png"), readFile(tmp / "a/frames/0004.png"));
  // A texture that is not a PNG is an input error before anything is written.
  writeSmallScene(tmp / "bad");
  writeFile(tmp / "bad/print.png", "not a png");
  auto bad = readFile(tmp / "bad/scene.toml");
  bad.replace(bad.find("[paper]\n"), 8, "[paper]\ntexture = \"print.png\"\n");
  writeFile(tmp / "bad/scene.toml", bad);
  const auto e = runCrumple("run " + (tmp / "bad").string() + " --out " + (tmp / "c").string());
  EXPECT_EQ(e.status, 2) << e.output;
  EXPECT_NE(e.output.find("paper.texture"), std::string::npos) << e.output;
  EXPECT_FALSE(fs::exists(tmp / "c/cache.pcache"));
}

// Every bad input exits 2, names the file and the problem, and leaves no
// cache or frames behind.
class BadInput : public ::testing::Test {
 protected:
  void expectRejected(const std::string& args, const std::vector<std::string>& mentions) {
    const auto r = runCrumple(args + " --out " + (tmp_ / "out").string());
    EXPECT_EQ(r.status, 2) << r.output;
    for (const auto& m : mentions)
      EXPECT_NE(r.output.find(m), std::string::npos) << "missing '" << m << "' in: " << r.output;
    EXPECT_FALSE(fs::exists(tmp_ / "out/cache.pcache"));
    EXPECT_FALSE(fs::exists(tmp_ / "out/frames/0001.png"));
  }
  // The small scene with `from` replaced by `to` in its scene.toml must be
  // rejected, the output naming `mentions`.
  void expectEditRejected(const std::string& from, const std::string& to,
                          const std::vector<std::string>& mentions) {
    writeSmallScene(tmp_ / "s");
    auto scene = smallSceneToml();
    scene.replace(scene.find(from), from.size(), to);
    writeFile(tmp_ / "s/scene.toml", scene);
    expectRejected("run " + (tmp_ / "s").string(), mentions);
  }
  TempDir tmp_;
};

TEST_F(BadInput, MissingSceneFile) {
  expectRejected("run " + (tmp_ / "nope/scene.toml").string(), {"nope/scene.toml"});
}

TEST_F(BadInput, MalformedGltf) {
  writeSmallScene(tmp_ / "s");
  writeFile(tmp_ / "s/anim.gltf", "{ \"asset\": { \"version\": \"2.0\" }, \"nodes\": [ oops");
  expectRejected("run " + (tmp_ / "s").string(), {"anim.gltf"});
}

TEST_F(BadInput, MissingHandleNode) {
  expectEditRejected("node = \"B\"", "node = \"Nobody\"", {"scene.toml", "Nobody"});
}

TEST_F(BadInput, NanKeyframe) {
  writeSmallScene(tmp_ / "s");
  writeFile(tmp_ / "s/anim.gltf", smallAnimation(std::numeric_limits<float>::quiet_NaN()));
  expectRejected("run " + (tmp_ / "s").string(), {"anim.gltf"});
}

TEST_F(BadInput, UnknownTomlKey) {
  writeSmallScene(tmp_ / "s");
  writeFile(tmp_ / "s/scene.toml", smallSceneToml("wobble = 3\n"));
  // [sheet] wobble is on line 16 of the generated scene.
  expectRejected("run " + (tmp_ / "s").string(), {"scene.toml:16", "wobble"});
}

TEST_F(BadInput, NegativeSheetSize) {
  expectEditRejected("width = 10.0", "width = -10.0", {"scene.toml", "width"});
}

TEST_F(BadInput, UnwritableOutputFolder) {
  writeSmallScene(tmp_ / "s");
  // A path below a regular file can never be created, even by root.
  writeFile(tmp_ / "blocker", "x");
  const auto r =
      runCrumple("run " + (tmp_ / "s").string() + " --out " + (tmp_ / "blocker/out").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("blocker/out"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(tmp_ / "blocker/out"));
}

TEST_F(BadInput, BadFrameRangeAndCorruptCache) {
  writeSmallScene(tmp_ / "s");
  expectRejected("run " + (tmp_ / "s").string() + " --frames 4-2", {"--frames"});
  expectRejected("run " + (tmp_ / "s").string() + " --frames 1-99", {"--frames"});
  writeFile(tmp_ / "junk.pcache", "definitely not a cache");
  const auto r = runCrumple("inspect " + (tmp_ / "junk.pcache").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("junk.pcache"), std::string::npos) << r.output;
}

TEST(Cli, InspectReportsATruncatedCacheAndAFlippedByte) {
  TempDir tmp;
  writeSmallScene(tmp / "scene");
  ASSERT_EQ(runCrumple("simulate " + (tmp / "scene").string() + " --out " + (tmp / "out").string())
                .status,
            0);
  const auto bytes = readFile(tmp / "out/cache.pcache");
  // Cut in the middle of the file: the complete frames before the cut are recovered.
  writeFile(tmp / "cut.pcache", bytes.substr(0, bytes.size() / 2));
  const auto cut = runCrumple("inspect --json " + (tmp / "cut.pcache").string());
  EXPECT_EQ(cut.status, 0) << cut.output;
  EXPECT_EQ(cut.output.find("\"frame_count\":6"), std::string::npos);
  EXPECT_NE(cut.output.find("\"frame\":1,"), std::string::npos) << cut.output;
  const auto cutText = runCrumple("inspect " + (tmp / "cut.pcache").string());
  EXPECT_NE(cutText.output.find("recovered"), std::string::npos) << cutText.output;
  // A flipped byte near the end (inside the last frame's block or the
  // footer) is reported; inside a frame, by its CRC with the frame number.
  auto flipped = bytes;
  flipped[bytes.size() * 3 / 4] = static_cast<char>(flipped[bytes.size() * 3 / 4] ^ 0x40);
  writeFile(tmp / "flip.pcache", flipped);
  const auto bad = runCrumple("inspect " + (tmp / "flip.pcache").string());
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find("CRC"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("frame "), std::string::npos) << bad.output;
}

// --aov: the path tracer's AOV layers in the frame's EXR, listed by
// OpenEXR's own exrheader (installed by scripts/bootstrap.sh), with the
// crumpling model's regions; refused by the preview and for unknown names.
TEST(Cli, RenderWithAovsWritesTheLayersACompositorReads) {
  TempDir tmp;
  ASSERT_EQ(runCrumple("simulate " + sourcePath("samples/cylinder-fold") + " --out " +
                       (tmp / "a").string())
                .status,
            0);
  const std::string cache = (tmp / "a/cache.pcache").string();
  const auto r = runCrumple("render " + cache +
                            " --frames 70-70 --backend embree --spp 2 --no-png --aov "
                            "depth,normal,albedo,position,region,handle-id,object-id --out " +
                            (tmp / "f").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string exr = (tmp / "f/0070.exr").string();
  EXPECT_FALSE(fs::exists(tmp / "f/0070.png"));
  const crumple::ImageChannels layers = crumple::exporters::readExrChannels(exr);
  const std::vector<std::string> expected = {
      "A",        "B",        "G",        "IndexHandle.X", "IndexOB.X", "N.X", "N.Y",
      "N.Z",      "P.X",      "P.Y",      "P.Z",           "R",         "Z",   "albedo.B",
      "albedo.G", "albedo.R", "region.B", "region.G",      "region.R"};
  std::vector<std::string> names;
  for (const auto& c : layers.channels) names.push_back(c.name);
  EXPECT_EQ(names, expected);
  // The shot's sheet is seen (object 1), curved paper and singular
  // neighbourhoods at this frame of the bend, and every handle id is one of
  // the scene's four handles or none.
  double sheet = 0.0, flat = 0.0, curved = 0.0, singular = 0.0;
  for (std::size_t i = 0; i < layers.channels[0].pixels.size(); ++i) {
    sheet += layers.find("IndexOB.X")->pixels[i] == 1.0f;
    flat += layers.find("region.R")->pixels[i];
    curved += layers.find("region.G")->pixels[i];
    singular += layers.find("region.B")->pixels[i];
    const float h = layers.find("IndexHandle.X")->pixels[i];
    EXPECT_TRUE(h >= 0.0f && h <= 4.0f && h == std::floor(h)) << h;
  }
  EXPECT_GT(sheet, 1000.0);
  EXPECT_GT(curved, 100.0);
  EXPECT_GT(singular, 100.0);
  EXPECT_NEAR(flat + curved + singular, sheet, 0.02 * sheet);  // every sheet pixel labelled
  const auto header = runCommand("exrheader " + exr);
  ASSERT_EQ(header.status, 0) << "exrheader (Debian's openexr, scripts/bootstrap.sh): "
                              << header.output;
  for (const std::string& name : expected)
    EXPECT_NE(header.output.find("    " + name + ", "), std::string::npos) << name;
  EXPECT_EQ(runCrumple("render " + cache + " --frames 40-40 --aov depth").status, 2)
      << "the preview has no AOVs";
  EXPECT_EQ(runCrumple("render " + cache + " --backend embree --aov depth,speed").status, 2);
}
