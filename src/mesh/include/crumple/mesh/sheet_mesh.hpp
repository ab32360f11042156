#pragma once
// The sheet as a triangle mesh: every vertex has its 2D pattern (rest) position
// and its 3D position, every triangle its region (docs/ARCHITECTURE.md "Invariants everyone
// keeps"). For the elastic foundation the whole sheet is one region; the hybrid model (paper Sec.
// 3) assigns flat and curved regions later.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "crumple/core/state_io.hpp"
#include "crumple/core/types.hpp"

namespace crumple::mesh {

// Region kinds of S_G (paper Sec. 3, Fig. 4): flat regions and curved regions.
enum class RegionType : std::uint8_t { Flat = 0, Curved = 1 };

struct SheetMesh {
  std::vector<Vec2> pattern;                  // rest position in the flat pattern (m)
  std::vector<Vec3> positions;                // current 3D position (m)
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise in the pattern
  std::vector<int> regionOfTriangle;          // region id per triangle
  std::vector<RegionType> regionTypes;        // type per region id

  std::size_t vertexCount() const { return pattern.size(); }
  std::size_t triangleCount() const { return triangles.size(); }
};

// An undirected mesh edge with its one or two incident triangles.
// For an interior edge (a hinge), opposite[k] is the vertex of triangles[k]
// that is not on the edge; for a boundary edge triangles[1] == -1.
struct MeshEdge {
  std::array<int, 2> v{};          // v[0] < v[1]
  std::array<int, 2> triangles{};  // incident triangles, [1] == -1 on the boundary
  std::array<int, 2> opposite{};   // opposite vertices, [1] == -1 on the boundary
  bool interior() const { return triangles[1] >= 0; }
};

// All edges sorted by (v0, v1). Throws std::invalid_argument on a
// non-manifold edge (three or more triangles).
std::vector<MeshEdge> buildEdges(const SheetMesh& mesh);

// The boundary loops of the mesh's pattern: each a closed sequence of vertex
// indices along boundary edges, with the sheet on its left (counter-
// clockwise around the outline, clockwise around a hole). Loops start at
// their lowest vertex and are sorted by it. Throws std::invalid_argument for
// a boundary that is not a set of simple loops (a vertex where two loops
// touch).
std::vector<std::vector<int>> boundaryLoops(const SheetMesh& mesh);

// Checkpoint and resume: the whole mesh (pattern, positions,
// triangles, regions) in a state; restoreSheetMesh throws CorruptDataError
// for indices out of range or sizes that do not match.
void saveSheetMesh(StateWriter& out, const SheetMesh& mesh);
SheetMesh restoreSheetMesh(StateReader& in);

// A width x height rectangle in the pattern, [0,width] x [0,height], meshed as
// a regular grid whose cells are split into four triangles at their centre
// (an isotropic "criss-cross" pattern without a preferred diagonal). The cell
// size is the largest that is <= maxEdge and divides both sides evenly
// (rounding the cell count up). All four corners are vertices.
SheetMesh makeRectangleSheet(double width, double height, double maxEdge);

// A simple polygon (counter-clockwise, m) in the pattern, meshed for the
// simulation: every outline edge split evenly into pieces <= maxEdge,
// interior points on a hexagonal lattice of spacing maxEdge kept at least
// maxEdge / 2 from the outline, joined by constrained Delaunay. All outline
// points are vertices. Throws std::invalid_argument for fewer than 3
// points, a clockwise outline or a non-positive maxEdge.
SheetMesh makePolygonSheet(const std::vector<Vec2>& outline, double maxEdge);

// Place a flat pattern in 3D: position = origin + u * uAxis + v * vAxis.
void placePattern(SheetMesh& mesh, const Vec3& origin, const Vec3& uAxis, const Vec3& vAxis);

// Index of the vertex whose pattern position is nearest to p (lowest index on ties).
int nearestPatternVertex(const SheetMesh& mesh, const Vec2& p);
// The first triangle whose pattern holds p (its border included) and p's
// barycentric weights in it (corner order); triangle -1 when p is outside
// the pattern. Degenerate pattern triangles are skipped.
struct PatternLocation {
  int triangle = -1;
  Vec3 weights = Vec3::Zero();
};
PatternLocation locatePattern(const SheetMesh& mesh, const Vec2& p);
// Index of the vertex whose 3D position is nearest to p (lowest index on ties).
int nearestVertex(const SheetMesh& mesh, const Vec3& p);

// Vertices sharing an edge with v, sorted ascending.
std::vector<int> vertexNeighbours(const SheetMesh& mesh, int v);

// Structural checks: indices in range, no degenerate pattern triangle, finite
// coordinates, region arrays consistent. Returns an empty string when valid,
// else a description of the first problem.
std::string validate(const SheetMesh& mesh);

}  // namespace crumple::mesh
