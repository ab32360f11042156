#pragma once
// Reading the extension sub-blocks crumple writes (pcache_contacts.cpp,
// pcache_tear.cpp): little-endian fields, errors that name the block, the
// record being read and the field (CorruptDataError). Internal to the cache
// library.
#include <array>
#include <bit>
#include <cstdint>
#include <string>
#include <vector>

#include "byte_encoder.hpp"
#include "crumple/core/error.hpp"
#include "crumple/exporters/pcache.hpp"

namespace crumple::cache::detail {

// Messages are built only on failure.
class SubBlockReader {
 public:
  SubBlockReader(const Bytes& bytes, const char* block) : bytes_(bytes), block_(block) {}

  std::uint8_t u8(const char* what) { return static_cast<std::uint8_t>(get(1, what)); }
  std::uint32_t u32(const char* what) { return static_cast<std::uint32_t>(get(4, what)); }
  int i32(const char* what) { return static_cast<std::int32_t>(u32(what)); }
  float f32(const char* what) { return std::bit_cast<float>(u32(what)); }
  double f64(const char* what) { return std::bit_cast<double>(get(8, what)); }
  // A u32 count of records of at least `minBytes` each, checked against what
  // is left so that a damaged count cannot trigger a huge allocation.
  std::size_t count(std::size_t minBytes, const char* what) {
    const std::size_t n = u32(what);
    if (n > remaining() / minBytes)
      fail(std::string(what) + " " + std::to_string(n) + " runs past the end of the block (" +
           std::to_string(remaining()) + " bytes left)");
    return n;
  }
  std::string str(const char* what) {
    const std::size_t n = u32(what);
    if (n > remaining())
      fail(std::string(what) + ": length " + std::to_string(n) + " runs past the end of the block");
    std::string s(reinterpret_cast<const char*>(bytes_.data() + pos_), n);
    pos_ += n;
    return s;
  }
  // The next n bytes.
  const std::uint8_t* raw(std::size_t n, const char* what) {
    if (n > remaining()) fail(std::string(what) + " truncated");
    const std::uint8_t* p = bytes_.data() + pos_;
    pos_ += n;
    return p;
  }
  std::size_t remaining() const { return bytes_.size() - pos_; }
  // The record the next reads belong to, for messages (kind null: none).
  void at(const char* kind, std::size_t index) {
    kind_ = kind;
    index_ = index;
  }
  void expectEnd() {
    kind_ = nullptr;
    if (remaining() != 0) fail(std::to_string(remaining()) + " trailing bytes");
  }
  [[noreturn]] void fail(const std::string& problem) const {
    std::string where = kind_ ? std::string(kind_) + " " + std::to_string(index_) + ": " : "";
    throw CorruptDataError(std::string("pcache ") + block_ + " sub-block: " + where + problem);
  }

 private:
  std::uint64_t get(int n, const char* what) {
    if (static_cast<std::size_t>(n) > remaining()) fail(std::string(what) + " truncated");
    std::uint64_t v = 0;
    for (int k = 0; k < n; ++k) v |= static_cast<std::uint64_t>(bytes_[pos_ + k]) << (8 * k);
    pos_ += static_cast<std::size_t>(n);
    return v;
  }
  const Bytes& bytes_;
  const char* block_;
  const char* kind_ = nullptr;
  std::size_t index_ = 0;
  std::size_t pos_ = 0;
};

inline std::string tagName(const Tag& tag) { return std::string(tag.data(), tag.size()); }

// The one block with `tag`, or null; two are malformed.
inline const ExtensionBlock* findOneBlock(const std::vector<ExtensionBlock>& blocks,
                                          const Tag& tag) {
  const ExtensionBlock* found = nullptr;
  for (const auto& b : blocks) {
    if (b.tag != tag) continue;
    if (found)
      throw CorruptDataError("pcache " + tagName(tag) + " sub-block: present more than once");
    found = &b;
  }
  return found;
}

}  // namespace crumple::cache::detail
