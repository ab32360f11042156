// The TEAR sub-block (cache/pcache_tear.hpp, docs/PCACHE.md): a frame's
// tear atlas round-trips exactly, and damaged blocks are rejected.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_tear.hpp"
#include "crumple/core/error.hpp"
#include "temp_dir.hpp"

namespace crumple::cache {
namespace {

using Bytes = std::vector<std::uint8_t>;

// Two patches in a 5 x 3 atlas: a left lip triangle with a support quad on
// its edge 0, and a right one masked only.
mesh::TearAtlas someAtlas() {
  mesh::TearAtlas a;
  a.texelSize = 0.5;
  a.width = 5;
  a.height = 3;
  a.mask = {255, 0, 255, 255, 0, 0, 0, 255, 0, 255, 255, 255, 0, 0, 255};
  mesh::TearPatch p;
  p.triangle = 2;
  p.tear = 0;
  p.side = mesh::LipSide::Left;
  p.lipEdges = 1;
  p.polygon = {Vec2(0, 0), Vec2(0.1, -0.25), Vec2(1.0, -0.25), Vec2(1, 0), Vec2(0, 1.0 / 3.0)};
  p.rect = {0, 0, 3, 3, Vec2(-0.5, -0.5)};
  a.patches.push_back(p);
  p.triangle = 7;
  p.tear = 1;
  p.side = mesh::LipSide::Right;
  p.lipEdges = 0;
  p.polygon = {Vec2(1, 0), Vec2(-0.0, 1e-300), Vec2(0.5, 0.5)};
  p.rect = {3, 0, 2, 2, Vec2(0.5, -0.5)};
  a.patches.push_back(p);
  return a;
}

void setU32(Bytes& b, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b.at(at + k) = static_cast<std::uint8_t>(v >> (8 * k));
}
void setF64(Bytes& b, std::size_t at, double v) {
  const auto u = std::bit_cast<std::uint64_t>(v);
  for (int k = 0; k < 8; ++k) b.at(at + k) = static_cast<std::uint8_t>(u >> (8 * k));
}

class PcacheTearTest : public test::TempDirTest {};

// The bytes are the ones docs/PCACHE.md specifies, field by field.
TEST(PcacheTear, EncodingFollowsTheDocumentedLayout) {
  mesh::TearAtlas a;
  a.texelSize = 1.0;
  a.width = 3;
  a.height = 1;
  a.mask = {255, 0, 255};
  mesh::TearPatch p;
  p.triangle = 1;
  p.tear = 2;
  p.side = mesh::LipSide::Right;
  p.polygon = {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)};
  p.rect = {0, 0, 3, 1, Vec2(0, 0)};
  a.patches = {p};
  const ExtensionBlock b = encodeTearAtlas(a);
  EXPECT_EQ(b.tag, (std::array<char, 4>{'T', 'E', 'A', 'R'}));
  const Bytes zero8(8, 0), one = {0, 0, 0, 0, 0, 0, 0xF0, 0x3F};
  Bytes expected = one;                           // f64 texel size 1.0
  expected.insert(expected.end(), {3, 0, 0, 0,    // u32 width
                                   1, 0, 0, 0,    // u32 height
                                   1, 0, 0, 0,    // u32 patch count
                                   1, 0, 0, 0,    // i32 triangle
                                   2, 0, 0, 0,    // i32 tear
                                   1, 0,          // u8 side (right), u8 lip edges
                                   3, 0, 0, 0});  // u32 polygon points
  for (const Bytes* f : {&zero8, &zero8, &one, &zero8, &zero8, &one})
    expected.insert(expected.end(), f->begin(), f->end());
  expected.insert(expected.end(), {0, 0, 0, 0, 0, 0, 0, 0, 3, 0, 0, 0, 1, 0, 0, 0});  // rect
  expected.insert(expected.end(), 16, 0);  // origin (0, 0)
  expected.push_back(0x05);                // mask bits 1, 0, 1
  EXPECT_EQ(b.data, expected);
  // An atlas without patches.
  EXPECT_EQ(encodeTearAtlas(mesh::TearAtlas{}).data.size(), 8u + 4u + 4u + 4u);
}

TEST_F(PcacheTearTest, RoundTripThroughACacheFile) {
  const std::string path = file("tear.pcache");
  CacheHeader h;
  h.sceneName = "tear";
  FrameRecord f1, f2;
  for (FrameRecord* f : {&f1, &f2}) {
    f->pattern = {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)};
    f->positions = {Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY()};
    f->triangles = {{0, 1, 2}};
    f->regionOfTriangle = {0};
    f->regionTypes = {0};
  }
  f1.frame = 1;
  f2.frame = 2;
  f1.extensions = {encodeTearAtlas(someAtlas())};
  {
    CacheWriter w(path, h);
    w.append(f1);
    w.append(f2);
    w.close();
  }
  const CacheReader r(path);
  const auto a = decodeTearAtlas(r.readFrame(0).extensions);
  ASSERT_TRUE(a.has_value());
  EXPECT_EQ(*a, someAtlas());
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a->patches[1].polygon[1].x()),
            std::bit_cast<std::uint64_t>(-0.0))
      << "bit for bit";
  EXPECT_FALSE(decodeTearAtlas(r.readFrame(1).extensions).has_value()) << "a frame without tears";
  EXPECT_FALSE(decodeTearAtlas({{{'T', 'E', 'A', 'r'}, {1}}}).has_value());
  const auto empty = decodeTearAtlas({encodeTearAtlas(mesh::TearAtlas{})});
  ASSERT_TRUE(empty.has_value());
  EXPECT_TRUE(empty->empty());
}

