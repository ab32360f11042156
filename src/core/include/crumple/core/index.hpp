#pragma once
// Index plumbing for the meshes' int ids. Vertices, triangles, faces, regions
// and rulings are named by int ids (-1 for "none") in every module's data
// (SheetMesh, GeometricMesh, the cache format), while the std::vector and
// std::array holding per-element data are indexed by std::size_t. idx() is
// the one conversion between the two, a light form of the typed element
// handles of geometry-central (Sharp et al.) that keeps the ids' type:
//
//   g.vertices[idx(r.a)].position      planes.resize(idx(n))
//
// It is exactly static_cast<std::size_t> (no cost, and no change at all in a
// release build) and asserts in a debug build that the value is not
// negative, where the cast would wrap to a huge index. inRange() is the
// test for an id that may be -1 or past the end (input being validated).
#include <cassert>
#include <concepts>
#include <cstddef>
#include <iterator>

namespace crumple {

// A non-negative id, count or iterator difference as a std::size_t index or
// size. Signed types only: an unsigned value needs no conversion.
template <std::signed_integral I>
[[nodiscard]] constexpr std::size_t idx(I i) noexcept {
  assert(i >= 0 && "a negative id used as an index");
  return static_cast<std::size_t>(i);
}

// Whether id i names an element of c: 0 <= i < std::size(c).
template <class Container, std::signed_integral I>
[[nodiscard]] constexpr bool inRange(const Container& c, I i) noexcept {
  return i >= 0 && static_cast<std::size_t>(i) < std::size(c);
}

}  // namespace crumple
