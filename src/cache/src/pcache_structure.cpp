// The STRC extension sub-block. Byte layout: docs/PCACHE.md ("Sub-blocks
// written by crumple").
#include "crumple/cache/pcache_structure.hpp"

#include <utility>

#include "sub_block.hpp"

namespace crumple::cache {
ExtensionBlock encodeStructureChanges(const StructureChanges& changes) {
  Bytes bytes;
  ByteWriter w(bytes);
  w.u32(kStructureFields);
  for (const StructureField& field : kStructureFieldList) w.u32(changes.*field.count);
  return {kStructureTag, std::move(bytes)};
}

std::optional<StructureChanges> decodeStructureChanges(
    const std::vector<ExtensionBlock>& frameBlocks) {
  const ExtensionBlock* block = detail::findOneBlock(frameBlocks, kStructureTag);
  if (!block) return std::nullopt;
  detail::SubBlockReader r(block->data, "STRC");
  const std::size_t n = r.count32(4, "field count");
  StructureChanges changes;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t value = r.u32("count");
    if (i < kStructureFieldList.size()) changes.*kStructureFieldList[i].count = value;
  }
  r.expectEnd();
  return changes;
}

}  // namespace crumple::cache
