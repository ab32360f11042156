// Hostile files and interrupted runs at the command line (docs/RELIABILITY.md):
// each case of the table there, with its exit status and what the message
// must name.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "test_util.hpp"

namespace crumple::testing {
namespace {

void expectExit2Naming(const CommandResult& r, const std::vector<std::string>& words) {
  EXPECT_EQ(r.status, 2) << r.output;
  for (const auto& w : words)
    EXPECT_NE(r.output.find(w), std::string::npos) << w << "\n" << r.output;
}

// The small shot's cache, simulated once per test into `dir`.
fs::path simulateSmall(const fs::path& dir, bool sound = false) {
  writeSmallScene(dir / "scene");
  if (sound) writeFile(dir / "scene/scene.toml", smallSceneToml() + "[sound]\n");
  const auto r =
      runCrumple("simulate " + (dir / "scene").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.status, 0) << r.output;
  return dir / "out/cache.pcache";
}

// A copy of `source` with its header and every frame passed through `edit`,
// written by the cache writer (which does not check): CRC-valid, hostile.
fs::path rewritten(const fs::path& source, const fs::path& target,
                   const std::function<void(cache::CacheHeader&)>& header,
                   const std::function<void(cache::FrameRecord&)>& frame) {
  const cache::CacheReader in(source.string());
  cache::CacheHeader h = in.header();
  header(h);
  cache::CacheWriter out(target.string(), h);
  for (std::size_t i = 0; i < in.frameCount(); ++i) {
    cache::FrameRecord f = in.readFrame(i);
    frame(f);
    out.append(f);
  }
  out.close();
  return target;
}

// The reproduction: frame 0 of a 3-frame `samples/crumple` cache
// with one index changed and its chunk's CRC recomputed
// (tests/fuzz/regressions/cache_tools/). Every tool that reads frames stops
// with exit 2 naming the file, the frame and the block, before any index is used.
TEST(HostileCache, AnIndexOutsideTheFrameIsExit2NamingFrameAndBlock) {
  TempDir tmp;
  const std::string dir = sourcePath("tests/fuzz/regressions/cache_tools/");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"triangle-index-minus-5.pcache", "topology: triangle 0 has vertex -5"},
      {"triangle-index-999999.pcache", "topology: triangle 0 has vertex 999999"},
      {"triangle-index-equal-to-vertex-count.pcache", "topology: triangle 0 has vertex 81"},
      {"handle-vertex-1e7.pcache", "handles: handle 0 has vertex 10000000"}};
  for (const auto& [file, block] : cases) {
    SCOPED_TRACE(file);
    const std::string path = dir + file;
    const std::vector<std::string> words = {path, "frame 0", block};
    expectExit2Naming(runCrumple("inspect " + path), words);
    expectExit2Naming(runCrumple("inspect --json " + path), words);
    expectExit2Naming(runCrumple("render " + path + " --debug-structure --frames 0-0 --out " +
                                 (tmp / "frames").string()),
                      words);
    expectExit2Naming(
        runCrumple("export " + path + " --format ply --out " + (tmp / "ply").string()), words);
  }
}

TEST(HostileCache, AnImpossibleFpsOrANonFinitePositionIsExit2) {
  TempDir tmp;
  const fs::path good = simulateSmall(tmp.path(), /*sound=*/true);
  const auto keep = [](auto&) {};
  for (const double fps : {std::numeric_limits<double>::quiet_NaN(), 0.0, -24.0}) {
    SCOPED_TRACE(fps);
    const fs::path bad = rewritten(
        good, tmp / "fps.pcache", [&](cache::CacheHeader& h) { h.fps = fps; }, keep);
    const std::vector<std::string> words = {bad.string(), "damaged cache header: fps"};
    expectExit2Naming(runCrumple("sound " + bad.string() + " --out " + (tmp / "s.wav").string()),
                      words);
    for (const char* format : {"usda", "gltf"})
      expectExit2Naming(runCrumple("export " + bad.string() + " --format " + format + " --out " +
                                   (tmp / format).string()),
                        words);
  }
  const fs::path nan = rewritten(good, tmp / "nan.pcache", keep, [](cache::FrameRecord& f) {
    if (f.frame == 3) f.positions[2].y() = std::numeric_limits<double>::quiet_NaN();
  });
  expectExit2Naming(runCrumple("render " + nan.string() + " --out " + (tmp / "frames").string()),
                    {nan.string(), "frame 3", "positions: vertex 2 is not finite or beyond 1e9 m"});
}

