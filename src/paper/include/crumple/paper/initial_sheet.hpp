#pragma once
// The starting S_G (paper Sec. 3.3 "Initialization"): a flat rectangle, one
// flat region triangulated on its corners and its handle vertices.
#include <vector>

#include "crumple/paper/geometric_mesh.hpp"

namespace crumple::paper {

struct InitialSheet {
  GeometricMesh mesh;
  std::vector<int> handleVertices;  // S_G vertex of each requested handle point
};

// The rectangle [0,width] x [0,height] in the pattern, placed in the world at
// origin + u * uAxis + v * vAxis. Every handle point becomes a vertex (on the
// outline when it is within 1e-9 relative of it, a corner when it is one);
// points closer than 1e-9 relative to each other share a vertex.
// Throws InputError for a point outside the sheet.
InitialSheet makeFlatSheet(double width, double height, const std::vector<Vec2>& handlePoints,
                           const Vec3& origin, const Vec3& uAxis, const Vec3& vAxis);

}  // namespace crumple::paper
