#pragma once
// Cutting the sheet's mesh along a tear's advance (thesis 3.3.3,
// "Remeshing", the part that concerns the simulated mesh): the segment from
// the tip s_t (a boundary vertex) to the next tip s_{t+1} (a pattern point
// inside the sheet) becomes a chain of mesh edges (the triangles it crosses
// are split where it crosses them, s_{t+1} is inserted), and every chain
// vertex but the new tip is doubled: one copy for each lip. The pattern is
// unchanged as a point set; no triangle crosses the cut.
#include "crumple/mesh/sheet_mesh.hpp"

namespace crumple::tear {

struct CutResult {
  int tip = -1;            // the vertex at s_{t+1} (an existing one when it is there already)
  std::vector<int> chain;  // the cut's vertices from s_t to s_{t+1} (right lip's copies)
  std::vector<int> twins;  // their left lip's copies (chain.size() - 1: the tip is shared)
};

// Cuts `mesh` from boundary vertex `from` to pattern point `to`. New
// vertices take 3D positions interpolated in the triangle (or on the edge)
// they are inserted in; new triangles keep their parent's region. Throws
// std::invalid_argument when `from` is not a boundary vertex, `to` is not
// inside the sheet, or the segment leaves the sheet before reaching `to`.
CutResult cutAlong(mesh::SheetMesh& mesh, int from, const Vec2& to);

}  // namespace crumple::tear
