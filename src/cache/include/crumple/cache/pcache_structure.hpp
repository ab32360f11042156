#pragma once
// How the crumpling model's structure changed in a frame, as a .pcache
// frame extension sub-block, STRC: how many singular vertices, curved
// regions and creases its animation steps made, and for what cause
// (docs/CRUMPLING.md "Structure changes per frame"). The pipeline writes it
// for a frame of the crumpling model; `crumple inspect` reads it. Byte
// layout in docs/PCACHE.md ("Sub-blocks written by crumple"); little-endian
// like the rest of the cache.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "crumple/cache/pcache.hpp"

namespace crumple::cache {

inline constexpr std::array<char, 4> kStructureTag{'S', 'T', 'R', 'C'};  // frame block

// Counts over the frame's animation steps, in the block's field order.
struct StructureChanges {
  // Singular vertices where the strip of a compressed flat region meets a
  // constrained border (paper Sec. 5.2).
  std::uint32_t singularFromFlat = 0;
  // Singular vertices on a compressed ruling inside a curved region (beyond
  // the paper: its Sec. 7.4 limitation 1, pressure inside a curved area).
  std::uint32_t singularFromRuling = 0;
  // Curved regions made of compressed flat regions (paper Sec. 5.1, 5.2).
  std::uint32_t curvedFromCompression = 0;
  // Flat regions bent along their most folded edge.
  std::uint32_t curvedFromFolding = 0;
  // Flat regions cut along the crease between two singular vertices (paper
  // Appendix B, Fig. 24 (c)).
  std::uint32_t creases = 0;
  // Flat regions split where they stopped being planar (paper Sec. 5.1).
  std::uint32_t flatSplits = 0;
  // Curved regions flattened back (paper Sec. 6.1).
  std::uint32_t curvedFlattened = 0;
  // Geometric steps and remeshings undone because they left the sheet over
  // the strain bound: what stretch does to the structure today.
  std::uint32_t undoneByStretch = 0;
  bool operator==(const StructureChanges&) const = default;
};

// The number of fields this version writes and reads.
inline constexpr std::uint32_t kStructureFields = 8;

// The fields in the block's order, each with its name in `crumple inspect
// --json` (docs/CRUMPLING.md "Structure changes per frame").
struct StructureField {
  const char* name;
  std::uint32_t StructureChanges::*count;
};
inline constexpr std::array<StructureField, kStructureFields> kStructureFieldList{{
    {"singular_from_flat", &StructureChanges::singularFromFlat},
    {"singular_from_ruling", &StructureChanges::singularFromRuling},
    {"curved_from_compression", &StructureChanges::curvedFromCompression},
    {"curved_from_folding", &StructureChanges::curvedFromFolding},
    {"creases", &StructureChanges::creases},
    {"flat_splits", &StructureChanges::flatSplits},
    {"curved_flattened", &StructureChanges::curvedFlattened},
    {"undone_by_stretch", &StructureChanges::undoneByStretch},
}};

// The sub-block: u32 field count, then that many u32 counts.
ExtensionBlock encodeStructureChanges(const StructureChanges& changes);

// Finds the STRC block in a frame's extension list and decodes it; nullopt
// when there is none (an older cache, or a frame of the elastic model).
// Fields beyond kStructureFields (a newer writer) are skipped; a block with
// fewer leaves the missing ones 0. Throws crumple::CorruptDataError naming
// the block for malformed data: truncated, trailing bytes, a field count the
// block cannot hold, or a second STRC block.
std::optional<StructureChanges> decodeStructureChanges(
    const std::vector<ExtensionBlock>& frameBlocks);

}  // namespace crumple::cache
