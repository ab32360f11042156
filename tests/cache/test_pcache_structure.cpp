// The STRC sub-block (cache/pcache_structure.hpp, docs/PCACHE.md): the
// documented layout, a newer writer's extra fields and an older writer's
// fewer, and malformed blocks.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "crumple/cache/pcache_structure.hpp"
#include "crumple/core/error.hpp"

namespace crumple::cache {
namespace {

using Bytes = std::vector<std::uint8_t>;

void putU32(Bytes& b, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

StructureChanges someChanges() {
  StructureChanges c;
  c.singularFromFlat = 1;
  c.singularFromRuling = 2;
  c.curvedFromCompression = 3;
  c.curvedFromFolding = 4;
  c.creases = 5;
  c.flatSplits = 6;
  c.curvedFlattened = 7;
  c.undoneByStretch = 0xffffffffu;
  return c;
}

TEST(PcacheStructure, EncodingFollowsTheDocumentedLayout) {
  const ExtensionBlock block = encodeStructureChanges(someChanges());
  EXPECT_EQ(block.tag, kStructureTag);
  Bytes expected;
  putU32(expected, 8);
  for (std::uint32_t v : {1u, 2u, 3u, 4u, 5u, 6u, 7u, 0xffffffffu}) putU32(expected, v);
  EXPECT_EQ(block.data, expected);
  const auto decoded = decodeStructureChanges({{{'X', 'Y', 'Z', 'W'}, {1, 2}}, block});
  ASSERT_TRUE(decoded.has_value());
  EXPECT_EQ(*decoded, someChanges());
  EXPECT_FALSE(decodeStructureChanges({}).has_value()) << "no block: an elastic frame";
}

TEST(PcacheStructure, ANewerWritersFieldsAreSkippedAndAnOlderWritersMissingOnesAreZero) {
  Bytes newer;
  putU32(newer, 10);
  for (std::uint32_t v = 1; v <= 10; ++v) putU32(newer, v);
  const auto fromNewer = decodeStructureChanges({{kStructureTag, newer}});
  ASSERT_TRUE(fromNewer.has_value());
  EXPECT_EQ(fromNewer->curvedFlattened, 7u);
  EXPECT_EQ(fromNewer->undoneByStretch, 8u);
  Bytes older;
  putU32(older, 2);
  putU32(older, 4);
  putU32(older, 5);
  const auto fromOlder = decodeStructureChanges({{kStructureTag, older}});
  ASSERT_TRUE(fromOlder.has_value());
  StructureChanges expected;
  expected.singularFromFlat = 4;
  expected.singularFromRuling = 5;
  EXPECT_EQ(*fromOlder, expected);
}

TEST(PcacheStructure, MalformedBlocksThrow) {
  const ExtensionBlock good = encodeStructureChanges(someChanges());
  ExtensionBlock truncated = good;
  truncated.data.pop_back();
  EXPECT_THROW(decodeStructureChanges({truncated}), CorruptDataError);
  ExtensionBlock trailing = good;
  trailing.data.push_back(0);
  EXPECT_THROW(decodeStructureChanges({trailing}), CorruptDataError);
  Bytes huge;
  putU32(huge, 0x40000000u);
  EXPECT_THROW(decodeStructureChanges({{kStructureTag, huge}}), CorruptDataError);
  EXPECT_THROW(decodeStructureChanges({good, good}), CorruptDataError) << "two STRC blocks";
  EXPECT_THROW(decodeStructureChanges({{kStructureTag, {}}}), CorruptDataError) << "empty";
}

}  // namespace
}  // namespace crumple::cache
