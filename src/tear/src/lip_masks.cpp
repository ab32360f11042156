#include "crumple/tear/lip_masks.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace crumple::tear {

std::vector<std::uint8_t> leftOfPath(const std::vector<Vec2>& path, const PixelGrid& grid) {
  if (grid.width <= 0 || grid.height <= 0 || !(grid.pixelSize > 0.0))
    throw std::invalid_argument("leftOfPath: empty pixel grid");
  if (path.size() < 2) throw std::invalid_argument("leftOfPath: a path needs two points");
  for (const Vec2& p : path)
    if (!p.allFinite()) throw std::invalid_argument("leftOfPath: non-finite path point");
  const Vec2 chord = path.back() - path.front();
  if (!(chord.norm() > 0.0)) throw std::invalid_argument("leftOfPath: the path does not advance");
  const Vec2 along = chord.normalized();
  const Vec2 left(-along.y(), along.x());
  // The path in (s, t) coordinates: s along the chord, t along its left
  // normal, extended at both ends far beyond the grid.
  const double reach = 4.0 * (grid.pixelSize * (grid.width + grid.height) + chord.norm()) +
                       (grid.origin - path.front()).norm();
  std::vector<Vec2> st;
  st.reserve(path.size() + 2);
  const auto toST = [&](const Vec2& p) {
    const Vec2 d = p - path.front();
    return Vec2(d.dot(along), d.dot(left));
  };
  st.push_back(toST(path.front()) - Vec2(reach, 0.0));
  for (const Vec2& p : path) st.push_back(toST(p));
  st.push_back(toST(path.back()) + Vec2(reach, 0.0));

  std::vector<std::uint8_t> out(static_cast<std::size_t>(grid.width) *
                                static_cast<std::size_t>(grid.height));
  for (int j = 0; j < grid.height; ++j) {
    for (int i = 0; i < grid.width; ++i) {
      const Vec2 q = toST(grid.centre(i, j));
      // Crossings of the ray {s = q.s, t > q.t} with the path's segments,
      // half-open in s so that a ray through a vertex counts it once.
      int crossings = 0;
      for (std::size_t k = 0; k + 1 < st.size(); ++k) {
        const Vec2& a = st[k];
        const Vec2& b = st[k + 1];
        if ((a.x() <= q.x()) == (b.x() <= q.x())) continue;
        const double t = a.y() + (q.x() - a.x()) / (b.x() - a.x()) * (b.y() - a.y());
        if (t > q.y()) ++crossings;
      }
      out[static_cast<std::size_t>(j) * static_cast<std::size_t>(grid.width) +
          static_cast<std::size_t>(i)] = crossings % 2 == 0 ? 1 : 0;
    }
  }
  return out;
}

}  // namespace crumple::tear
