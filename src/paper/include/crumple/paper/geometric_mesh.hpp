#pragma once
// S_G, the geometric layer of the hybrid model (paper Sec. 3.2, Fig. 2):
// a coarse polygon mesh of the sheet whose faces belong either to flat
// regions (triangles whose corners are singular, junction, handle or
// boundary vertices) or to curved regions (strips of rulings: quads between
// two boundary vertices, or triangles fanning from a singular apex). Every
// vertex has its pattern (2D rest) position and its 3D position.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/mesh/sheet_mesh.hpp"

namespace crumple::paper {

struct GeometricVertex {
  Vec2 pattern = Vec2::Zero();   // position in the pattern (m)
  Vec3 position = Vec3::Zero();  // position in the world (m)
  Vec3 velocity = Vec3::Zero();  // carried between elastic steps (m/s)
  bool onBoundary = false;       // lies on the sheet outline dS
  bool corner = false;           // a corner of the outline (never moves)
  bool singular = false;         // permanent singular point, a d-cone apex (paper Sec. 5.2)
  bool handle = false;           // pinned by a handle rig: never moves in the pattern
  int outlineSegment = -1;       // onBoundary: outline segment i (corner i -> i+1) holding it
};

// An S_G face: a triangle, or a quad of a curved region (v[3] >= 0).
// Counter-clockwise in the pattern.
struct GeometricFace {
  std::array<int, 4> v{-1, -1, -1, -1};
  int region = -1;
  int size() const { return v[3] < 0 ? 3 : 4; }
  friend bool operator==(const GeometricFace&, const GeometricFace&) = default;
};

// A ruling of a curved region: the S_G edge (a, b), straight on the surface
// (paper Sec. 3.2, R_C).
struct Ruling {
  int a = -1;
  int b = -1;
};

struct Region {
  mesh::RegionType type = mesh::RegionType::Flat;
  // Curved regions: the ordered rulings r_0..r_n. Face k of the region lies
  // between r_k and r_{k+1} (a quad, or a triangle when they share a vertex).
  std::vector<Ruling> rulings;
  int apex = -1;  // curved: the singular vertex all rulings pass through, else -1
};

struct GeometricMesh {
  std::vector<GeometricVertex> vertices;
  std::vector<GeometricFace> faces;
  std::vector<Region> regions;
  std::vector<Vec2> outline;  // the sheet outline dS in the pattern, CCW corners

  std::size_t vertexCount() const { return vertices.size(); }
  std::size_t faceCount() const { return faces.size(); }
};

// An undirected S_G edge and its one or two faces (faces[1] == -1 on dS).
struct GeometricEdge {
  std::array<int, 2> v{};      // v[0] < v[1]
  std::array<int, 2> faces{};  // incident faces
  bool interior() const { return faces[1] >= 0; }
};

// All edges of S_G sorted by (v0, v1). Throws std::invalid_argument when an
// edge has more than two faces.
std::vector<GeometricEdge> buildEdges(const GeometricMesh& g);

// Unit normal of a face in 3D (a quad uses the cross product of its
// diagonals, so a non-planar quad gets its mean normal).
Vec3 faceNormal(const GeometricMesh& g, int face);

// Unsigned angle between the normals of two faces (rad), the dihedral angle
// the paper compares against theta_0 (Sec. 5.1).
double dihedralAngle(const GeometricMesh& g, int faceA, int faceB);

// Signed pattern area of a face (> 0 when counter-clockwise).
double patternArea(const GeometricMesh& g, int face);

// Area enclosed by the outline.
double outlineArea(const GeometricMesh& g);

// Outline parameter: arc length along dS from corner 0, counter-clockwise,
// in [0, perimeter). outlinePoint is its inverse.
double outlinePerimeter(const GeometricMesh& g);
double outlineParameter(const GeometricMesh& g, const Vec2& p, int segment);
Vec2 outlinePoint(const GeometricMesh& g, double s, int* segment = nullptr);

// Editing primitives for the remeshing steps.
// Appends a vertex and returns its index.
int addVertex(GeometricMesh& g, const GeometricVertex& v);
// Replaces the faces of curved region `region` by the faces between its
// consecutive rulings (a quad, or a triangle where two rulings share a
// vertex), oriented counter-clockwise in the pattern.
void rebuildCurvedFaces(GeometricMesh& g, int region);
// Removes the faces of a region (the region entry stays, empty).
void removeRegionFaces(GeometricMesh& g, int region);
// Drops regions without faces and vertices no face uses (singular and
// handle vertices are always kept), renumbering both. Returns the vertex
// map old -> new (-1 for a removed vertex).
std::vector<int> compact(GeometricMesh& g);

// Junction vertices (paper Sec. 6.1): vertices on dS where a curved region
// and another region meet. Sorted.
std::vector<int> junctionVertices(const GeometricMesh& g);

// Region invariants ("in debug builds"): indices in range, faces
// counter-clockwise and non-degenerate in the pattern, the faces cover the
// outline exactly (area sum equal within 1e-9 relative), boundary vertices
// on their outline segment, curved-region faces consistent with their
// rulings, flat regions planar within `planarityTolerance` (rad; < 0 skips
// the check). Returns "" when valid, else the first problem found.
std::string validate(const GeometricMesh& g, double planarityTolerance = -1.0);

}  // namespace crumple::paper
