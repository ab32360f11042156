#pragma once
// A frame's baked tear textures (thesis 3.3.4) as a .pcache frame
// extension sub-block, TEAR: the patches drawn instead of the triangles that
// border a tear, and their masks packed into one atlas (mesh::TearAtlas,
// made by tear::bakeTearAtlas). The pipeline writes it; the renderers read
// it through pipeline::FrameViewBuilder. Byte layout in docs/PCACHE.md
// ("Sub-blocks written by crumple"); little-endian like the rest of the
// cache, the mask one bit per texel.
#include <array>
#include <optional>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/mesh/tear_patches.hpp"

namespace crumple::cache {

inline constexpr std::array<char, 4> kTearAtlasTag{'T', 'E', 'A', 'R'};  // frame block

// The sub-block. Throws std::invalid_argument for an atlas that
// mesh::validate(atlas) rejects (naming the problem) and std::length_error
// for more than 2^32 - 1 patches or polygon points.
ExtensionBlock encodeTearAtlas(const mesh::TearAtlas& atlas);

// Finds the TEAR block in a frame's extension list and decodes it; nullopt
// when there is none (an older cache, or a frame without tears). Throws
// crumple::CorruptDataError naming the block and the patch for malformed
// data: truncated, trailing bytes, a count larger than the block can hold, a
// second TEAR block, mask bits beyond the atlas that are not 0, or anything
// mesh::validate(atlas) rejects. Triangle indices are not checked against
// the frame's mesh (the decoder does not see it; validate(atlas, mesh) does).
std::optional<mesh::TearAtlas> decodeTearAtlas(const std::vector<ExtensionBlock>& frameBlocks);

}  // namespace crumple::cache
