// The SGEO sub-block (cache/pcache_developable.hpp, docs/PCACHE.md): the
// documented layout, the regions rebuilt from the frame's ruling list, and
// malformed blocks.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "crumple/cache/pcache_developable.hpp"
#include "crumple/core/error.hpp"

namespace crumple::cache {
namespace {

using Bytes = std::vector<std::uint8_t>;

void putU32(Bytes& b, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

// A frame of 8 vertices, regions 0 flat and 1, 2 curved, five rulings.
FrameRecord frameWith(const std::vector<RegionRulings>& regions) {
  FrameRecord f;
  f.frame = 7;
  f.positions.assign(8, Vec3::Zero());
  f.pattern.assign(8, Vec2::Zero());
  f.regionTypes = {0, 1, 1};
  f.rulings = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {6, 5}};
  f.extensions.push_back(encodeRegionRulings(regions));
  return f;
}

TEST(PcacheDevelopable, EncodingFollowsTheDocumentedLayout) {
  const ExtensionBlock block = encodeRegionRulings({{1, -1, 3}, {2, 6, 2}});
  EXPECT_EQ(block.tag, kDevelopableTag);
  Bytes expected;
  putU32(expected, 2);
  for (std::uint32_t v : {1u, 0xffffffffu, 3u, 2u, 6u, 2u}) putU32(expected, v);
  EXPECT_EQ(block.data, expected);
}

TEST(PcacheDevelopable, RegionsTakeTheirRulingsInOrder) {
  const auto s = decodeDevelopable(frameWith({{1, -1, 3}, {2, 6, 2}}));
  ASSERT_TRUE(s.has_value());
  ASSERT_EQ(s->regions.size(), 2u);
  EXPECT_EQ(s->regions[0].region, 1);
  EXPECT_EQ(s->regions[0].apex, -1);
  EXPECT_EQ(s->regions[0].rulings, (std::vector<std::array<int, 2>>{{0, 1}, {2, 3}, {4, 5}}));
  EXPECT_EQ(s->regions[1].apex, 6);
  EXPECT_EQ(s->regions[1].rulings, (std::vector<std::array<int, 2>>{{6, 7}, {6, 5}}));
  // A flat region's rulings, or a curved region with one ruling, are no strip.
  const auto t = decodeDevelopable(frameWith({{0, -1, 4}, {2, -1, 1}}));
  ASSERT_TRUE(t.has_value());
  EXPECT_TRUE(t->regions.empty());
  FrameRecord none;
  EXPECT_FALSE(decodeDevelopable(none).has_value()) << "no block: the elastic model's frame";
}

TEST(PcacheDevelopable, MalformedBlocksThrow) {
  EXPECT_THROW(decodeDevelopable(frameWith({{3, -1, 5}})), CorruptDataError) << "region id";
  EXPECT_THROW(decodeDevelopable(frameWith({{1, 8, 5}})), CorruptDataError) << "apex";
  EXPECT_THROW(decodeDevelopable(frameWith({{1, -1, 4}})), CorruptDataError) << "one left over";
  EXPECT_THROW(decodeDevelopable(frameWith({{1, -1, 4}, {2, -1, 2}})), CorruptDataError)
      << "more than the list";
  FrameRecord twice = frameWith({{1, -1, 5}});
  twice.extensions.push_back(twice.extensions.front());
  EXPECT_THROW(decodeDevelopable(twice), CorruptDataError) << "two SGEO blocks";
  FrameRecord truncated = frameWith({{1, -1, 5}});
  truncated.extensions.front().data.pop_back();
  EXPECT_THROW(decodeDevelopable(truncated), CorruptDataError);
  FrameRecord trailing = frameWith({{1, -1, 5}});
  trailing.extensions.front().data.push_back(0);
  EXPECT_THROW(decodeDevelopable(trailing), CorruptDataError);
  FrameRecord huge = frameWith({});
  huge.extensions.front().data = {0xff, 0xff, 0xff, 0x7f};
  EXPECT_THROW(decodeDevelopable(huge), CorruptDataError) << "a count the block cannot hold";
  EXPECT_THROW(encodeRegionRulings({{-1, -1, 1}}), std::invalid_argument);
}

}  // namespace
}  // namespace crumple::cache
