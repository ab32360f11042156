#pragma once
// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320), as in zlib and PNG.
#include <cstddef>
#include <cstdint>

namespace crumple {

// Continue a CRC over more bytes: crc32(data, n, crc32(prev, m)) == crc32 of both.
std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc = 0);

}  // namespace crumple
