// What a resume keeps and what it refuses: `--resume` after any file that
// shapes the shot changed (the animation file and the buffers it names, the
// paper preset, the texture) is exit 2 naming the file; a resumed run's
// summary.json is the uninterrupted run's (but for its timings), on the
// elastic and on the crumpling model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_motion.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"
#include "test_util.hpp"

using namespace crumple;
using namespace crumple::testing;

namespace {

std::vector<std::uint8_t> fromBase64(const std::string& text) {
  std::vector<std::uint8_t> out;
  std::uint32_t bits = 0;
  int count = 0;
  for (const char c : text) {
    const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const char* at = std::strchr(table, c);
    if (c == '=' || c == '\0' || at == nullptr) break;
    bits = (bits << 6) | static_cast<std::uint32_t>(at - table);
    if ((count += 6) >= 8) {
      count -= 8;
      out.push_back(static_cast<std::uint8_t>(bits >> count));
    }
  }
  return out;
}

// The small scene (test_util.hpp) with its buffer in anim.bin beside
// anim.gltf, and a printed texture.
void writeSceneWithFiles(const fs::path& dir, std::uint8_t shade) {
  writeSmallScene(dir);
  std::string gltf = readFile(dir / "anim.gltf");
  const std::string prefix = "data:application/octet-stream;base64,";
  const auto from = gltf.find(prefix);
  const auto to = gltf.find('"', from);
  ASSERT_NE(from, std::string::npos);
  const auto blob = fromBase64(gltf.substr(from + prefix.size(), to - from - prefix.size()));
  writeFile(dir / "anim.bin", std::string(blob.begin(), blob.end()));
  gltf.replace(from, to - from, "anim.bin");
  writeFile(dir / "anim.gltf", gltf);
  ImageRGBA8 tex(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      std::uint8_t* p = tex.at(x, y);
      p[0] = shade;
      p[1] = static_cast<std::uint8_t>(30 * x);
      p[2] = static_cast<std::uint8_t>(30 * y);
      p[3] = 255;
    }
  exporters::writePng((dir / "print.png").string(), tex);
  std::string scene = readFile(dir / "scene.toml");
  scene.replace(scene.find("[paper]\n"), 8, "[paper]\ntexture = \"print.png\"\n");
  writeFile(dir / "scene.toml", scene);
}

// summary.json without what the clock decides: every ms_per_frame (and
// the stages' object of them) and the contacts' share of the step.
std::string modelFields(const std::string& json) {
  static const std::regex timing(R"re("(\w*ms_per_frame|share_of_step)":(\{[^}]*\}|[^,}]*))re");
  return std::regex_replace(json, timing, "\"$1\":-");
}

pipeline::ShotOptions options(const fs::path& out, bool render) {
  pipeline::ShotOptions o;
  o.outDir = out.string();
  o.render = render;
  o.log = nullptr;
  o.interactive = 0;
  return o;
}

// Runs the shot whole with a checkpoint every `every` frames, then resumes
// it from its last checkpoint (the frames after it simulated again); expects
// the same cache and the same summary (but for timings) both times.
void expectResumedSummaryIsTheWholeOne(const io::SceneSpec& scene, const fs::path& out, int every,
                                       bool render,
                                       std::optional<pipeline::FrameRange> frames = {}) {
  pipeline::ShotOptions o = options(out, render);
  o.frames = frames;
  o.checkpointEvery = every;
  (void)pipeline::runShot(scene, o);
  const std::string whole = readFile(out / "summary.json");
  const std::string cache = readFile(out / "cache.pcache");
  ASSERT_FALSE(whole.empty());
  o.checkpointEvery = 0;
  o.resume = true;
  (void)pipeline::runShot(scene, o);
  const std::string resumed = readFile(out / "summary.json");
  EXPECT_EQ(readFile(out / "cache.pcache"), cache);
  EXPECT_EQ(modelFields(resumed), modelFields(whole)) << "checkpoint every " << every;
}

// The crumpling model's shot of the resume test: samples/crumple to frame
// 45, whole, and resumed from its checkpoints every `every` frames. S_P has
// its most triangles (112) at the start and 60-71 from frame 9 on; singular
// vertices appear from frame 12, the handles lag from frame 33 and the
// whole sheet is held still on frames 36-45 (warnings with their frames).
void expectCrumplingResumeKeepsTheSummary(int every) {
  const TempDir tmp;
  const auto scene = io::loadScene(io::resolveScenePath(sourcePath("samples/crumple")));
  const pipeline::FrameRange frames{scene.frameStart, 45};
  expectResumedSummaryIsTheWholeOne(scene, tmp / "out", every, false, frames);
  const std::string summary = readFile(tmp / "out/summary.json");
  EXPECT_NE(summary.find("\"max_triangles\":112"), std::string::npos) << summary;
  EXPECT_NE(summary.find("lags behind its node"), std::string::npos) << summary;
}

}  // namespace

