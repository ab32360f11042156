#pragma once
// Little-endian encoding of the .pcache chunks and sub-blocks, byte by byte:
// independent of the host's byte order (docs/PCACHE.md). Internal to the
// cache library.
#include <array>
#include <bit>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace crumple::cache::detail {

using Bytes = std::vector<std::uint8_t>;
using Tag = std::array<char, 4>;

// Appends to `out`; a count or string length beyond 32 bits is
// std::length_error naming `what`.
class Encoder {
 public:
  explicit Encoder(Bytes& out) : out_(out) {}

  void u8(std::uint8_t v) { out_.push_back(v); }
  void u32(std::uint32_t v) { put(v, 4); }
  void u64(std::uint64_t v) { put(v, 8); }
  void i32(int v) { u32(static_cast<std::uint32_t>(v)); }
  void f32(float v) { u32(std::bit_cast<std::uint32_t>(v)); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void raw(const void* data, std::size_t n) {
    const auto* b = static_cast<const std::uint8_t*>(data);
    out_.insert(out_.end(), b, b + n);
  }
  void tag(const Tag& t) { raw(t.data(), t.size()); }
  void count(std::size_t n, const char* what) {
    if (n > std::numeric_limits<std::uint32_t>::max())
      throw std::length_error(std::string("pcache: too many ") + what + " (" + std::to_string(n) +
                              ") for a 32-bit count");
    u32(static_cast<std::uint32_t>(n));
  }
  void str(const std::string& s, const char* what) {
    count(s.size(), what);
    raw(s.data(), s.size());
  }

 private:
  void put(std::uint64_t v, int bytes) {
    for (int k = 0; k < bytes; ++k) out_.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
  }
  Bytes& out_;
};

}  // namespace crumple::cache::detail
