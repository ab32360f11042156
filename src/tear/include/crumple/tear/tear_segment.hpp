#pragma once
// One advance of one tear, as the mesh took it and as the texture shows it
// (thesis 3.3.3-3.3.4): the simulated mesh is cut along a chain of edges from
// the tip s_t to the next tip s_{t+1}; the detailed path, the greedy walk
// over the fibers between the same two tips, is where the paper visibly
// parts. The baked tear textures (tear_atlas.hpp) bridge the two.
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::tear {

struct TearSegment {
  int tear = 0;              // which tear (0, 1, ...: in the order they started)
  std::vector<Vec2> cut;     // the mesh cut's vertices from s_t to s_{t+1} (pattern, m)
  std::vector<Vec2> detail;  // the detail path from s_t to s_{t+1} (pattern, m; detailPath)
};

}  // namespace crumple::tear
