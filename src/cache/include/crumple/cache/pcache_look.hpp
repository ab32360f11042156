#pragma once
// The look a cache carries so that rendering needs nothing but the cache
// (docs/PCACHE.md "Extension sub-blocks written by crumple"): the paper's
// texture (header "PTEX"), the rest meshes of the scene's mesh props (header
// "PROP") and each frame's prop motions (frame "PRPM"). Little-endian, on
// the core byte codec. The pipeline decides what goes in (which props, from
// which animation file); this is only the bytes.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/types.hpp"

namespace crumple::cache {

inline constexpr std::array<char, 4> kPaperTextureTag{'P', 'T', 'E', 'X'};
inline constexpr std::array<char, 4> kPropMeshesTag{'P', 'R', 'O', 'P'};
inline constexpr std::array<char, 4> kPropMotionsTag{'P', 'R', 'P', 'M'};

// A mesh prop at rest: world-space vertices at t = 0 and triangles.
struct PropMeshRecord {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
  bool operator==(const PropMeshRecord&) const = default;
};

// "PTEX": the texture file's bytes (a PNG), verbatim.
ExtensionBlock encodePaperTexture(std::vector<std::uint8_t> png);
// The bytes of the header's PTEX block, or null without one.
// CorruptDataError for two.
const std::vector<std::uint8_t>* findPaperTexture(const std::vector<ExtensionBlock>& headerBlocks);

// "PROP": u32 n; per prop u32 V, V x 3 f64, u32 T, T x 3 i32.
ExtensionBlock encodePropMeshes(const std::vector<PropMeshRecord>& meshes);
// nullopt without a PROP block. CorruptDataError for a malformed block, a
// vertex that is not finite or a triangle index outside its prop's vertices.
std::optional<std::vector<PropMeshRecord>> decodePropMeshes(
    const std::vector<ExtensionBlock>& headerBlocks);

// "PRPM": u32 n; per prop 16 f64, its column-major 4x4 motion from the rest
// mesh to the frame.
ExtensionBlock encodePropMotions(const std::vector<Mat4>& motions);
// nullopt without a PRPM block. CorruptDataError for a malformed block or a
// motion that is not finite.
std::optional<std::vector<Mat4>> decodePropMotions(const std::vector<ExtensionBlock>& frameBlocks);

}  // namespace crumple::cache
