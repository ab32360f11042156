#pragma once
// A simulation's state in bytes (checkpoint and resume): every
// stateful stage writes what it carries from one frame to the next, and
// reads it back into a fresh object, so that a resumed run goes on exactly
// as the uninterrupted one. Little-endian, IEEE doubles bit for bit; each
// section is tagged, so a mismatch is named instead of misread.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple {

class StateWriter {
 public:
  // A section's four-character tag (its start is checked on reading).
  void tag(const char (&name)[5]);
  void u8(std::uint8_t v) { bytes_.push_back(v); }
  void u32(std::uint32_t v);
  void u64(std::uint64_t v);
  void i32(int v) { u32(static_cast<std::uint32_t>(v)); }
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void f64(double v);
  void boolean(bool v) { u8(v ? 1 : 0); }
  void str(const std::string& s);
  void vec2(const Vec2& v);
  void vec3(const Vec3& v);
  void f64s(const std::vector<double>& v);
  void i32s(const std::vector<int>& v);
  void bytes(const std::vector<char>& v);
  void vec2s(const std::vector<Vec2>& v);
  void vec3s(const std::vector<Vec3>& v);
  void triangles(const std::vector<std::array<int, 3>>& v);
  void count(std::size_t n);

  const std::vector<std::uint8_t>& data() const { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
};

// Reads what a StateWriter wrote. Every read is bounds-checked: a short or
// malformed state throws CorruptDataError naming `what` (the checkpoint).
class StateReader {
 public:
  StateReader(const std::vector<std::uint8_t>& bytes, std::string what);
  // Throws CorruptDataError unless the next four bytes are `name`.
  void tag(const char (&name)[5]);
  std::uint8_t u8();
  std::uint32_t u32();
  std::uint64_t u64();
  int i32() { return static_cast<int>(u32()); }
  std::int64_t i64() { return static_cast<std::int64_t>(u64()); }
  double f64();
  bool boolean();
  std::string str();
  Vec2 vec2();
  Vec3 vec3();
  std::vector<double> f64s();
  std::vector<int> i32s();
  std::vector<char> bytes();
  std::vector<Vec2> vec2s();
  std::vector<Vec3> vec3s();
  std::vector<std::array<int, 3>> triangles();
  // A count of items of at least `minBytes` each, checked against what is left.
  std::size_t count(std::size_t minBytes);
  bool atEnd() const { return pos_ == bytes_.size(); }
  [[noreturn]] void fail(const std::string& problem) const;

 private:
  const std::uint8_t* take(std::size_t n);
  const std::vector<std::uint8_t>& bytes_;
  std::string what_;
  std::size_t pos_ = 0;
};

}  // namespace crumple
