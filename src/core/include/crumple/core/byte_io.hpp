#pragma once
// The one byte codec of the project's binary files: the .pcache mesh cache
// and its sub-blocks (docs/PCACHE.md) and the checkpoint's state
// (state_io.hpp). Little-endian byte by byte, whatever the host's order;
// IEEE-754 floats bit for bit. The reader checks every read against the
// bytes left, so a damaged length or count is an error, never a huge
// allocation or a read past the end.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace crumple {

using Bytes = std::vector<std::uint8_t>;
using ByteTag = std::array<char, 4>;  // a chunk's or section's four-character tag

// Appends to a byte vector it does not own.
class ByteWriter {
 public:
  explicit ByteWriter(Bytes& out) : out_(&out) {}

  void u8(std::uint8_t v) { out_->push_back(v); }
  void u32(std::uint32_t v) { put(v, 4); }
  void u64(std::uint64_t v) { put(v, 8); }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void f32(float v);
  void f64(double v);
  void boolean(bool v) { u8(v ? 1 : 0); }
  void raw(const void* data, std::size_t n);
  void tag(const ByteTag& t) { raw(t.data(), t.size()); }
  // A count in 32 bits; beyond them std::length_error naming `what`.
  void count32(std::size_t n, const char* what);
  void count64(std::size_t n) { u64(static_cast<std::uint64_t>(n)); }
  // A string after its length (count32 / count64).
  void str32(const std::string& s, const char* what);
  void str64(const std::string& s);

 private:
  void put(std::uint64_t v, int bytes) {
    for (int k = 0; k < bytes; ++k) out_->push_back(static_cast<std::uint8_t>(v >> (8 * k)));
  }
  Bytes* out_;
};

// Reads what a ByteWriter wrote. Every failure throws CorruptDataError whose
// message is "<source>: <record> <index>: <problem>", the source and record
// parts when set, followed by " (at byte N)" when the reader was asked to
// name offsets. `field` arguments name what was being read (may be null).
class ByteReader {
 public:
  struct Naming {
    std::string source;        // what is read: "the checkpoint", "pcache CONT sub-block"
    bool byteOffsets = false;  // end messages with the offset of the failed read
  };
  ByteReader(std::span<const std::uint8_t> bytes, Naming naming);

  std::uint8_t u8(const char* field = nullptr) { return *take(1, field); }
  std::uint32_t u32(const char* field = nullptr) {
    return static_cast<std::uint32_t>(get(4, field));
  }
  std::uint64_t u64(const char* field = nullptr) { return get(8, field); }
  std::int32_t i32(const char* field = nullptr) { return static_cast<std::int32_t>(u32(field)); }
  std::int64_t i64(const char* field = nullptr) { return static_cast<std::int64_t>(u64(field)); }
  float f32(const char* field = nullptr);
  double f64(const char* field = nullptr);
  // A 0 or 1 byte; any other value is damage.
  bool boolean(const char* field = nullptr);
  ByteTag tag(const char* field = nullptr);
  // The next n bytes.
  const std::uint8_t* take(std::size_t n, const char* field = nullptr);
  // A count (32 or 64 bits) of items of at least minBytes each, checked
  // against the bytes left.
  std::size_t count32(std::size_t minBytes, const char* field = nullptr);
  std::size_t count64(std::size_t minBytes, const char* field = nullptr);
  std::string str32(const char* field = nullptr);
  std::string str64(const char* field = nullptr);

  std::size_t remaining() const { return bytes_.size() - pos_; }
  std::size_t position() const { return pos_; }
  bool atEnd() const { return pos_ == bytes_.size(); }
  // Throws unless every byte was read.
  void expectEnd();
  // The record the next reads belong to, named in messages (kind null: none).
  void at(const char* kind, std::size_t index) {
    kind_ = kind;
    index_ = index;
  }
  [[noreturn]] void fail(const std::string& problem) const;

 private:
  std::uint64_t get(int n, const char* field);
  std::size_t checkedCount(std::uint64_t n, std::size_t minBytes, const char* field) const;
  std::span<const std::uint8_t> bytes_;
  Naming naming_;
  const char* kind_ = nullptr;
  std::size_t index_ = 0;
  std::size_t pos_ = 0;
};

}  // namespace crumple