// decode(bytes) must throw CorruptDataError naming the block and `part`.
void expectCorrupt(const Bytes& bytes, const std::string& part, const std::string& label) {
  SCOPED_TRACE(label);
  try {
    (void)decodeTearAtlas({{kTearAtlasTag, bytes}});
    ADD_FAILURE() << "no CorruptDataError";
  } catch (const CorruptDataError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("TEAR"), std::string::npos) << what;
    EXPECT_NE(what.find(part), std::string::npos) << what;
  }
}

TEST(PcacheTear, MalformedBlocksThrow) {
  const Bytes good = encodeTearAtlas(someAtlas()).data;
  // header 20, patch 0 at 20 (polygon of 5: 126 bytes), patch 1 at 146 (94), mask at 240.
  ASSERT_EQ(good.size(), 242u);
  ASSERT_TRUE(decodeTearAtlas({{kTearAtlasTag, good}}).has_value());
  const auto corrupt = [&](const std::string& label, const std::string& part,
                           const std::function<void(Bytes&)>& damage) {
    Bytes b = good;
    damage(b);
    expectCorrupt(b, part, label);
  };
  for (std::size_t n = 0; n < good.size(); ++n)
    corrupt("cut at " + std::to_string(n), "", [&](Bytes& b) { b.resize(n); });
  corrupt("trailing byte", "bytes for 5 x 3 texels", [](Bytes& b) { b.push_back(0); });
  corrupt("NaN texel size", "texel size",
          [](Bytes& b) { setF64(b, 0, std::numeric_limits<double>::quiet_NaN()); });
  corrupt("zero texel size", "texel size", [](Bytes& b) { setF64(b, 0, 0.0); });
  corrupt("huge atlas", "texels", [](Bytes& b) { setU32(b, 8, 0x7fffffffu); });
  corrupt("atlas width beyond int", "beyond 2^31", [](Bytes& b) { setU32(b, 8, 0x80000000u); });
  corrupt("absurd patch count", "runs past", [](Bytes& b) { setU32(b, 16, 0xFFFFFFFFu); });
  corrupt("negative triangle", "patch 0: triangle -1",
          [](Bytes& b) { setU32(b, 20, 0xFFFFFFFFu); });
  corrupt("negative tear", "patch 0: tear -3", [](Bytes& b) { setU32(b, 24, 0xFFFFFFFDu); });
  corrupt("side 2", "patch 1: side 2", [](Bytes& b) { b[154] = 2; });
  corrupt("lip edges 8", "patch 1: lip edges 8", [](Bytes& b) { b[155] = 8; });
  corrupt("lip edges without points", "3 polygon points for 1 lip edges",
          [](Bytes& b) { b[155] = 1; });
  corrupt("absurd polygon count", "patch 1: polygon point count",
          [](Bytes& b) { setU32(b, 156, 0x10000000u); });
  corrupt("NaN polygon point", "patch 0: polygon point is not finite",
          [](Bytes& b) { setF64(b, 34, std::numeric_limits<double>::quiet_NaN()); });
  corrupt("rect outside the atlas", "patch 1: rect 3 x 2", [](Bytes& b) { setU32(b, 216, 3); });
  corrupt("empty rect", "patch 1: rect 0 x 2", [](Bytes& b) { setU32(b, 216, 0); });
  corrupt("rect x beyond int", "rect x", [](Bytes& b) { setU32(b, 208, 0xFFFFFFFFu); });
  corrupt("infinite origin", "patch 1: rect origin",
          [](Bytes& b) { setF64(b, 224, std::numeric_limits<double>::infinity()); });
  corrupt("unsorted triangles", "patch 1: triangle 2 after triangle 2",
          [](Bytes& b) { setU32(b, 146, 2); });
  corrupt("a bit beyond the last texel", "bits beyond the last texel",
          [](Bytes& b) { b[241] = static_cast<std::uint8_t>(b[241] | 0x80); });
  // Two blocks.
  try {
    (void)decodeTearAtlas({{kTearAtlasTag, good}, {kTearAtlasTag, good}});
    ADD_FAILURE() << "no CorruptDataError";
  } catch (const CorruptDataError& e) {
    EXPECT_NE(std::string(e.what()).find("more than once"), std::string::npos) << e.what();
  }
}

TEST(PcacheTear, EncoderRejectsWhatTheDecoderWould) {
  mesh::TearAtlas a = someAtlas();
  a.mask[3] = 7;
  EXPECT_THROW(encodeTearAtlas(a), std::invalid_argument);
  a = someAtlas();
  a.mask.pop_back();
  EXPECT_THROW(encodeTearAtlas(a), std::invalid_argument);
  a = someAtlas();
  std::swap(a.patches[0], a.patches[1]);
  EXPECT_THROW(encodeTearAtlas(a), std::invalid_argument);
  a = someAtlas();
  a.patches[0].rect.x = 3;
  EXPECT_THROW(encodeTearAtlas(a), std::invalid_argument);
  a = someAtlas();
  a.patches[1].polygon.pop_back();
  EXPECT_THROW(encodeTearAtlas(a), std::invalid_argument);
}

}  // namespace
}  // namespace crumple::cache
