// Time origins of DCC files as Blender 3.4 writes them
// (tests/io/data/blender/make_time_origin.py): one animation exported with
// the scene starting at frame 0 and at frame 1 (Blender's default) as FBX,
// glTF, GLB and COLLADA. Every format puts the animated node where Blender
// shows it at every frame, within 1e-5 m; FBX takes are read back from the
// file (src/io/src/fbx_takes.hpp).
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/io/animation.hpp"
#include "fbx_takes.hpp"

namespace crumple::io {
namespace {

constexpr double kTol = 1e-5;  // m

std::string blenderData(const std::string& name) {
  return std::string(CRUMPLE_IO_TEST_DATA) + "/blender/" + name;
}

// Blender's own world positions of Handle (startN.json), in crumple's
// world (Y up: Blender's (x, y, z) is (x, z, -y)).
struct Truth {
  double fps = 24.0;
  std::vector<int> frames;
  std::vector<Vec3> handle;
};

Truth readTruth(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  Truth t;
  // {"fps": 24, "frames": [...], "handle": [[x, y, z], ...]}: numbers in order.
  const std::size_t framesAt = text.find("\"frames\""), handleAt = text.find("\"handle\"");
  EXPECT_NE(framesAt, std::string::npos);
  EXPECT_NE(handleAt, std::string::npos);
  const auto numbers = [&](std::size_t from, std::size_t to) {
    std::vector<double> out;
    std::string token;
    for (std::size_t i = from; i < to; ++i) {
      const char c = text[i];
      if ((c >= '0' && c <= '9') || c == '-' || c == '.' || c == 'e' || c == 'E' || c == '+') {
        token += c;
      } else if (!token.empty()) {
        out.push_back(std::stod(token));
        token.clear();
      }
    }
    return out;
  };
  for (const double f : numbers(framesAt + 8, handleAt)) t.frames.push_back(static_cast<int>(f));
  const std::vector<double> xyz = numbers(handleAt + 8, text.size());
  for (std::size_t i = 0; i + 2 < xyz.size(); i += 3)
    t.handle.push_back(Vec3(xyz[i], xyz[i + 2], -xyz[i + 1]));
  EXPECT_EQ(t.frames.size(), t.handle.size());
  return t;
}

class TimeOrigin : public ::testing::TestWithParam<int> {};

TEST_P(TimeOrigin, EveryFormatShowsBlendersFrameAtEveryFrame) {
  const int start = GetParam();
  const std::string stem = "start" + std::to_string(start);
  const Truth truth = readTruth(blenderData(stem + ".json"));
  ASSERT_FALSE(truth.frames.empty());
  EXPECT_EQ(truth.frames.front(), start);
  for (const char* ext : {".fbx", ".gltf", ".glb", ".dae"}) {
    const AnimationScene scene = AnimationScene::load(blenderData(stem + ext));
    double worst = 0.0;
    for (std::size_t i = 0; i < truth.frames.size(); ++i) {
      const double t = truth.frames[i] / truth.fps;
      const Vec3 p = scene.worldPose("Handle", t).position;
      worst = std::max(worst, (p - truth.handle[i]).norm());
      EXPECT_LE((p - truth.handle[i]).norm(), kTol)
          << stem << ext << " frame " << truth.frames[i] << ": " << p.transpose() << " against "
          << truth.handle[i].transpose();
    }
    std::printf("%s%s: largest distance from Blender's Handle over %zu frames %.2e m\n",
                stem.c_str(), ext, truth.frames.size(), worst);
  }
}

INSTANTIATE_TEST_SUITE_P(BlenderStartFrames, TimeOrigin, ::testing::Values(0, 1));

TEST(FbxTakes, BlendersTakeStartsAtItsSceneStart) {
  for (const int start : {0, 1}) {
    const auto takes = detail::readFbxTakes(blenderData("start" + std::to_string(start) + ".fbx"));
    ASSERT_FALSE(takes.empty());
    for (const auto& take : takes) {
      EXPECT_NEAR(detail::assimpKeyShift(take), start / 24.0, 1e-12) << take.name;
      ASSERT_TRUE(take.firstKey.has_value()) << take.name;
    }
  }
}

// A binary FBX cut short anywhere, or with a record's length damaged, is an
// InputError naming the file (or reads to the end), never a crash: the
// reader checks every offset against its parent record and the file.
TEST(FbxTakes, DamagedBinaryFilesAreInputErrors) {
  const std::string source = blenderData("start1.fbx");
  std::ifstream in(source, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1000u);
  const std::string cut = ::testing::TempDir() + "/crumple_fbx_cut.fbx";
  int errors = 0, tried = 0;
  for (std::size_t length = 27; length < bytes.size(); length += 97) {
    for (const bool damage : {false, true}) {
      std::string b = bytes.substr(0, length);
      if (damage) b[length / 2] = static_cast<char>(b[length / 2] ^ 0x5A);
      std::ofstream(cut, std::ios::binary) << b;
      ++tried;
      try {
        (void)detail::readFbxTakes(cut);
      } catch (const InputError& e) {
        ++errors;
        EXPECT_NE(std::string(e.what()).find(cut), std::string::npos) << e.what();
      }
    }
  }
  EXPECT_GT(errors, tried / 2) << "most damaged files are refused";
}

// Blender's default FBX export (All Actions, NLA Strips) writes a take per
// object and action, each restarted at 0: the import says so.
TEST(FbxTakes, BlendersPerActionTakesAreNamedInAWarning) {
  const AnimationScene scene = AnimationScene::load(blenderData("per_action.fbx"));
  bool warned = false;
  for (const std::string& w : scene.warnings())
    warned = warned || w.find("per-action export") != std::string::npos;
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace crumple::io
