#pragma once
// Shared by the cache fuzz targets (docs/FUZZING.md): an input with the CRC
// of every chunk recomputed, so that mutated bytes reach the decoders and the
// tools behind them instead of stopping at the CRC check.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "crumple/core/crc32.hpp"
#include "crumple/core/error.hpp"

namespace crumple::fuzz {

inline std::uint64_t littleEndian(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

// The input with the CRC of every chunk that fits in it recomputed
// (docs/PCACHE.md "Chunks": tag, u32 version, u64 length L, L bytes, u32 CRC
// of all before it), walking the chunks from the magic on.
inline std::vector<std::uint8_t> withValidCrcs(const std::uint8_t* data, std::size_t size) {
  constexpr std::size_t kMagic = 8, kPrefix = 16, kCrc = 4;
  std::vector<std::uint8_t> bytes(data, data + size);
  std::size_t offset = kMagic;
  while (offset + kPrefix + kCrc <= size) {
    const std::uint64_t length = littleEndian(bytes.data() + offset + 8, 8);
    if (length > size - offset - kPrefix - kCrc) break;
    const std::size_t end = offset + kPrefix + static_cast<std::size_t>(length);
    const std::uint32_t crc = crumple::crc32(bytes.data() + offset, end - offset);
    for (std::size_t i = 0; i < kCrc; ++i)
      bytes[end + i] = static_cast<std::uint8_t>(crc >> (8 * i));
    offset = end + kCrc;
  }
  return bytes;
}

// Runs `use` on the input, and again with every chunk's CRC recomputed when
// that changes it.
template <typename Use>
void asGivenAndWithValidCrcs(const std::uint8_t* data, std::size_t size, Use use) {
  use(data, size);
  const std::vector<std::uint8_t> fixed = withValidCrcs(data, size);
  if (!std::equal(fixed.begin(), fixed.end(), data)) use(fixed.data(), fixed.size());
}

// Runs a decoder for which damage (CorruptDataError) is an expected outcome.
template <typename Decode>
void tolerateDamage(Decode decode) {
  try {
    (void)decode();
  } catch (const crumple::CorruptDataError&) {
  }
}

}  // namespace crumple::fuzz
