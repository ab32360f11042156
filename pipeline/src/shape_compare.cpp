#include "crumple/pipeline/shape_compare.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "crumple/core/error.hpp"
#include "crumple/core/geometry2d.hpp"

namespace crumple::pipeline {

namespace {

std::size_t at(int i) { return static_cast<std::size_t>(i); }

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
        lo_ = lo_.cwiseMin(pattern[at(v)]);
        hi = hi.cwiseMax(pattern[at(v)]);
      }
    n_ = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(triangles.size()))));
    cell_ = (hi - lo_).cwiseMax(Vec2::Constant(1e-12)) / n_;
    cells_.resize(static_cast<std::size_t>(n_) * static_cast<std::size_t>(n_));
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      Vec2 a = Vec2::Constant(std::numeric_limits<double>::infinity());
      Vec2 b = -a;
      for (int v : triangles[t]) {
        a = a.cwiseMin(pattern[at(v)]);
        b = b.cwiseMax(pattern[at(v)]);
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

 private:
  std::pair<int, int> cellOf(const Vec2& p) const {
    const Vec2 q = (p - lo_).cwiseQuotient(cell_);
    return {std::clamp(static_cast<int>(std::floor(q.x())), 0, n_ - 1),
            std::clamp(static_cast<int>(std::floor(q.y())), 0, n_ - 1)};
  }
  std::size_t index(int i, int j) const {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i);
  }
  Hit barycentric(int t, const Vec2& p) const {
    const auto& tri = triangles_[at(t)];
    const Vec2& a = pattern_[at(tri[0])];
    const Vec2& b = pattern_[at(tri[1])];
    const Vec2& c = pattern_[at(tri[2])];
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

  const std::vector<Vec2>& pattern_;
  const std::vector<std::array<int, 3>>& triangles_;
  Vec2 lo_ = Vec2::Zero(), cell_ = Vec2::Ones();
  int n_ = 1;
  std::vector<std::vector<int>> cells_;
};

// Pattern area per vertex: a third of each triangle's it belongs to.
std::vector<double> vertexAreas(const std::vector<Vec2>& pattern,
                                const std::vector<std::array<int, 3>>& triangles) {
  std::vector<double> area(pattern.size(), 0.0);
  for (const auto& t : triangles) {
    const double a = std::abs(cross2(pattern[at(t[1])] - pattern[at(t[0])],
                                     pattern[at(t[2])] - pattern[at(t[0])])) /
                     6.0;
    for (int v : t) area[at(v)] += a;
  }
  return area;
}

// Sheet `from`'s vertices measured against sheet `to`: sums into the totals.
void measureOneWay(const std::vector<Vec2>& patternFrom,
                   const std::vector<std::array<int, 3>>& trianglesFrom,
                   const std::vector<Vec3>& positionsFrom, const std::vector<Vec2>& patternTo,
                   const std::vector<std::array<int, 3>>& trianglesTo,
                   const std::vector<Vec3>& positionsTo, double& weighted, double& weight,
                   ShapeDistance& out) {
  const PatternLocator locator(patternTo, trianglesTo);
  const std::vector<double> area = vertexAreas(patternFrom, trianglesFrom);
  double sum = 0.0, total = 0.0;
  for (std::size_t v = 0; v < patternFrom.size(); ++v) {
    if (!(area[v] > 0.0)) continue;  // in no triangle
    const auto hit = locator.locate(patternFrom[v]);
    const auto& tri = trianglesTo[at(hit.triangle)];
    const Vec3 there = hit.w[0] * positionsTo[at(tri[0])] + hit.w[1] * positionsTo[at(tri[1])] +
                       hit.w[2] * positionsTo[at(tri[2])];
    const double d = (positionsFrom[v] - there).norm();
    sum += area[v] * d;
    total += area[v];
    out.max = std::max(out.max, d);
    out.outside += hit.inside ? 0 : 1;
  }
  // Each direction weighs as much as the other, whatever its vertex count.
  if (total > 0.0) {
    weighted += sum / total;
    weight += 1.0;
  }
}

// The frame's sizes and indices are consistent (the cache reader checks
// CRCs, not what the blocks say).
void checkFrame(const cache::CacheReader& reader, const cache::FrameRecord& f) {
  const auto fail = [&](const std::string& what) {
    throw CorruptDataError(reader.path() + ": frame " + std::to_string(f.frame) + ": " + what);
  };
  if (f.pattern.size() != f.positions.size()) fail("its pattern and positions differ in size");
  if (f.triangles.empty()) fail("no triangles");
  for (const auto& t : f.triangles)
    for (int v : t)
      if (v < 0 || at(v) >= f.positions.size()) fail("a triangle's vertex is out of range");
  for (std::size_t v = 0; v < f.positions.size(); ++v)
    if (!f.positions[v].allFinite() || !f.pattern[v].allFinite()) fail("a vertex is not finite");
}

}  // namespace

ShapeDistance shapeDistance(const std::vector<Vec2>& patternA,
                            const std::vector<std::array<int, 3>>& trianglesA,
                            const std::vector<Vec3>& positionsA, const std::vector<Vec2>& patternB,
                            const std::vector<std::array<int, 3>>& trianglesB,
                            const std::vector<Vec3>& positionsB) {
  if (trianglesA.empty() || trianglesB.empty())
    throw std::invalid_argument("shapeDistance: a sheet without triangles");
  ShapeDistance out;
  double weighted = 0.0, weight = 0.0;
  measureOneWay(patternA, trianglesA, positionsA, patternB, trianglesB, positionsB, weighted,
                weight, out);
  measureOneWay(patternB, trianglesB, positionsB, patternA, trianglesA, positionsA, weighted,
                weight, out);
  out.mean = weight > 0.0 ? weighted / weight : 0.0;
  return out;
}

std::vector<ShapeDistance> compareShapes(const cache::CacheReader& a, const cache::CacheReader& b) {
  std::map<int, std::size_t> inB;
  for (std::size_t i = 0; i < b.frameCount(); ++i) inB[b.frameNumber(i)] = i;
  std::vector<ShapeDistance> out;
  for (std::size_t i = 0; i < a.frameCount(); ++i) {
    const auto it = inB.find(a.frameNumber(i));
    if (it == inB.end()) continue;
    const cache::FrameRecord fa = a.readFrame(i);
    const cache::FrameRecord fb = b.readFrame(it->second);
    checkFrame(a, fa);
    checkFrame(b, fb);
    ShapeDistance d = shapeDistance(fa.pattern, fa.triangles, fa.positions, fb.pattern,
                                    fb.triangles, fb.positions);
    d.frame = fa.frame;
    d.singularVertices = fa.singularVertices.size();
    out.push_back(d);
  }
  if (out.empty()) throw InputError(b.path(), "shares no frame number with " + a.path());
  return out;
}

}  // namespace crumple::pipeline
