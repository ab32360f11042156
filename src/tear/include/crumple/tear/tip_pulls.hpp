#pragma once
// The two pulls at a candidate tearing point, in the pattern (thesis 3.3.3):
// the elastic step's membrane force of each triangle around the point,
// clustered in 3D into F_left and F_right (clusterTipForces) starting from
// the tear direction, and mapped to the pattern through each triangle's
// deformation (the forces are in-plane: a force f on triangle t maps to
// (F^T F)^-1 F^T f, F the 3 x 2 deformation gradient of t).
#include <vector>

#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/tear/griffith.hpp"

namespace crumple::tear {

struct TriangleForce {
  int triangle = -1;
  Vec3 force = Vec3::Zero();
};

struct TipPulls {
  Vec2 left = Vec2::Zero();           // in the pattern (N)
  Vec2 right = Vec2::Zero();          // in the pattern (N)
  ForceClusters clusters;             // in 3D
  Vec2 tearDirection = Vec2::Zero();  // the first guess, in the pattern (unit)
};

// The direction a tear would take from boundary vertex v with nothing else
// known: the bisector of the boundary's directions on either side of v,
// pointing into the sheet (thesis Fig. 3.17; at a tear's tip, of its lips).
// Each direction runs to the first boundary vertex at least the mean length
// of v's edges away along the boundary. Throws std::invalid_argument
// when v is not on the boundary.
Vec2 boundaryBisector(const mesh::SheetMesh& mesh, int vertex);

// The pulls at `vertex` from the forces of its triangles (`forces`, each
// triangle holding the vertex), with `tearDirection` (pattern, non-zero) as
// the clustering's first guess. Only forces that draw the vertex back
// against the tear direction (in the pattern) are pulls: the forces of the
// material ahead, which holds the vertex against them, are left out (at a
// free vertex in equilibrium all the forces sum to zero, and two clusters
// of all of them would always be opposite: theta = pi, no release). The
// surface normal at the vertex is the area-weighted normal of the
// triangles. No pull: both zero, clusters empty.
TipPulls tipPulls(const mesh::SheetMesh& mesh, int vertex, const std::vector<TriangleForce>& forces,
                  const Vec2& tearDirection);

}  // namespace crumple::tear
