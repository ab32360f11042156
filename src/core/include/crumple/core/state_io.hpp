#pragma once
// A simulation's state in bytes (checkpoint and resume): every
// stateful stage writes what it carries from one frame to the next, and
// reads it back into a fresh object, so that a resumed run goes on exactly
// as the uninterrupted one. Written with the project's one byte codec
// (byte_io.hpp): little-endian, IEEE doubles bit for bit, 64-bit counts; each
// section is tagged, so a mismatch is named instead of misread.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "crumple/core/byte_io.hpp"
#include "crumple/core/types.hpp"

namespace crumple {

class StateWriter {
 public:
  // A section's four-character tag (its start is checked on reading).
  void tag(const char (&name)[5]);
  void u8(std::uint8_t v) { out().u8(v); }
  void u32(std::uint32_t v) { out().u32(v); }
  void u64(std::uint64_t v) { out().u64(v); }
  void i32(int v) { out().i32(v); }
  void i64(std::int64_t v) { out().i64(v); }
  void f64(double v) { out().f64(v); }
  void boolean(bool v) { out().boolean(v); }
  void str(const std::string& s) { out().str64(s); }
  void vec2(const Vec2& v);
  void vec3(const Vec3& v);
  void f64s(const std::vector<double>& v);
  void i32s(const std::vector<int>& v);
  void bytes(const std::vector<char>& v);
  void vec2s(const std::vector<Vec2>& v);
  void vec3s(const std::vector<Vec3>& v);
  void triangles(const std::vector<std::array<int, 3>>& v);
  void count(std::size_t n) { out().count64(n); }

  const Bytes& data() const { return bytes_; }

 private:
  ByteWriter out() { return ByteWriter(bytes_); }
  Bytes bytes_;
};

// Reads what a StateWriter wrote. Every read is bounds-checked: a short or
// malformed state throws CorruptDataError naming `what` (the checkpoint).
class StateReader {
 public:
  StateReader(const std::vector<std::uint8_t>& bytes, std::string what);
  // Throws CorruptDataError unless the next four bytes are `name`.
  void tag(const char (&name)[5]);
  std::uint8_t u8() { return in_.u8(); }
  std::uint32_t u32() { return in_.u32(); }
  std::uint64_t u64() { return in_.u64(); }
  int i32() { return in_.i32(); }
  std::int64_t i64() { return in_.i64(); }
  double f64() { return in_.f64(); }
  bool boolean() { return in_.boolean(); }
  std::string str() { return in_.str64(); }
  Vec2 vec2();
  Vec3 vec3();
  std::vector<double> f64s();
  std::vector<int> i32s();
  std::vector<char> bytes();
  std::vector<Vec2> vec2s();
  std::vector<Vec3> vec3s();
  std::vector<std::array<int, 3>> triangles();
  // A count of items of at least `minBytes` each, checked against what is left.
  std::size_t count(std::size_t minBytes) { return in_.count64(minBytes); }
  bool atEnd() const { return in_.atEnd(); }
  [[noreturn]] void fail(const std::string& problem) const { in_.fail(problem); }

 private:
  template <typename T, typename ReadOne>
  std::vector<T> list(std::size_t minBytes, ReadOne readOne);
  ByteReader in_;
};

}  // namespace crumple
