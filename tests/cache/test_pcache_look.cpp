// The look sub-blocks PTEX, PROP, PRPM (cache/pcache_look.hpp,
// docs/PCACHE.md): the documented layout, and damaged blocks refused with
// the block and the prop named.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "crumple/cache/pcache_look.hpp"
#include "crumple/core/error.hpp"

namespace crumple::cache {
namespace {

using Bytes = std::vector<std::uint8_t>;

void putU32(Bytes& b, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

void putF64(Bytes& b, double v) {
  const auto u = std::bit_cast<std::uint64_t>(v);
  for (int k = 0; k < 8; ++k) b.push_back(static_cast<std::uint8_t>(u >> (8 * k)));
}

PropMeshRecord tetrahedron() {
  return {{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1.5)},
          {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}}};
}

std::string messageOf(const std::vector<ExtensionBlock>& blocks) {
  try {
    (void)decodePropMeshes(blocks);
  } catch (const CorruptDataError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(PcacheLook, PropMeshesFollowTheDocumentedLayout) {
  const PropMeshRecord m = tetrahedron();
  const ExtensionBlock block = encodePropMeshes({m});
  EXPECT_EQ(block.tag, kPropMeshesTag);
  Bytes expected;
  putU32(expected, 1);
  putU32(expected, 4);
  for (const Vec3& v : m.vertices)
    for (int k = 0; k < 3; ++k) putF64(expected, v[k]);
  putU32(expected, 4);
  for (const auto& t : m.triangles)
    for (int i : t) putU32(expected, static_cast<std::uint32_t>(i));
  EXPECT_EQ(block.data, expected);
  const auto decoded = decodePropMeshes({encodePaperTexture({1, 2, 3}), block});
  ASSERT_TRUE(decoded.has_value());
  ASSERT_EQ(decoded->size(), 1u);
  EXPECT_EQ((*decoded)[0], m);
  EXPECT_FALSE(decodePropMeshes({}).has_value());
}

TEST(PcacheLook, PropMotionsAreColumnMajorAndRoundTrip) {
  Mat4 a = Mat4::Identity();
  a(0, 3) = 0.25;  // a translation: column 3
  a(1, 0) = -2.0;
  const ExtensionBlock block = encodePropMotions({a, Mat4::Identity()});
  EXPECT_EQ(block.tag, kPropMotionsTag);
  ASSERT_EQ(block.data.size(), 4u + 2u * 128u);
  Bytes column0;
  for (double v : {1.0, -2.0, 0.0, 0.0}) putF64(column0, v);
  EXPECT_TRUE(std::equal(column0.begin(), column0.end(), block.data.begin() + 4));
  const auto decoded = decodePropMotions({block});
  ASSERT_TRUE(decoded.has_value());
  ASSERT_EQ(decoded->size(), 2u);
  EXPECT_EQ((*decoded)[0], a);
  EXPECT_FALSE(decodePropMotions({}).has_value());
}

TEST(PcacheLook, ThePaperTextureIsKeptVerbatim) {
  const Bytes png{0x89, 'P', 'N', 'G', 0, 0xff};
  const std::vector<ExtensionBlock> blocks{encodePropMeshes({}), encodePaperTexture(png)};
  const Bytes* found = findPaperTexture(blocks);
  ASSERT_NE(found, nullptr);
  EXPECT_EQ(*found, png);
  EXPECT_EQ(findPaperTexture({}), nullptr);
  EXPECT_THROW((void)findPaperTexture({encodePaperTexture(png), encodePaperTexture(png)}),
               CorruptDataError);
}

TEST(PcacheLook, DamagedPropBlocksAreRefused) {
  const ExtensionBlock good = encodePropMeshes({tetrahedron(), tetrahedron()});
  ExtensionBlock cut = good;
  cut.data.resize(cut.data.size() - 3);
  EXPECT_EQ(messageOf({cut}),
            "pcache PROP sub-block: prop 1: triangle count 4 runs past the end (45 bytes left)");
  ExtensionBlock index = good;
  index.data[4 + 4 + 4 * 24 + 4] = 9;  // the first triangle's first vertex of prop 0
  EXPECT_EQ(messageOf({index}), "pcache PROP sub-block: prop 0: vertex index 9 out of range");
  ExtensionBlock nan = good;
  for (int k = 0; k < 8; ++k) nan.data[8 + static_cast<std::size_t>(k)] = 0xff;
  EXPECT_EQ(messageOf({nan}), "pcache PROP sub-block: prop 0: a vertex is not finite");
  ExtensionBlock trailing = good;
  trailing.data.push_back(0);
  EXPECT_EQ(messageOf({trailing}), "pcache PROP sub-block: 1 trailing bytes");
  ExtensionBlock huge = good;
  huge.data[0] = huge.data[1] = huge.data[2] = huge.data[3] = 0xff;
  EXPECT_NE(messageOf({huge}).find("runs past the end"), std::string::npos);
  EXPECT_NE(messageOf({good, good}).find("present more than once"), std::string::npos);

  Mat4 bad = Mat4::Identity();
  bad(2, 2) = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)decodePropMotions({encodePropMotions({Mat4::Identity(), bad})}),
               CorruptDataError);
}

}  // namespace
}  // namespace crumple::cache