// A cache without its footer (the shot was killed after frame 3 of 6) still
// renders, sounds and exports, and each says so on stderr and in its summary.
TEST(RecoveredCache, EveryToolSaysHowManyOfThePlannedFramesItHolds) {
  TempDir tmp;
  const fs::path good = simulateSmall(tmp.path(), /*sound=*/true);
  const cache::CacheReader whole(good.string());
  ASSERT_EQ(whole.frameCount(), 6u);
  // The first three frames, as a run killed after them leaves the file.
  const fs::path cut = tmp / "cut.pcache";
  {
    cache::CacheWriter w(cut.string(), whole.header());
    for (std::size_t i = 0; i < 3; ++i) w.append(whole.readFrame(i));
  }  // destroyed without close(): no footer, as a killed run leaves it
  const std::string note = "of the 6 planned frames (1-6)";
  for (const std::string& command :
       {"render " + cut.string() + " --out " + (tmp / "frames").string(),
        "sound " + cut.string() + " --out " + (tmp / "cut.wav").string(),
        "export " + cut.string() + " --format obj --out " + (tmp / "obj").string()}) {
    SCOPED_TRACE(command);
    const auto r = runCrumple(command);
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find(cut.string() + " has no footer"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("holds 3 " + note), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("  note: "), std::string::npos) << r.output;  // the summary's line
  }
  const auto json = runCrumple("inspect --json " + cut.string());
  EXPECT_EQ(json.status, 0) << json.output;
  EXPECT_NE(json.output.find("\"recovered\":true"), std::string::npos) << json.output;
  EXPECT_NE(json.output.find("\"planned_frames\":6"), std::string::npos) << json.output;
  const auto complete = runCrumple("inspect --json " + good.string());
  EXPECT_NE(complete.output.find("\"recovered\":false"), std::string::npos) << complete.output;
}

// The small shot with its own handle tracks and extra [scene] lines.
fs::path smallShot(const fs::path& dir, const std::vector<GltfTrack>& tracks,
                   const std::string& sceneLines = "") {
  fs::create_directories(dir);
  std::string toml = smallSceneToml();
  toml.insert(toml.find("[sheet]"), sceneLines);
  writeFile(dir / "scene.toml", toml);
  writeFile(dir / "anim.gltf", makeGltf(tracks));
  return dir;
}

