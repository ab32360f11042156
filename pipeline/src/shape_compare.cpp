#include "crumple/pipeline/shape_compare.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "crumple/core/error.hpp"
#include "crumple/core/geometry2d.hpp"
#include "pattern_locator.hpp"

namespace crumple::pipeline {

namespace {

std::size_t at(int i) { return static_cast<std::size_t>(i); }

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
  const detail::PatternLocator locator(patternTo, trianglesTo);
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
