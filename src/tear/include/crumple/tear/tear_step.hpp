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
#include "crumple/tear/params.hpp"
#include "crumple/tear/tip_pulls.hpp"

namespace crumple::tear {

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
