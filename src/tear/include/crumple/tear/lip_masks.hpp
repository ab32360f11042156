#pragma once
// The two lips of a tear in texture space (thesis 3.3.4, Fig. 3.24): over a
// pixel grid of the pattern, which pixels lie left of the tear's detail path
// (kept by T_left, cut from T_right) and which right of it. Every pixel is on
// exactly one side, so the two lips' alpha masks are complementary: no pixel
// is opaque on both, none on neither.
#include <cstdint>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::tear {

struct PixelGrid {
  Vec2 origin = Vec2::Zero();  // pattern position of pixel (0, 0)'s corner (m)
  double pixelSize = 2.5e-4;   // m
  int width = 0;
  int height = 0;
  Vec2 centre(int i, int j) const { return origin + pixelSize * Vec2(i + 0.5, j + 0.5); }
};

// 1 where the pixel centre lies left of the path (walking from its first
// point to its last), 0 right of it; row-major, width * height. The path
// (at least two distinct points, not crossing itself) is extended at both
// ends along the chord from its first to its last point, so that it splits
// the whole plane; a pixel's side is the parity of the path's crossings by
// the ray from its centre along the chord's left normal. Throws
// std::invalid_argument for an empty grid or a degenerate path.
std::vector<std::uint8_t> leftOfPath(const std::vector<Vec2>& path, const PixelGrid& grid);

}  // namespace crumple::tear
