#pragma once
// The geometric step on S_G (paper Sec. 5-6.1; thesis 2.4-2.5.1, Algorithm 1):
// edge flips and splits of flat regions, compression analysis, ruling
// propagation with singular-vertex insertion, junction points.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "crumple/core/rng.hpp"
#include "crumple/paper/geometric_mesh.hpp"
#include "crumple/paper/params.hpp"

namespace crumple::paper {

// Whether the faces of a region may be remeshed for compression in this
// step (nullptr: all may). The hybrid sheet lets a region settle for a few
// elastic steps after it was cut (HybridSheet, CrumpleParams::remeshCooldown).
using FaceFilter = std::function<bool(int face)>;

// 3D position of the sheet outline at outline parameter s (arc length from
// corner 0, see outlineParameter): the boundary curve of S_P the new ruling
// endpoints are placed on (paper Appendix B: "cubic interpolation along the
// boundary curve given by the mesh S_P").
using BoundaryPosition = std::function<Vec3(double s)>;

// What one geometric step did (counts), for logs, tests and the cache.
struct GeometricStepStats {
  int edgeFlips = 0;
  int flatSplits = 0;           // flat regions split along an edge above theta_0
  int curvedCreated = 0;        // curved regions created from compressed flat regions
  int curvedBent = 0;           // of them, flat regions bent along a fold (bendFoldedFlatRegions)
  int singularInserted = 0;     // new singular vertices (paper Sec. 5.2)
  int singularInCurved = 0;     // of them, on a compressed ruling (treatCurvedCompression)
  int creases = 0;              // degenerate curved regions between two singular vertices
  int junctionMoves = 0;        // junction points moved (paper Sec. 6.1)
  int curvedFlattened = 0;      // curved regions turned back into flat regions
  double maxCompression = 0.0;  // largest triangle compression ratio seen in flat regions
  std::vector<Vec2> cuts;       // pattern points where compression was treated (for the cooldown)
  std::vector<std::string> notes;  // remeshing that was attempted and declined, and why
};

// thesis 2.4.1: flips an edge between two triangles of one flat region when
// it is compressed by more than eps_c and the other diagonal of their
// (convex) quad is not. Returns the number of flips.
int flipCompressedEdges(GeometricMesh& g, const CrumpleParams& params);

// Before splitting a non-planar flat region (splitFlatRegions), its most
// folded interior edge is offered to the ruling machinery as a strip of
// rulings parallel to that edge (S_P bends smoothly across S_G's internal
// edges; see docs/CRUMPLING.md). Returns the number of regions bent.
// With `sp` (S_P with its positions after the elastic step), the rulings
// follow how S_P actually bends inside the region instead: parallel to the
// principal direction of sum theta^2 e e^T over S_P's hinges there (the
// direction S_P bends across), through its most bent hinge. A twisting or
// rolling sheet folds S_G's few triangles along edges that are not rulings
// (the diagonal of a strip), which would otherwise make a crease.
int bendFoldedFlatRegions(GeometricMesh& g, const CrumpleParams& params,
                          const BoundaryPosition& boundary, GeometricStepStats& stats,
                          const mesh::SheetMesh* sp = nullptr);

// paper Sec. 5.1: a flat region is a maximal connected set of pairwise
// coplanar triangles (dihedral <= theta_0). Relabels flat faces into such
// sets; returns how many regions were split.
int splitFlatRegions(GeometricMesh& g, const CrumpleParams& params);

// paper Sec. 5.1 (a)-(c), 5.2, Appendices A-B: for each flat region whose
// most compressed triangle exceeds eps_c, propagates imaginary rulings along
// the direction of minimal compression, inserts singular vertices where they
// meet constrained borders, and remeshes the region into a curved region of
// parallel or conical rulings plus the flat remainder. `rng` draws singular
// vertex positions (law exp(-d^2/sigma^2)); `drawIndex` is advanced for each
// number drawn so results are reproducible.
void treatCompression(GeometricMesh& g, const CrumpleParams& params,
                      const BoundaryPosition& boundary, const CounterRng& rng,
                      std::uint64_t& drawIndex, GeometricStepStats& stats,
                      const FaceFilter& mayRemesh = nullptr);

// Beyond the paper (its Sec. 7.4 limitation "pressure applied inside a
// curved area"): a curved region whose ruling is compressed by more than
// eps_c gets a singular vertex on it, drawn with the law of Sec. 5.2, and is
// remeshed around it as in Fig. 11 on both sides (fans to the nearest rulings
// above theta_0, flat transition triangles). See docs/CRUMPLING.md.
void treatCurvedCompression(GeometricMesh& g, const CrumpleParams& params, const CounterRng& rng,
                            std::uint64_t& drawIndex, GeometricStepStats& stats,
                            const FaceFilter& mayRemesh = nullptr);

// paper Sec. 6.1, thesis 2.5.1: moves junction points between curved and
// flat regions with the hysteresis theta_low / theta_high (and the
// opposite-region rule of Fig. 13), and turns curved regions whose rulings
// are all below theta_low back into flat regions.
void updateJunctions(GeometricMesh& g, const CrumpleParams& params,
                     const BoundaryPosition& boundary, GeometricStepStats& stats);

// Dihedral angle at ruling k of a curved region: between the faces on both
// sides of it (or between the region's end face and the neighbouring face
// of another region for k = 0 and k = n); 0 on the sheet boundary.
double rulingDihedral(const GeometricMesh& g, int region, int k);

}  // namespace crumple::paper
