#include "crumple/core/state_io.hpp"

#include <cstring>

#include "crumple/core/error.hpp"

namespace crumple {

void StateWriter::tag(const char (&name)[5]) { bytes_.insert(bytes_.end(), name, name + 4); }

void StateWriter::vec2(const Vec2& v) {
  f64(v.x());
  f64(v.y());
}

void StateWriter::vec3(const Vec3& v) {
  for (int k = 0; k < 3; ++k) f64(v[k]);
}

namespace {

// A list: its count, then each item (paired with readList below).
template <typename T, typename WriteOne>
void writeList(StateWriter& out, const std::vector<T>& v, WriteOne writeOne) {
  out.count(v.size());
  for (const T& x : v) writeOne(x);
}

}  // namespace

void StateWriter::f64s(const std::vector<double>& v) {
  writeList(*this, v, [&](double x) { f64(x); });
}
void StateWriter::i32s(const std::vector<int>& v) {
  writeList(*this, v, [&](int x) { i32(x); });
}
void StateWriter::bytes(const std::vector<char>& v) {
  writeList(*this, v, [&](char x) { u8(static_cast<std::uint8_t>(x)); });
}
void StateWriter::vec2s(const std::vector<Vec2>& v) {
  writeList(*this, v, [&](const Vec2& x) { vec2(x); });
}
void StateWriter::vec3s(const std::vector<Vec3>& v) {
  writeList(*this, v, [&](const Vec3& x) { vec3(x); });
}
void StateWriter::triangles(const std::vector<std::array<int, 3>>& v) {
  writeList(*this, v, [&](const std::array<int, 3>& t) {
    for (int x : t) i32(x);
  });
}

StateReader::StateReader(const std::vector<std::uint8_t>& bytes, std::string what)
    : in_(bytes, {std::move(what), true}) {}

void StateReader::tag(const char (&name)[5]) {
  const ByteTag found = in_.tag();
  if (std::memcmp(found.data(), name, 4) != 0)
    fail(std::string("expected the section '") + name + "', found '" +
         std::string(found.data(), 4) + "'");
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

// A list of items of at least minBytes each (its count checked against the
// bytes left), each read by readOne.
template <typename T, typename ReadOne>
std::vector<T> StateReader::list(std::size_t minBytes, ReadOne readOne) {
  std::vector<T> v(count(minBytes));
  for (T& x : v) x = readOne();
  return v;
}

std::vector<double> StateReader::f64s() {
  return list<double>(8, [&] { return f64(); });
}
std::vector<int> StateReader::i32s() {
  return list<int>(4, [&] { return i32(); });
}
std::vector<char> StateReader::bytes() {
  return list<char>(1, [&] { return static_cast<char>(u8()); });
}
std::vector<Vec2> StateReader::vec2s() {
  return list<Vec2>(16, [&] { return vec2(); });
}
std::vector<Vec3> StateReader::vec3s() {
  return list<Vec3>(24, [&] { return vec3(); });
}
std::vector<std::array<int, 3>> StateReader::triangles() {
  return list<std::array<int, 3>>(12, [&] {
    std::array<int, 3> t{};
    for (int& x : t) x = i32();
    return t;
  });
}

}  // namespace crumple
