#pragma once
// The shape of one shot against another's (`crumple compare A.pcache
// B.pcache`): per frame, the distance between the points of the two sheets
// at the same pattern (material) position, whatever their meshes. The
// crumpling model is judged this way against a fine elastic reference
// running the same motion (docs/CRUMPLING.md "Shape against a fine
// reference").
#include <array>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/types.hpp"

namespace crumple::pipeline {

struct ShapeDistance {
  int frame = 0;
  // Mean over both sheets' vertices, each located in the other sheet by its
  // pattern position and weighted by its pattern area (a third of its
  // triangles'), of the distance to the point there (m): the same for any
  // triangulation of the same surfaces.
  double mean = 0.0;
  double max = 0.0;  // the largest of those distances (m)
  // Vertices whose pattern position lies in no triangle of the other sheet
  // (outside its outline, or in a tear's gap) measured to its nearest
  // triangle.
  std::size_t outside = 0;
  std::size_t singularVertices = 0;  // in the first cache's frame
};

// One frame pair: the pattern, triangles and positions of each sheet.
// Throws std::invalid_argument for a sheet without triangles.
ShapeDistance shapeDistance(const std::vector<Vec2>& patternA,
                            const std::vector<std::array<int, 3>>& trianglesA,
                            const std::vector<Vec3>& positionsA, const std::vector<Vec2>& patternB,
                            const std::vector<std::array<int, 3>>& trianglesB,
                            const std::vector<Vec3>& positionsB);

// Every frame number the two caches share, in order. Throws InputError
// when they share none, and CorruptDataError naming the file and frame for
// a frame whose indices or numbers are out of range.
std::vector<ShapeDistance> compareShapes(const cache::CacheReader& a, const cache::CacheReader& b);

}  // namespace crumple::pipeline
