#pragma once
// Cutting the sheet's mesh along a tear's advance (thesis 3.3.3,
// "Remeshing", the part that concerns the simulated mesh): the segment from
// the tip s_t (a boundary vertex) to the next tip s_{t+1} (a pattern point
// inside the sheet) becomes a chain of mesh edges (the triangles it crosses
// are split where it crosses them, s_{t+1} is inserted), and every chain
// vertex but the new tip is doubled: one copy for each lip. The pattern is
// unchanged as a point set; no triangle crosses the cut.
#include <array>
#include <utility>
#include <vector>

#include "crumple/mesh/sheet_mesh.hpp"

namespace crumple::tear {

// A vertex the cut added, as an affine combination of vertices of the mesh
// before it (unused slots: vertex -1, weight 0): what carries per-vertex
// state (velocities) over the cut.
struct VertexBlend {
  std::array<int, 3> vertex{-1, -1, -1};
  std::array<double, 3> weight{};
};

// The blend sum_k w_k vertex_k of the given terms, merged by vertex; more
// than three vertices keep the three heaviest, renormalised to sum 1 (an
// approximation, for per-vertex state such as velocities).
VertexBlend makeBlend(std::vector<std::pair<int, double>> terms);

struct CutOptions {
  // Fraction of an edge (in [0, 0.5)): a crossing nearer than this to one of
  // the edge's ends goes through that end, and s_{t+1} nearer than this (in
  // barycentric weight) to a vertex or an edge moves onto it, so that the
  // cut leaves no sliver triangles; the vertex it snaps to then moves onto
  // the exact point (the cut line or s_{t+1}) when it may: an interior
  // vertex, not `fixed`, whose triangles keep half their area and no angle
  // below 15 degrees.
  // 0 = cut exactly.
  double snap = 0.0;
  const std::vector<char>* fixed = nullptr;  // per vertex: != 0 never moves (held vertices)
};

struct CutResult {
  int tip = -1;            // the vertex at s_{t+1} (an existing one when it is there already)
  std::vector<int> chain;  // the cut's vertices from s_t to s_{t+1} (right lip's copies)
  // Their left lip's copies: chain.size() - 1 (the tip is shared), or
  // chain.size() when the cut went through to the boundary.
  std::vector<int> twins;
  bool separated = false;  // the cut reached the boundary: no tip is left
  // One per vertex the cut appended (vertex index = old count + k).
  std::vector<VertexBlend> blends;
  // Vertices from before the cut that moved (pattern and 3D) onto the cut,
  // with their new place as a blend of the mesh before the cut.
  std::vector<std::pair<int, VertexBlend>> relocated;
};

// Cuts `mesh` from boundary vertex `from` to pattern point `to`. The cut
// stops where it first meets the boundary again (CutResult::separated).
// Existing vertex indices are kept and new vertices appended; new vertices
// take 3D positions interpolated in the triangle (or on the edge) they are
// inserted in; new triangles keep their parent's region. A cut that snaps
// back onto `from` changes nothing (chain == {from}). Throws
// std::invalid_argument when `from` is not a boundary vertex, `to` is not
// inside the sheet, or the segment leaves the sheet at `from`.
CutResult cutAlong(mesh::SheetMesh& mesh, int from, const Vec2& to, const CutOptions& options = {});

}  // namespace crumple::tear
