// The STRC extension sub-block. Byte layout: docs/PCACHE.md ("Sub-blocks
// written by crumple").
#include "crumple/exporters/pcache_structure.hpp"

#include <utility>

#include "block_reader.hpp"
#include "byte_encoder.hpp"

namespace crumple::cache {
namespace {

// The fields in block order.
std::array<std::uint32_t StructureChanges::*, kStructureFields> fields() {
  return {&StructureChanges::singularFromFlat,
          &StructureChanges::singularFromRuling,
          &StructureChanges::curvedFromCompression,
          &StructureChanges::curvedFromFolding,
          &StructureChanges::creases,
          &StructureChanges::flatSplits,
          &StructureChanges::curvedFlattened,
          &StructureChanges::undoneByStretch};
}

}  // namespace

ExtensionBlock encodeStructureChanges(const StructureChanges& changes) {
  detail::Bytes bytes;
  detail::Encoder w(bytes);
  w.u32(kStructureFields);
  for (auto field : fields()) w.u32(changes.*field);
  return {kStructureTag, std::move(bytes)};
}

std::optional<StructureChanges> decodeStructureChanges(
    const std::vector<ExtensionBlock>& frameBlocks) {
  const ExtensionBlock* block = detail::findOneBlock(frameBlocks, kStructureTag);
  if (!block) return std::nullopt;
  detail::SubBlockReader r(block->data, "STRC");
  const std::size_t n = r.count(4, "field count");
  StructureChanges changes;
  const auto known = fields();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t value = r.u32("count");
    if (i < known.size()) changes.*known[i] = value;
  }
  r.expectEnd();
  return changes;
}

}  // namespace crumple::cache
