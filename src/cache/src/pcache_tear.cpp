// The TEAR extension sub-block. Byte layout: docs/PCACHE.md ("Sub-blocks
// written by crumple").
#include "crumple/cache/pcache_tear.hpp"

#include <bit>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

#include "sub_block.hpp"

namespace crumple::cache {
namespace {

using Reader = detail::SubBlockReader;

// Smallest encoded patch: 2 i32, 2 u8, u32 + 3 points, 4 u32, 2 f64.
constexpr std::size_t kMinPatchBytes = 4 + 4 + 1 + 1 + 4 + 3 * 16 + 4 * 4 + 2 * 8;

}  // namespace

ExtensionBlock encodeTearAtlas(const mesh::TearAtlas& atlas) {
  if (const std::string problem = mesh::validate(atlas); !problem.empty())
    throw std::invalid_argument("encodeTearAtlas: " + problem);
  Bytes bytes;
  ByteWriter w(bytes);
  w.f64(atlas.texelSize);
  w.u32(static_cast<std::uint32_t>(atlas.width));
  w.u32(static_cast<std::uint32_t>(atlas.height));
  w.count32(atlas.patches.size(), "tear patches");
  for (const mesh::TearPatch& p : atlas.patches) {
    w.i32(p.triangle);
    w.i32(p.tear);
    w.u8(static_cast<std::uint8_t>(p.side));
    w.u8(p.lipEdges);
    w.count32(p.polygon.size(), "tear patch polygon points");
    for (const Vec2& q : p.polygon) {
      w.f64(q.x());
      w.f64(q.y());
    }
    w.u32(static_cast<std::uint32_t>(p.rect.x));
    w.u32(static_cast<std::uint32_t>(p.rect.y));
    w.u32(static_cast<std::uint32_t>(p.rect.width));
    w.u32(static_cast<std::uint32_t>(p.rect.height));
    w.f64(p.rect.origin.x());
    w.f64(p.rect.origin.y());
  }
  // The mask, a bit per texel in row-major order, least significant bit first.
  std::uint8_t byte = 0;
  for (std::size_t i = 0; i < atlas.mask.size(); ++i) {
    if (atlas.mask[i] != 0) byte = static_cast<std::uint8_t>(byte | (1u << (i % 8)));
    if (i % 8 == 7) {
      w.u8(byte);
      byte = 0;
    }
  }
  if (atlas.mask.size() % 8 != 0) w.u8(byte);
  return {kTearAtlasTag, std::move(bytes)};
}

std::optional<mesh::TearAtlas> decodeTearAtlas(const std::vector<ExtensionBlock>& frameBlocks) {
  const ExtensionBlock* block = detail::findOneBlock(frameBlocks, kTearAtlasTag);
  if (!block) return std::nullopt;
  Reader r(block->data, "TEAR");
  mesh::TearAtlas atlas;
  atlas.texelSize = r.f64("texel size");
  const std::uint32_t width = r.u32("atlas width");
  const std::uint32_t height = r.u32("atlas height");
  if (width > 0x7fffffffu || height > 0x7fffffffu)
    r.fail("atlas size " + std::to_string(width) + " x " + std::to_string(height) +
           " beyond 2^31 - 1");
  atlas.width = static_cast<int>(width);
  atlas.height = static_cast<int>(height);
  atlas.patches.resize(r.count32(kMinPatchBytes, "patch count"));
  for (std::size_t i = 0; i < atlas.patches.size(); ++i) {
    mesh::TearPatch& p = atlas.patches[i];
    r.at("patch", i);
    p.triangle = r.i32("triangle");
    p.tear = r.i32("tear");
    p.side = static_cast<mesh::LipSide>(r.u8("side"));
    p.lipEdges = r.u8("lip edges");
    p.polygon.resize(r.count32(16, "polygon point count"));
    for (Vec2& q : p.polygon) {
      q.x() = r.f64("polygon point");
      q.y() = r.f64("polygon point");
    }
    const auto asInt = [&](std::uint32_t v, const char* what) {
      if (v > 0x7fffffffu) r.fail(std::string(what) + " " + std::to_string(v) + " beyond 2^31 - 1");
      return static_cast<int>(v);
    };
    p.rect.x = asInt(r.u32("rect x"), "rect x");
    p.rect.y = asInt(r.u32("rect y"), "rect y");
    p.rect.width = asInt(r.u32("rect width"), "rect width");
    p.rect.height = asInt(r.u32("rect height"), "rect height");
    p.rect.origin.x() = r.f64("rect origin");
    p.rect.origin.y() = r.f64("rect origin");
  }
  r.at("mask", 0);
  const std::uint64_t texels = static_cast<std::uint64_t>(width) * height;
  if (texels / 8 + (texels % 8 != 0) != r.remaining())
    r.fail(std::to_string(r.remaining()) + " bytes for " + std::to_string(width) + " x " +
           std::to_string(height) + " texels (one bit each)");
  const std::uint8_t* bits = r.take(r.remaining(), "mask");
  atlas.mask.resize(static_cast<std::size_t>(texels));
  for (std::size_t i = 0; i < atlas.mask.size(); ++i)
    atlas.mask[i] = (bits[i / 8] >> (i % 8)) & 1u ? 255 : 0;
  if (texels % 8 != 0 && (bits[texels / 8] >> (texels % 8)) != 0)
    r.fail("bits beyond the last texel are not 0");
  r.expectEnd();
  if (const std::string problem = mesh::validate(atlas); !problem.empty()) {
    r.at(nullptr, 0);
    r.fail(problem);
  }
  return atlas;
}

}  // namespace crumple::cache
