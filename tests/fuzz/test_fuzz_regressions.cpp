// Replays every seed (corpus/<target>/) and every crash input found by the
// fuzzers (regressions/<target>/) through the fuzz targets' entry points,
// compiled here with g++ and renamed crumpleFuzz_<target> (CMakeLists.txt):
// each must return normally (docs/FUZZING.md). The seeds must also be inputs
// the readers accept, so the corpora keep exercising the success paths.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_contacts.hpp"
#include "crumple/cache/pcache_developable.hpp"
#include "crumple/cache/pcache_look.hpp"
#include "crumple/cache/pcache_motion.hpp"
#include "crumple/cache/pcache_sound.hpp"
#include "crumple/cache/pcache_tear.hpp"
#include "crumple/core/error.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"

extern "C" int crumpleFuzz_scene(const std::uint8_t* data, std::size_t size);
extern "C" int crumpleFuzz_cache(const std::uint8_t* data, std::size_t size);
extern "C" int crumpleFuzz_cache_tools(const std::uint8_t* data, std::size_t size);
extern "C" int crumpleFuzz_gltf(const std::uint8_t* data, std::size_t size);
extern "C" int crumpleFuzz_fbx(const std::uint8_t* data, std::size_t size);
extern "C" int crumpleFuzz_collada(const std::uint8_t* data, std::size_t size);

