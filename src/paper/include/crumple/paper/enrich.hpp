#pragma once
// S_P, the physical triangle mesh built from S_G before each simulation step
// (paper Sec. 3.2 and Sec. 4 "Enriching the coarse mesh before simulation",
// Fig. 4; thesis 2.3.2). Flat regions are sampled isotropically (rho_bound
// along the sheet outline, rho_int inside) and triangulated by constrained
// Delaunay; curved-region quads are split at their barycenter; every S_G
// vertex is an S_P vertex with the same index.
#include <array>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/paper/geometric_mesh.hpp"
#include "crumple/paper/params.hpp"

namespace crumple::paper {

struct PhysicalMesh {
  // S_P. Vertex i < S_G vertex count IS S_G vertex i (same pattern and
  // position); added vertices follow. regionOfTriangle is the S_G region of
  // each triangle and regionTypes is copied from the S_G regions.
  mesh::SheetMesh mesh;
  // An added vertex is the affine combination sum_k weights[k] * (vertex k of
  // S_G face `face`), exact because the point lies in a planar flat-region
  // face or is a quad's barycenter. Unused slots (k >= face size) weigh 0.
  struct Sample {
    int face = -1;
    std::array<double, 4> weights{};
  };
  std::vector<Sample> samples;      // one per added vertex: mesh vertex (S_G count + k)
  std::vector<int> faceOfTriangle;  // S_G face holding each S_P triangle (its centroid)

  // Number of S_P vertices that are S_G vertices.
  std::size_t geometricVertexCount() const { return mesh.vertexCount() - samples.size(); }
};

// Builds S_P from S_G (paper Sec. 4 "Enriching the coarse mesh", thesis
// 2.3.2, Fig. 4). Flat regions are sampled as a whole: the region's S_G
// edges on the sheet outline (edges with a single face) are split evenly into
// ceil(length * rhoBound) pieces; interior samples come from a hexagonal
// lattice of spacing h = 1/sqrt(rhoInt) anchored at the pattern origin and
// are kept at least h/2 from the region border and from every S_G vertex;
// S_G vertices of the region (and unused S_G vertices inside it, e.g. a
// handle) are kept; the points are joined by constrained Delaunay with the
// region border as constraints. Edges between regions (flat/flat, rulings)
// are never split. Curved regions: triangles are copied, quads get a
// barycenter vertex and four triangles. The topology and pattern depend on
// S_G's pattern and faces only, so an unchanged S_G pattern gives the same
// S_P. Positions are set as by updateSamples. Throws std::invalid_argument
// on a face with an unknown region or when a flat region's border cannot be
// triangulated (crossing or touching border edges).
PhysicalMesh buildPhysicalMesh(const GeometricMesh& g, const CrumpleParams& params);

// Recomputes the S_P positions from S_G's current 3D state: S_G vertices are
// copied, added vertices interpolated with their sample weights (paper
// Sec. 4, Fig. 3 arrow (g)). With `velocities`, also writes one velocity per
// S_P vertex, interpolated the same way from the S_G vertex velocities.
// Throws std::invalid_argument when `g` has not the vertex count `p` was
// built from.
void updateSamples(PhysicalMesh& p, const GeometricMesh& g,
                   std::vector<Vec3>* velocities = nullptr);

// Bending-stiffness factor of every hinge of S_P (in `hinges` order):
// min(1, ((A1 + A2) / |e|^2) / ratio) from the hinge's two pattern triangles
// and its pattern length (two equilateral triangles give 0.87). The discrete
// hinge stiffness grows like |e|^2 / (A1 + A2) and its Hessian like
// 1 / height^3, so the long thin cells rulings make would stall Newton;
// below `ratio` (CrumpleParams::sliverHingeRatio) the hinge is softened in
// proportion. Boundary edges get 1.
std::vector<double> sliverHingeFactors(const mesh::SheetMesh& sp,
                                       const std::vector<mesh::MeshEdge>& hinges, double ratio);

}  // namespace crumple::paper
