#pragma once
// Locating pattern points on a sheet (pipeline-internal): which triangle of
// a sheet's pattern holds a point, and where in it. Shared by the shape
// comparison of two caches and the motion blur's frame velocities, both of
// which follow a material point from one mesh to another by its pattern
// position.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "crumple/core/geometry2d.hpp"
#include "crumple/core/types.hpp"

namespace crumple::pipeline::detail {

// A sheet's triangles bucketed on a uniform grid over its pattern, for
// locating pattern points (each triangle in every cell its bounding box
// touches).
class PatternLocator {
 public:
  PatternLocator(const std::vector<Vec2>& pattern, const std::vector<std::array<int, 3>>& triangles)
      : pattern_(pattern), triangles_(triangles) {
    lo_ = Vec2::Constant(std::numeric_limits<double>::infinity());
    Vec2 hi = -lo_;
    for (const auto& t : triangles)
      for (int v : t) {
        lo_ = lo_.cwiseMin(pattern[idx(v)]);
        hi = hi.cwiseMax(pattern[idx(v)]);
      }
    n_ = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(triangles.size()))));
    cell_ = (hi - lo_).cwiseMax(Vec2::Constant(1e-12)) / n_;
    cells_.resize(static_cast<std::size_t>(n_) * static_cast<std::size_t>(n_));
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      Vec2 a = Vec2::Constant(std::numeric_limits<double>::infinity());
      Vec2 b = -a;
      for (int v : triangles[t]) {
        a = a.cwiseMin(pattern[idx(v)]);
        b = b.cwiseMax(pattern[idx(v)]);
      }
      const auto [i0, j0] = cellOf(a);
      const auto [i1, j1] = cellOf(b);
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) cells_[index(i, j)].push_back(static_cast<int>(t));
    }
  }

  // The triangle holding p and p's barycentric coordinates in it; a point in
  // none gets the nearest triangle of its cell's neighbourhood (or of the
  // sheet) with clamped coordinates, and `inside` false.
  struct Hit {
    int triangle = -1;
    std::array<double, 3> w{};
    bool inside = false;
  };
  Hit locate(const Vec2& p) const {
    Hit best;
    double bestGap = std::numeric_limits<double>::infinity();
    const auto [ci, cj] = cellOf(p);
    for (int ring = 0; ring <= n_; ++ring) {
      for (int j = cj - ring; j <= cj + ring; ++j)
        for (int i = ci - ring; i <= ci + ring; ++i) {
          if (i < 0 || j < 0 || i >= n_ || j >= n_) continue;
          if (std::max(std::abs(i - ci), std::abs(j - cj)) != ring) continue;
          for (int t : cells_[index(i, j)]) {
            const Hit h = barycentric(t, p);
            const double gap = -std::min({h.w[0], h.w[1], h.w[2], 0.0});
            if (gap < bestGap) {
              bestGap = gap;
              best = h;
            }
          }
        }
      // A point inside a triangle ends the search; otherwise one more ring
      // after the first hit, then stop.
      if (bestGap <= 1e-9 || (best.triangle >= 0 && ring > 0)) break;
    }
    best.inside = bestGap <= 1e-9;
    if (!best.inside) {  // clamp onto the triangle
      double sum = 0.0;
      for (double& x : best.w) sum += (x = std::max(0.0, x));
      for (double& x : best.w) x /= sum > 0.0 ? sum : 1.0;
    }
    return best;
  }

  // p's barycentric coordinates in triangle t (unclamped; {1, -1, -1} for a
  // degenerate triangle).
  Hit barycentric(int t, const Vec2& p) const {
    const auto& tri = triangles_[idx(t)];
    const Vec2& a = pattern_[idx(tri[0])];
    const Vec2& b = pattern_[idx(tri[1])];
    const Vec2& c = pattern_[idx(tri[2])];
    const double area = cross2(b - a, c - a);
    Hit h;
    h.triangle = t;
    if (!(std::abs(area) > 0.0)) {
      h.w = {1.0, -1.0, -1.0};  // degenerate: never inside
      return h;
    }
    h.w[0] = cross2(b - p, c - p) / area;
    h.w[1] = cross2(c - p, a - p) / area;
    h.w[2] = 1.0 - h.w[0] - h.w[1];
    return h;
  }

 private:
  static std::size_t idx(int i) { return static_cast<std::size_t>(i); }
  std::pair<int, int> cellOf(const Vec2& p) const {
    const Vec2 q = (p - lo_).cwiseQuotient(cell_);
    return {std::clamp(static_cast<int>(std::floor(q.x())), 0, n_ - 1),
            std::clamp(static_cast<int>(std::floor(q.y())), 0, n_ - 1)};
  }
  std::size_t index(int i, int j) const {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i);
  }

  const std::vector<Vec2>& pattern_;
  const std::vector<std::array<int, 3>>& triangles_;
  Vec2 lo_ = Vec2::Zero(), cell_ = Vec2::Ones();
  int n_ = 1;
  std::vector<std::vector<int>> cells_;
};

}  // namespace crumple::pipeline::detail