namespace {

namespace fs = std::filesystem;
using FuzzTarget = int (*)(const std::uint8_t*, std::size_t);

struct Target {
  const char* name;
  FuzzTarget run;
};

void PrintTo(const Target& target, std::ostream* os) { *os << target.name; }

const Target kTargets[] = {{"scene", crumpleFuzz_scene},
                           {"cache", crumpleFuzz_cache},
                           {"cache_tools", crumpleFuzz_cache_tools},
                           {"gltf", crumpleFuzz_gltf},
                           {"fbx", crumpleFuzz_fbx},
                           {"collada", crumpleFuzz_collada}};

// The import probe's memory limit for this test (docs/FUZZING.md), so that an
// input that makes assimp allocate without end fails fast.
const bool kImportMemoryLimited = setenv("CRUMPLE_IMPORT_MEMORY_MB", "512", 0) == 0;

// Under a sanitizer the probe cannot limit the child's address space: the
// inputs that make assimp allocate tens of gigabytes (named *-oom-*) are left out.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
constexpr bool kSanitized = __has_feature(address_sanitizer);
#else
constexpr bool kSanitized = false;
#endif
bool runnable(const fs::path& input) {
  return !kSanitized || input.filename().string().find("-oom-") == std::string::npos;
}

// Every input file of a folder (not README.md), sorted; none when it is absent.
std::vector<fs::path> inputsIn(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return files;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file() && e.path().filename() != "README.md" && runnable(e.path())) {
      files.push_back(e.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::uint8_t> readBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string readText(const fs::path& path) {
  const std::vector<std::uint8_t> bytes = readBytes(path);
  return {bytes.begin(), bytes.end()};
}

class FuzzRegression : public ::testing::TestWithParam<Target> {};

TEST_P(FuzzRegression, EverySeedAndCrashInputReturnsNormally) {
  ASSERT_TRUE(kImportMemoryLimited);
  const Target& target = GetParam();
  const fs::path root(CRUMPLE_FUZZ_DIR);
  const std::vector<fs::path> seeds = inputsIn(root / "corpus" / target.name);
  ASSERT_FALSE(seeds.empty()) << "no seed corpus in corpus/" << target.name;
  std::vector<fs::path> inputs = seeds;
  const std::vector<fs::path> crashes = inputsIn(root / "regressions" / target.name);
  inputs.insert(inputs.end(), crashes.begin(), crashes.end());
  for (const fs::path& input : inputs) {
    SCOPED_TRACE(input.string());
    const std::vector<std::uint8_t> bytes = readBytes(input);
    EXPECT_EQ(target.run(bytes.data(), bytes.size()), 0);
  }
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzRegression, ::testing::ValuesIn(kTargets),
                         [](const ::testing::TestParamInfo<Target>& info) {
                           return std::string(info.param.name);
                         });

// The seeds are valid inputs: a corpus of rejected files would only fuzz the
// readers' first checks.
TEST(FuzzSeeds, SceneSeedsParse) {
  for (const fs::path& seed : inputsIn(fs::path(CRUMPLE_FUZZ_DIR) / "corpus" / "scene")) {
    SCOPED_TRACE(seed.string());
    const crumple::io::SceneSpec scene = crumple::io::parseScene(
        readText(seed), seed.filename().string(), CRUMPLE_FUZZ_SCENE_DIR, false);
    EXPECT_GE(scene.frameEnd, scene.frameStart);
  }
}

TEST(FuzzSeeds, CacheSeedsReadWithoutIssues) {
  std::vector<fs::path> seeds = inputsIn(fs::path(CRUMPLE_FUZZ_DIR) / "corpus" / "cache");
  for (const fs::path& seed : inputsIn(fs::path(CRUMPLE_FUZZ_DIR) / "corpus" / "cache_tools"))
    seeds.push_back(seed);
  for (const fs::path& seed : seeds) {
    SCOPED_TRACE(seed.string());
    const crumple::cache::CacheReader reader(seed.string());
    EXPECT_FALSE(reader.recovered());
    EXPECT_GT(reader.frameCount(), 0u);
    EXPECT_TRUE(reader.verifyAll().empty());
  }
}

TEST(FuzzSeeds, AnimationSeedsLoadWithAnAnimatedNode) {
  for (const char* format : {"gltf", "fbx", "collada"}) {
    for (const fs::path& seed : inputsIn(fs::path(CRUMPLE_FUZZ_DIR) / "corpus" / format)) {
      SCOPED_TRACE(seed.string());
      const crumple::io::AnimationScene scene = crumple::io::AnimationScene::load(seed.string());
      EXPECT_GT(scene.endTime(), scene.startTime());
    }
  }
}

// Files that crash assimp 5.2.5 itself (regressions/<format>/assimp-*): the
// import probe turns each into an InputError naming the file and assimp
// (docs/FUZZING.md), in this process too.
TEST(FuzzSeeds, AssimpCrashesBecomeInputErrors) {
  int seen = 0;
  for (const char* format : {"gltf", "fbx", "collada"}) {
    for (const fs::path& input : inputsIn(fs::path(CRUMPLE_FUZZ_DIR) / "regressions" / format)) {
      if (input.filename().string().rfind("assimp-", 0) != 0) continue;
      SCOPED_TRACE(input.string());
      ++seen;
      try {
        (void)crumple::io::AnimationScene::load(input.string());
        ADD_FAILURE() << "loaded";
      } catch (const crumple::InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(input.string()), std::string::npos) << message;
        EXPECT_NE(message.find("assimp"), std::string::npos) << message;
      }
    }
  }
  EXPECT_GT(seen, 0);
}

// A binary glTF whose JSON chunk claims 3.8 GB made assimp allocate that
// much (and take seconds) before failing; its lengths are checked first.
TEST(FuzzSeeds, BinaryGltfWithImpossibleLengthsIsRejectedBeforeAssimp) {
  const fs::path input =
      fs::path(CRUMPLE_FUZZ_DIR) / "regressions" / "gltf" / "glb-json-chunk-3.8GB.glb";
  try {
    (void)crumple::io::AnimationScene::load(input.string());
    ADD_FAILURE() << "loaded";
  } catch (const crumple::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("binary glTF chunk 0 gives a length of 3858958688"),
              std::string::npos)
        << e.what();
  }
}

// A tiny cache carrying every sub-block crumple writes (COLL, SNDS and SHTR
// in the header; CONT, TEAR, SEVT, SGEO, VELO, PRPM and PRPV in a frame)
// reads back equal through the
// decoders and passes through the cache target. corpus/cache/blocks.pcache is
// this file (CRUMPLE_FUZZ_SEED_OUT=path writes a copy there).
TEST(FuzzSeeds, CacheWithEverySubBlockReadsBack) {
  namespace cache = crumple::cache;
  using crumple::Vec2;
  using crumple::Vec3;
  const fs::path path =
      fs::temp_directory_path() / ("crumple-fuzz-blocks-" + std::to_string(getpid()) + ".pcache");
  cache::CacheHeader header;
  header.frameStart = 1;
  header.frameEnd = 2;
  header.sceneName = "blocks";
  header.sheetWidth = 0.1;
  header.sheetHeight = 0.1;
  header.handleNames = {"a"};
  const std::vector<cache::ColliderInfo> colliders = {{"table", "wood", 0.4}};
  const cache::SoundSetupRecord setup{0.01, 20.0, 0.5, 0.02, 0.01, 0.005, 0.1};
  const cache::Shutter shutter{-0.25, 0.25};
  header.extensions = {cache::encodeColliders(colliders), cache::encodeSoundSetup(setup),
                       cache::encodeShutter(shutter)};

  cache::FrameRecord frame;
  frame.frame = 1;
  frame.time = 1.0 / 24.0;
  frame.triangles = {{0, 1, 2}, {0, 2, 3}};
  frame.regionOfTriangle = {0, 1};
  frame.regionTypes = {0, 1};
  frame.rulings = {{0, 2}, {0, 3}};
  frame.pattern = {Vec2(0, 0), Vec2(0.1, 0), Vec2(0.1, 0.1), Vec2(0, 0.1)};
  frame.positions = {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.1, 0, -0.1), Vec3(0, 0, -0.1)};
  frame.handleVertices = {0};
  frame.handleTargets = {Vec3(0, 0, 0)};
  const std::vector<cache::ContactRecord> contacts = {{2, 0, 0.05f, 0.2f}, {3, -1, 0.0f, 0.1f}};
  crumple::mesh::TearAtlas atlas;
  atlas.texelSize = 0.5;
  atlas.width = 2;
  atlas.height = 2;
  atlas.mask = {255, 0, 255, 255};
  crumple::mesh::TearPatch patch;
  patch.triangle = 1;
  patch.tear = 0;
  patch.polygon = {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)};
  patch.rect = {0, 0, 2, 2, Vec2(-0.5, -0.5)};
  atlas.patches = {patch};
  crumple::sound::SoundEvent event;
  event.kind = crumple::sound::EventKind::Crumpling;
  event.amplitude = 1e-4;
  event.position = Vec3(0.05, 0, -0.05);
  event.resonators = {{0.05, 0.02, 1e-3, Vec3(0.05, 0, -0.05), Vec3::UnitY(), 0.02}};
  // Velocities rounded to float as the block keeps them.
  const std::vector<Vec3> velocities = {Vec3(0.5, 0, 0), Vec3(0.5, 0.25, 0), Vec3(0, 0, -1),
                                        Vec3::Zero()};
  crumple::Mat4 propVelocity = crumple::Mat4::Zero();
  propVelocity(0, 3) = 1.0;
  frame.extensions = {cache::encodeContacts(contacts),
                      cache::encodeTearAtlas(atlas),
                      cache::encodeSoundEvents({event}),
                      cache::encodeVelocities(velocities),
                      cache::encodePropMotions({crumple::Mat4::Identity()}),
                      cache::encodePropVelocities({propVelocity}),
                      cache::encodeRegionRulings({{1, 0, 2}})};
  {
    cache::CacheWriter writer(path.string(), header);
    writer.append(frame);
    frame.frame = 2;
    frame.extensions = {cache::encodeVelocities(std::vector<Vec3>(4, Vec3::Zero()))};
    writer.append(frame);
    writer.close();
  }

  {
    const cache::CacheReader reader(path.string());
    ASSERT_EQ(reader.frameCount(), 2u);
    EXPECT_EQ(cache::decodeColliders(reader.header().extensions), colliders);
    EXPECT_EQ(cache::decodeSoundSetup(reader.header().extensions), setup);
    const cache::FrameRecord first = reader.readFrame(0);
    EXPECT_EQ(cache::decodeContacts(first.extensions), contacts);
    EXPECT_EQ(cache::decodeTearAtlas(first.extensions), atlas);
    ASSERT_TRUE(cache::decodeSoundEvents(first.extensions).has_value());
    EXPECT_EQ(cache::decodeSoundEvents(first.extensions)->size(), 1u);
    const auto developable = cache::decodeDevelopable(first);
    ASSERT_TRUE(developable.has_value());
    ASSERT_EQ(developable->regions.size(), 1u);
    EXPECT_EQ(developable->regions[0].apex, 0);
    EXPECT_EQ(cache::decodeShutter(reader.header().extensions), shutter);
    EXPECT_EQ(cache::decodeVelocities(first.extensions), velocities);
    EXPECT_EQ(cache::decodePropVelocities(first.extensions),
              std::vector<crumple::Mat4>{propVelocity});
    EXPECT_TRUE(reader.verifyAll().empty());
  }
  const std::vector<std::uint8_t> bytes = readBytes(path);
  EXPECT_EQ(crumpleFuzz_cache(bytes.data(), bytes.size()), 0);
  if (const char* out = std::getenv("CRUMPLE_FUZZ_SEED_OUT"); out && *out) {
    fs::copy_file(path, out, fs::copy_options::overwrite_existing);
  }
  fs::remove(path);
}

}  // namespace
