#include "crumple/core/state_io.hpp"

#include <bit>
#include <cstring>
#include <limits>

#include "crumple/core/error.hpp"

namespace crumple {

void StateWriter::tag(const char (&name)[5]) { bytes_.insert(bytes_.end(), name, name + 4); }

void StateWriter::u32(std::uint32_t v) {
  for (int k = 0; k < 4; ++k) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

void StateWriter::u64(std::uint64_t v) {
  for (int k = 0; k < 8; ++k) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

void StateWriter::f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }

void StateWriter::count(std::size_t n) { u64(static_cast<std::uint64_t>(n)); }

void StateWriter::str(const std::string& s) {
  count(s.size());
  bytes_.insert(bytes_.end(), s.begin(), s.end());
}

void StateWriter::vec2(const Vec2& v) {
  f64(v.x());
  f64(v.y());
}

void StateWriter::vec3(const Vec3& v) {
  for (int k = 0; k < 3; ++k) f64(v[k]);
}

void StateWriter::f64s(const std::vector<double>& v) {
  count(v.size());
  for (double x : v) f64(x);
}

void StateWriter::i32s(const std::vector<int>& v) {
  count(v.size());
  for (int x : v) i32(x);
}

void StateWriter::bytes(const std::vector<char>& v) {
  count(v.size());
  for (char x : v) u8(static_cast<std::uint8_t>(x));
}

void StateWriter::vec2s(const std::vector<Vec2>& v) {
  count(v.size());
  for (const Vec2& x : v) vec2(x);
}

void StateWriter::vec3s(const std::vector<Vec3>& v) {
  count(v.size());
  for (const Vec3& x : v) vec3(x);
}

void StateWriter::triangles(const std::vector<std::array<int, 3>>& v) {
  count(v.size());
  for (const auto& t : v)
    for (int x : t) i32(x);
}

StateReader::StateReader(const std::vector<std::uint8_t>& bytes, std::string what)
    : bytes_(bytes), what_(std::move(what)) {}

void StateReader::fail(const std::string& problem) const {
  throw CorruptDataError(what_ + ": " + problem + " (at byte " + std::to_string(pos_) + ")");
}

const std::uint8_t* StateReader::take(std::size_t n) {
  if (n > bytes_.size() - pos_) fail("truncated");
  const std::uint8_t* p = bytes_.data() + pos_;
  pos_ += n;
  return p;
}

void StateReader::tag(const char (&name)[5]) {
  const std::uint8_t* p = take(4);
  if (std::memcmp(p, name, 4) != 0)
    fail(std::string("expected the section '") + name + "', found '" +
         std::string(reinterpret_cast<const char*>(p), 4) + "'");
}

std::uint8_t StateReader::u8() { return *take(1); }

std::uint32_t StateReader::u32() {
  const std::uint8_t* p = take(4);
  std::uint32_t v = 0;
  for (int k = 0; k < 4; ++k) v |= static_cast<std::uint32_t>(p[k]) << (8 * k);
  return v;
}

std::uint64_t StateReader::u64() {
  const std::uint8_t* p = take(8);
  std::uint64_t v = 0;
  for (int k = 0; k < 8; ++k) v |= static_cast<std::uint64_t>(p[k]) << (8 * k);
  return v;
}

double StateReader::f64() { return std::bit_cast<double>(u64()); }

bool StateReader::boolean() {
  const std::uint8_t b = u8();
  if (b > 1) fail("a flag of " + std::to_string(b));
  return b == 1;
}

std::size_t StateReader::count(std::size_t minBytes) {
  const std::uint64_t n = u64();
  if (minBytes > 0 && n > (bytes_.size() - pos_) / minBytes)
    fail("a count of " + std::to_string(n) + " runs past the end");
  return static_cast<std::size_t>(n);
}

std::string StateReader::str() {
  const std::size_t n = count(1);
  const std::uint8_t* p = take(n);
  return std::string(reinterpret_cast<const char*>(p), n);
}

// Points and vectors (positions, velocities, pattern points) are finite in
// any state the simulation writes; a non-finite one is damage.
Vec2 StateReader::vec2() {
  const double x = f64();
  const Vec2 v(x, f64());
  if (!v.allFinite()) fail("a point or vector that is not finite");
  return v;
}

Vec3 StateReader::vec3() {
  Vec3 v;
  for (int k = 0; k < 3; ++k) v[k] = f64();
  if (!v.allFinite()) fail("a point or vector that is not finite");
  return v;
}

std::vector<double> StateReader::f64s() {
  std::vector<double> v(count(8));
  for (double& x : v) x = f64();
  return v;
}

std::vector<int> StateReader::i32s() {
  std::vector<int> v(count(4));
  for (int& x : v) x = i32();
  return v;
}

std::vector<char> StateReader::bytes() {
  std::vector<char> v(count(1));
  for (char& x : v) x = static_cast<char>(u8());
  return v;
}

std::vector<Vec2> StateReader::vec2s() {
  std::vector<Vec2> v(count(16));
  for (Vec2& x : v) x = vec2();
  return v;
}

std::vector<Vec3> StateReader::vec3s() {
  std::vector<Vec3> v(count(24));
  for (Vec3& x : v) x = vec3();
  return v;
}

std::vector<std::array<int, 3>> StateReader::triangles() {
  std::vector<std::array<int, 3>> v(count(12));
  for (auto& t : v)
    for (int& x : t) x = i32();
  return v;
}

}  // namespace crumple
