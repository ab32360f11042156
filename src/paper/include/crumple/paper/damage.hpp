#pragma once
// Fiber damage around singular vertices (paper Sec. 4 "Modeling fiber
// damage", eq. (1); thesis 2.3.3, eqs. (2.1)-(2.2)).
#include <vector>

#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/paper/params.hpp"

namespace crumple::paper {

struct HingeDamage {
  double restAngle = 0.0;        // theta_rest of the hinge (rad, signed like the hinge angle)
  double stiffnessFactor = 1.0;  // 1 / (1 + d)
};

// For every hinge (interior edge (i, j) of S_P, in `hinges` order):
// theta_i = thetaRest / N_i and d_i = D / N_i when vertex i is singular
// (N_i: the number of edges around i), 0 otherwise; the hinge gets the rest
// angle theta_i + theta_j and the bending stiffness factor 1 / (1 + d_i + d_j).
// The rest angle takes the sign of the hinge's current angle (the way the
// paper is folded there; + when it is flat), so the damaged sheet keeps the
// fold it has rather than flipping it.
std::vector<HingeDamage> fiberDamage(const mesh::SheetMesh& sp,
                                     const std::vector<mesh::MeshEdge>& hinges,
                                     const std::vector<char>& singular,
                                     const std::vector<double>& hingeAngles,
                                     const CrumpleParams& params);

}  // namespace crumple::paper
