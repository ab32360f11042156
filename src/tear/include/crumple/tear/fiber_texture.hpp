#pragma once
// The fibers' resistance to tearing over the pattern, T_fibers(u, v) in
// [0, 1] (thesis 3.2.2 and 3.3.2): seeded fractal gradient (Perlin) noise on
// a texel grid covering the pattern, optionally anisotropic (paper's fibers
// lie mostly along its machine direction). A pure function of its
// parameters and seed: the same texture on any machine and thread count.
#include <array>
#include <cstdint>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/tear/params.hpp"

namespace crumple::tear {

class FiberTexture {
 public:
  // A texture covering the pattern rectangle [origin, origin + size] (m).
  // Throws std::invalid_argument for non-positive or non-finite sizes, fewer
  // than one octave, a persistence outside (0, 1], anisotropy < 1, a zero
  // fiber direction, or more than 64 M texels.
  FiberTexture(const Vec2& origin, const Vec2& size, const FiberTextureParams& params);

  int width() const { return width_; }
  int height() const { return height_; }
  double texelSize() const { return params_.texelSize; }
  // Texel (i, j), i along u, j along v; in [0, 1] (min 0, max 1 over the texture).
  double texel(int i, int j) const {
    return values_[static_cast<std::size_t>(j) * static_cast<std::size_t>(width_) +
                   static_cast<std::size_t>(i)];
  }
  // Pattern position of texel (i, j)'s centre, and the texel holding p
  // (clamped to the texture).
  Vec2 centre(int i, int j) const;
  std::array<int, 2> texelOf(const Vec2& p) const;
  // T_fibers at pattern point p: bilinear between texel centres, clamped.
  double sample(const Vec2& p) const;

 private:
  FiberTextureParams params_;
  Vec2 origin_;
  int width_ = 0;
  int height_ = 0;
  std::vector<double> values_;
};

}  // namespace crumple::tear
