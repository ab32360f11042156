#pragma once
// Constrained Delaunay triangulation of a planar straight-line graph, the
// triangulation helper S_P enrichment uses to connect the samples of a flat
// region (paper Sec. 4 "Enriching the coarse mesh"; thesis 2.3.2). CGAL
// stays inside delaunay.cpp: including this header costs nothing.
#include <array>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::mesh {

// Constrained Delaunay triangulation (CGAL) of `points` with constraint
// segments (index pairs). Returns only the triangles inside the domain the
// constraints enclose (odd nesting level counted from the infinite face, as
// in CGAL's "mark domains" example), counter-clockwise, as indices into
// `points`; with no constraint the domain is empty. No Steiner points:
// throws std::invalid_argument when constraints cross each other or a
// constraint passes through another point, when two points are closer than
// 1e-12 times the bounding-box diagonal, on an out-of-range or degenerate
// constraint, or on a non-finite point. The output is deterministic: every
// triangle starts at its smallest index and the list is sorted.
std::vector<std::array<int, 3>> constrainedDelaunay(
    const std::vector<Vec2>& points, const std::vector<std::array<int, 2>>& constraints);

}  // namespace crumple::mesh
