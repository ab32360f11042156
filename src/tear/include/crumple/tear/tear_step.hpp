#pragma once
// The Griffith test of a frame's candidate tearing points (thesis 3.3.3,
// step 2 of Fig. 3.14, without the remeshing): for each candidate, its
// fracture energy E_f = C T_fibers(u, v) d_p, the two pulls of its
// triangles' forces, the energy release E_r and, when E_r >= E_f, where
// its tip goes: s + V E_r d_prop in the pattern.
#include <functional>
#include <vector>

#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/tear/candidates.hpp"
#include "crumple/tear/fiber_texture.hpp"
#include "crumple/tear/tip_pulls.hpp"

namespace crumple::tear {

struct TearParams {
  // C: the paper's general resistance (thesis 3.3.2: 0.005), in the units
  // of E_r, i.e. of the forces given. The pipeline gives the forces in units
  // of the paper's stretch stiffness times the mesh's mean edge length
  // (k_s h, the force of unit strain over one edge), so E_r is a
  // dimensionless, strain-like number independent of the mesh resolution
  // and C = 0.005 tears where the pull at a point reaches the force of half
  // a percent of strain (office paper breaks at 1.5-3 %).
  double resistance = 0.005;
  double tipDamage = 0.5;       // D in [0, 1]: d_p at a tear's tip (1 elsewhere)
  double speed = 1.0;           // V (m per unit of E_r): the tip advances V E_r per step
  double minInwardAngle = 0.1;  // rad: inward corners sharper than pi + this
};

struct CandidateTest {
  TearCandidate candidate;
  double fractureEnergy = 0.0;  // E_f (N)
  Propagation propagation;      // E_r, direction, angle
  bool tears = false;           // E_r >= E_f
  Vec2 next = Vec2::Zero();     // the next tip in the pattern (the point itself when not)
};

// The membrane forces of the triangles around a vertex (the elastic step's).
using VertexForces = std::function<std::vector<TriangleForce>(int vertex)>;

// Tests every candidate of the frame (tearCandidates with the given tips,
// junctions and held vertices), in vertex order. Candidates with no force
// (all their triangles unstrained) do not tear.
std::vector<CandidateTest> testCandidates(const mesh::SheetMesh& mesh, const FiberTexture& fibers,
                                          const std::vector<int>& tips,
                                          const std::vector<int>& junctions,
                                          const std::vector<char>& held, const VertexForces& forces,
                                          const TearParams& params);

}  // namespace crumple::tear