TEST(Resume, AChangedInputIsRefusedNamingIt) {
  const TempDir tmp;
  const fs::path dir = tmp / "scene";
  writeSceneWithFiles(dir, 200);
  // The paper preset from a folder of this test's ($CRUMPLE_ASSETS/papers).
  fs::create_directories(tmp / "assets/papers");
  fs::copy_file(sourcePath("assets/papers/office-70gsm.toml"),
                tmp / "assets/papers/office-70gsm.toml");
  const fs::path preset = tmp / "assets/papers/office-70gsm.toml";
  const std::string simulate = "env CRUMPLE_ASSETS=" + (tmp / "assets").string() + " " +
                               CRUMPLE_BIN + " simulate " + dir.string() + " --out " +
                               (tmp / "out").string() + " --checkpoint-every 2";
  const auto whole = runCommand(simulate);
  ASSERT_EQ(whole.status, 0) << whole.output;
  const std::string cache = readFile(tmp / "out/cache.pcache");

  // Each file changed in turn: refused, naming it; put back, the next one.
  const auto expectRefused = [&](const fs::path& file, const std::string& what) {
    const auto r = runCommand(simulate + " --resume");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(what + " "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(file.filename().string() +
                            " changed since the checkpoint was written: cannot resume"),
              std::string::npos)
        << r.output;
  };
  for (const auto& [name, what] : {std::pair{"anim.gltf", "the animation file"},
                                   std::pair{"anim.bin", "the file the animation file names"}}) {
    const std::string original = readFile(dir / name);
    std::string changed = original;
    if (std::string(name) == "anim.gltf")
      changed += "\n";  // the same animation, other bytes
    else
      changed[0] = static_cast<char>(changed[0] ^ 1);  // the first key's time, 0 -> 1e-45 s
    writeFile(dir / name, changed);
    expectRefused(dir / name, what);
    writeFile(dir / name, original);
  }
  const std::string presetText = readFile(preset);
  writeFile(preset, presetText + "# edited\n");
  expectRefused(preset, "the paper preset");
  writeFile(preset, presetText);
  const std::string texture = readFile(dir / "print.png");
  writeSceneWithFiles(dir, 100);  // the same scene, another texture
  expectRefused(dir / "print.png", "the paper texture");
  writeFile(dir / "print.png", texture);

  // Everything as it was: it resumes, to the same bytes.
  const auto r = runCommand(simulate + " --resume");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("resuming after frame 5"), std::string::npos) << r.output;
  EXPECT_EQ(readFile(tmp / "out/cache.pcache"), cache);
}

TEST(Resume, TheElasticModelsSummaryIsTheUninterruptedRuns) {
  // The small scene with a handle that jumps beyond the sheet's reach at
  // frame 3 (a warning with its frames), rendered: resumed after frame 5
  // (checkpoint every 4), then after frame 6 (the last: nothing left to do).
  const TempDir tmp;
  writeSmallScene(tmp / "s");
  const GltfTrack a{"A",
                    {0.0f, 0.1f, 0.125f},
                    {{-0.05f, 0.2f, 0.0f}, {-0.05f, 0.2f, 0.0f}, {-0.05f, 1e4f, 0.0f}}};
  const GltfTrack b{"B", {}, {{0.05f, 0.2f, 0.0f}}};
  writeFile(tmp / "s/anim.gltf", makeGltf({a, b}));
  const auto scene = io::loadScene((tmp / "s/scene.toml").string());
  for (const int every : {4, 5}) {
    expectResumedSummaryIsTheWholeOne(scene, tmp / "out", every, true);
    const std::string summary = readFile(tmp / "out/summary.json");
    EXPECT_NE(summary.find("\"frames_rendered\":6"), std::string::npos) << summary;
    EXPECT_NE(summary.find("pulled beyond the sheet's reach at frames 3-6"), std::string::npos)
        << summary;
  }
}

// Resumed after frame 36: the lags and the held-still steps run across it.
TEST(Resume, TheCrumplingModelsSummaryIsTheUninterruptedRuns) {
  expectCrumplingResumeKeepsTheSummary(36);
}

// The same shot resumed from its checkpoint of the last frame: nothing is
// simulated again, the summary still counts the whole shot.
TEST(Resume, ACrumplingModelResumedAtItsLastFrameKeepsTheSummary) {
  expectCrumplingResumeKeepsTheSummary(45);
}

TEST(Resume, AGustyAirShotResumesToTheSameBytes) {
  // The air keeps no state between steps (docs/AIR.md): the wind is a
  // function of place and time, the gusts of the seed.
  const TempDir tmp;
  const auto scene = io::loadScene(io::resolveScenePath(sourcePath("samples/desk-draught")));
  ASSERT_TRUE(scene.sim.air.has_value());
  // Checkpoints at frames 13 and 26: the resume simulates 27-34 again, in the gust.
  expectResumedSummaryIsTheWholeOne(scene, tmp / "out", 13, false,
                                    pipeline::FrameRange{scene.frameStart, 34});
}

TEST(Resume, AShotWithAShutterResumesToTheSameBytes) {
  // Motion blur: the first frame simulated again takes its velocities from
  // the last cached frame (the one before it), as the whole run did.
  const TempDir tmp;
  writeSmallScene(tmp / "s");
  io::SceneSpec scene = io::loadScene((tmp / "s/scene.toml").string());
  scene.camera.shutterOpen = -0.25;  // as `--shutter -0.25,0.25` sets it
  scene.camera.shutterClose = 0.25;
  expectResumedSummaryIsTheWholeOne(scene, tmp / "out", 4, false);
  const cache::CacheReader reader((tmp / "out/cache.pcache").string());
  const auto last = cache::decodeVelocities(reader.readFrame(reader.frameCount() - 1).extensions);
  ASSERT_TRUE(last.has_value());
  double fastest = 0.0;
  for (const Vec3& v : *last) fastest = std::max(fastest, v.norm());
  EXPECT_GT(fastest, 1e-3) << "the handles move the sheet in the frames resumed";
}
