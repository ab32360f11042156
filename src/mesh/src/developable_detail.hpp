#pragma once
// The refinement's inner steps (developable.hpp), shared by its three
// sources: developable_runs.cpp finds the S_G faces, the sheet's boundary
// curves and the runs; developable_fold.cpp cuts a run into sub-cells and
// folds them; developable_refine.cpp picks the densities, assembles the
// mesh and keeps the isometry guard.
#include <array>
#include <map>
#include <span>
#include <utility>
#include <vector>

#include "crumple/mesh/boundary_curve.hpp"
#include "crumple/mesh/developable.hpp"

namespace crumple::mesh::developable {

// An S_G face of a curved region, between rulings r0 = (a0, b0) and
// r1 = (a1, b1) (paper Sec. 3.2): a quad, or a fan where the rulings share
// an end.
struct Face {
  std::array<int, 2> r0{-1, -1}, r1{-1, -1};
  int fanSide = -1;            // 0: a0 == a1 (the apex), 1: b0 == b1, -1: a quad
  double orientation = 1.0;    // +1 when (a0, a1, b1, b0) runs counter-clockwise in the pattern
  std::vector<int> triangles;  // the source triangles covering it
  bool refinable = false;
};

// Consecutive refinable faces of one region whose inner rulings may move.
struct Run {
  std::vector<Face> faces;
};

// The sheet's boundary loops in the pattern, each with its 3D boundary
// curve (paper Sec. 6.2, cubic in the outline parameter).
class BoundaryCurves {
 public:
  BoundaryCurves(const SheetMesh& sheet, std::span<const char> breakVertex);
  // The 3D point at fraction t of the boundary edge from vertex a to b (the
  // edge's ends exactly at t = 0 and 1); the straight line when a-b is not a
  // boundary edge.
  Vec3 sidePoint(const SheetMesh& sheet, int a, int b, double t) const;
  bool isBoundaryEdge(int a, int b) const;

 private:
  struct EdgeOnLoop {
    int loop = -1;
    double s0 = 0.0, length = 0.0;  // outline parameter of its start, its pattern length
  };
  std::map<std::pair<int, int>, EdgeOnLoop> edges_;  // directed as the loop runs
  std::vector<BoundaryCurve> curves_;
};

// Per vertex: the triangles using it.
std::vector<std::vector<int>> trianglesOfVertices(const SheetMesh& sheet);

// The faces of a curved region, in ruling order, each with its source
// triangles and whether it can be refined (both non-ruling sides on the
// sheet's boundary, no locked triangle, the source triangles a quad's
// barycentre fan or the fan triangle itself).
std::vector<Face> regionFaces(const SheetMesh& sheet, const CurvedRegion& region,
                              const std::vector<int>& regionTriangles,
                              const BoundaryCurves& boundary, std::span<const char> lockedTriangle);

// The runs of a region's faces: maximal sequences of at least two
// refinable faces of one kind whose inner rulings have free ends (not
// pinned, used by no triangle beyond the two faces beside them).
std::vector<Run> regionRuns(const std::vector<Face>& faces,
                            const std::vector<std::vector<int>>& trianglesOfVertex,
                            std::span<const char> pinnedVertex);

// One sub-ruling of a run: its ends in the pattern, their 3D positions, and
// the source vertex of each end (an S_G ruling's ends; -1 for a new vertex).
struct SubRuling {
  Vec2 pa = Vec2::Zero(), pb = Vec2::Zero();
  Vec3 xa = Vec3::Zero(), xb = Vec3::Zero();
  int va = -1, vb = -1;
  int face = 0;  // the face of the run it starts (the last sub-ruling: the last face)
};

// The sub-rulings of a run with cells[k] sub-cells in face k, their 3D ends
// on the naive surface: ends on the paper's cubic boundary curve, S_G
// ruling ends where S_P has them.
std::vector<SubRuling> subRulings(const SheetMesh& sheet, const Run& run,
                                  std::span<const int> cells, const BoundaryCurves& boundary);

// Signed fold angles of a strip of sub-rulings at its inner sub-rulings
// 1 .. M - 1 (rad; the dihedral between the sub-cells beside each, about
// the sub-ruling from its a end to its b end).
std::vector<double> foldAngles(std::span<const SubRuling> strip);

// The isometric strip (paper Sec. 3.2: generalized cones joined by common
// rulings): rigid pattern cells folded about the sub-rulings, started on
// S_P's first ruling in the first naive cell's plane, the angles corrected
// (minimum-norm Levenberg-Marquardt, a fixed number of steps) so that the
// last ruling lands on S_P's, what is left blended linearly along the run.
// Rewrites xa, xb of the inner sub-rulings; returns the closure error left
// to the blend (m).
struct FoldResult {
  double closure = 0.0;
  double largestFold = 0.0;  // rad, after the correction
  std::vector<double> angles;
};
FoldResult foldStrip(std::vector<SubRuling>& strip);

}  // namespace crumple::mesh::developable
