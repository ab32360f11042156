#pragma once
// Small 2D geometry on pattern points shared by the modules.
#include <algorithm>

#include "crumple/core/types.hpp"

namespace crumple {

// z of the 3D cross product of (a, 0) and (b, 0): twice the signed area of
// the triangle (0, a, b), > 0 when b is counter-clockwise from a.
inline double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Distance from p to the segment [a, b] (a point when a == b).
inline double distanceToSegment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

}  // namespace crumple
