#pragma once
// Which of a frame's rulings belong to which region of the crumpling model's
// S_G, as a .pcache frame extension sub-block, SGEO (docs/PCACHE.md
// "Sub-blocks written by crumple"): what the render-time refinement of the
// curved regions needs beyond the frame's mesh and ruling list
// (mesh/developable.hpp). Written for the crumpling model's frames; a frame
// without it is drawn as its mesh.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/mesh/developable.hpp"

namespace crumple::cache {

inline constexpr std::array<char, 4> kDevelopableTag{'S', 'G', 'E', 'O'};  // frame block

// One region's share of FrameRecord::rulings, in the list's order.
struct RegionRulings {
  std::int32_t region = -1;  // the frame's region id
  std::int32_t apex = -1;    // the singular vertex its rulings pass through, or -1
  std::uint32_t count = 0;   // how many consecutive rulings of the list are its
  bool operator==(const RegionRulings&) const = default;
};

// The sub-block: u32 n, then n x (i32 region, i32 apex, u32 ruling count).
ExtensionBlock encodeRegionRulings(const std::vector<RegionRulings>& regions);

// The frame's curved regions with their rulings (the SGEO block applied to
// FrameRecord::rulings; regions that are not curved, or with fewer than two
// rulings, left out); nullopt when the frame has no SGEO block. Throws
// crumple::CorruptDataError naming the block for malformed data: truncated,
// trailing bytes, a count the block cannot hold, a region id or apex out of
// range for the frame, counts that do not add up to the frame's rulings, or
// a second SGEO block.
std::optional<mesh::DevelopableStructure> decodeDevelopable(const FrameRecord& frame);

}  // namespace crumple::cache