// Two handle nodes at one point from the first frame: every frame halves its
// substep again and again. The cost guard stops the shot after three such
// frames, naming the handles, and the cache keeps the frames before.
TEST(CostGuardShot, HandlesAtOnePointStopTheShotNamingThem) {
  TempDir tmp;
  const std::array<float, 3> p{0.0f, 0.20f, 0.0f};
  const fs::path scene =
      smallShot(tmp / "s", {{"A", {0.0f, 0.25f}, {p, p}}, {"B", {0.0f, 0.25f}, {p, p}}});
  const auto r = runCrumple("simulate " + scene.string() + " --out " + (tmp / "out").string());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("stage 'cost guard'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("handles 'left' and 'right' are at one point"), std::string::npos)
      << r.output;
  const cache::CacheReader reader((tmp / "out/cache.pcache").string());
  EXPECT_FALSE(reader.recovered());  // closed: valid up to the last good frame
  EXPECT_TRUE(reader.verifyAll().empty());
}

// A key that throws a node a kilometre away: the frame runs past its budget
// ([scene] frame_budget_s here, so that the test is quick), and the stop
// says which handle is out of reach.
TEST(CostGuardShot, AFrameOverItsBudgetStopsTheShotNamingTheLikelyCause) {
  TempDir tmp;
  const fs::path scene =
      smallShot(tmp / "s",
                // Bound at frame 1 (t = 1/24 s), a kilometre away from frame 2 on:
                // whichever frame runs past the budget, the cause is there.
                {{"A",
                  {0.0f, 0.042f, 0.05f},
                  {{-0.05f, 0.2f, 0.0f}, {-0.05f, 0.2f, 0.0f}, {1000.0f, 0.2f, 0.0f}}},
                 {"B", {0.0f, 0.25f}, {{0.05f, 0.2f, 0.0f}, {0.05f, 0.2f, 0.0f}}}},
                "frame_budget_s = 0.001\n");
  const auto r = runCrumple("simulate " + scene.string() + " --out " + (tmp / "out").string());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("ran past its budget of 0.001 s"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("likely cause: handles 'left' and 'right' are"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("farther than the sheet reaches"), std::string::npos) << r.output;
}

// Parse-time checks and the command line's own (docs/RELIABILITY.md, items
// 5 and 8): each is exit 2 naming the file, line and key or the option.
TEST(BadInputCases, EachIsExit2NamingWhatIsWrong) {
  TempDir tmp;
  writeSmallScene(tmp / "s");
  const std::string simulate =
      "simulate " + (tmp / "s").string() + " --out " + (tmp / "out").string();
  struct Case {
    std::string from, to;  // the scene line changed (empty: the scene as it is)
    std::string command;
    std::vector<std::string> words;
  };
  const std::vector<Case> cases = {
      {"width = 10.0", "width = 1e6", simulate, {"scene.toml:", "'sheet.width'", "not a sheet"}},
      {"width = 10.0", "width = 1e15", simulate, {"'sheet.width'", "not a sheet"}},
      {"width = 10.0", "width = 1e30", simulate, {"'sheet.width'", "not a sheet"}},
      {"max_edge = 2.5", "max_edge = 0.005", simulate, {"'sheet.max_edge'", "vertices, more than"}},
      {"resolution = [160, 120]",
       "resolution = [16384, 16384]",
       simulate,
       {"'camera.resolution'", "268435456 pixels"}},
      {"name = \"small\"",
       "name = \"../../escape\"",
       simulate,
       {"'scene.name'", "not a folder name"}},
      {"animation = \"anim.gltf\"",
       "animation = \"anim.txt\"",
       simulate,
       {"'scene.animation'", "not a .gltf"}},
      {"pattern = [10.0, 10.0]",
       "pattern = [0.0, 10.0]",
       simulate,
       {"scene.toml:", "'handles.pattern'", "bind the same sheet vertex"}},
      {"", "", simulate + " --seed -1", {"--seed", "'-1' is not a seed"}},
      {"", "", simulate + " --seed 12345678901234567890123", {"--seed"}},
      {"", "", "compare a.png b.png --tolerance nan", {"--tolerance"}},
      {"", "", "frobnicate", {"'frobnicate' is not a command", "simulate"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.command + " with " + c.to);
    std::string toml = smallSceneToml();
    if (!c.from.empty()) {
      const auto at = toml.find(c.from);
      ASSERT_NE(at, std::string::npos) << c.from;
      toml.replace(at, c.from.size(), c.to);
    }
    writeFile(tmp / "s/scene.toml", toml);
    expectExit2Naming(runCrumple(c.command), c.words);
  }
}

// Keys that go back in time are an authoring error, named with the node.
TEST(BadInputCases, DecreasingKeyTimesAreExit2NamingTheNode) {
  TempDir tmp;
  const fs::path scene =
      smallShot(tmp / "s", {{"A",
                             {0.0f, 0.2f, 0.1f},
                             {{-0.05f, 0.2f, 0.0f}, {-0.05f, 0.2f, 0.0f}, {-0.05f, 0.2f, 0.0f}}},
                            {"B", {0.0f, 0.25f}, {{0.05f, 0.2f, 0.0f}, {0.05f, 0.2f, 0.0f}}}});
  expectExit2Naming(runCrumple("simulate " + scene.string() + " --out " + (tmp / "out").string()),
                    {"anim.gltf", "node 'A'", "key 2", "must not decrease"});
}

// `sound --gain-db` beyond any mix, `--out` naming a folder, and a damaged
// SEVT block named with the cache and the frame.
TEST(BadInputCases, SoundOptionsAndDamagedEvents) {
  TempDir tmp;
  const fs::path cachePath = simulateSmall(tmp.path(), /*sound=*/true);
  expectExit2Naming(runCrumple("sound " + cachePath.string() + " --gain-db 1e308"), {"--gain-db"});
  fs::create_directories(tmp / "wav");
  const auto folder =
      runCrumple("sound " + cachePath.string() + " --out " + (tmp / "wav").string());
  EXPECT_EQ(folder.status, 0) << folder.output;
  EXPECT_TRUE(fs::exists(tmp / "wav/sound.wav"));
  const fs::path bad = rewritten(
      cachePath, tmp / "sevt.pcache", [](auto&) {},
      [](cache::FrameRecord& f) {
        if (f.frame == 2) f.extensions.push_back({{'S', 'E', 'V', 'T'}, {1, 2, 3}});
      });
  expectExit2Naming(runCrumple("sound " + bad.string() + " --out " + (tmp / "b.wav").string()),
                    {bad.string(), "frame 2", "SEVT"});
}

// A killed writer's temporaries are removed by the next writer of the
// folder; a write that fails (here the file size limit, as a full disk
// does) leaves none and is exit 2 naming the file.
TEST(Temporaries, NoneIsLeftBehind) {
  TempDir tmp;
  const fs::path cachePath = simulateSmall(tmp.path(), /*sound=*/true);
  writeFile(tmp / "out/summary.json.tmp", "{ half written");
  writeFile(tmp / "out/sound.wav.tmp", "RIFF");
  writeFile(tmp / "out/0001.obj.4242.tmp", "v 0 0 0");
  const auto again =
      runCrumple("simulate " + (tmp / "scene").string() + " --out " + (tmp / "out").string());
  EXPECT_EQ(again.status, 0) << again.output;
  for (const char* name : {"summary.json.tmp", "sound.wav.tmp", "0001.obj.4242.tmp"})
    EXPECT_FALSE(fs::exists(tmp / "out" / name)) << name;
  EXPECT_TRUE(fs::exists(tmp / "out/summary.json"));
  // 16 blocks of 512 bytes: the WAV (0.25 s of stereo 24-bit at 48 kHz,
  // 72 kB) cannot be written; SIGXFSZ ignored, the write fails with EFBIG.
  fs::create_directories(tmp / "full");
  const auto full =
      runCommand("ulimit -f 16; trap '' XFSZ; " + std::string(CRUMPLE_BIN) + " sound " +
                 cachePath.string() + " --out " + (tmp / "full/sound.wav").string());
  EXPECT_EQ(full.status, 2) << full.output;
  EXPECT_NE(full.output.find((tmp / "full/sound.wav").string()), std::string::npos) << full.output;
  for (const auto& e : fs::directory_iterator(tmp / "full"))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

}  // namespace
}  // namespace crumple::testing
