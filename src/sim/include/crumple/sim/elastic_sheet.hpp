#pragma once
// Elastic sheet simulation (paper Sec. 4; thesis 2.3.1): StVK membrane energy
// from the Green strain, discrete bending on dihedral angles with per-hinge
// rest angle and stiffness factor (Bridson et al. 2003, Grinspun et al. 2003),
// gravity, Rayleigh damping, backward Euler solved by Newton iterations with a
// line search, sparse Cholesky solves through CHOLMOD (symbolic analysis kept
// while the topology is unchanged), handle vertices as hard constraints.
#include <functional>
#include <memory>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/sim/material.hpp"

namespace crumple::sim {

class ColliderSet;

struct SimParams {
  Vec3 gravity{0.0, -9.81, 0.0};  // m/s^2
  double massDamping = 0.5;       // 1/s  (Rayleigh alpha: force -alpha M v)
  double stiffnessDamping = 0.0;  // s    (Rayleigh beta:  force -beta K v)
  int maxNewtonIterations = 30;
  // Converged when the max norm of the Newton step is below
  // newtonTolerance * (typical edge length) -- see docs/ARCHITECTURE.md.
  double newtonTolerance = 1e-7;
  int maxHalvings = 8;  // a failed substep is split in two at most this deep
  // Multiplies the membrane (stretch) moduli. 1 = the paper's real in-plane
  // stiffness. The hybrid crumpling model lowers it: its coarse FEM "only
  // needs stiffness of medium range" since lengths are restored geometrically
  // (paper Sec. 1 and Sec. 6.3).
  double membraneScale = 1.0;
  // Every vertex weighs at least this fraction of the mean vertex mass (0 =
  // the lumped masses as they are). The hybrid model's remeshing can leave
  // sliver triangles whose vertices would weigh ~1e-4 of the others and stall
  // Newton's convergence; the floor adds a negligible mass there.
  double minVertexMassFraction = 0.0;
};

// A hard constraint: vertex `vertex` sits at `position`.
struct Pin {
  int vertex = -1;
  Vec3 position = Vec3::Zero();
};
// Pin positions at any time t (s); the integrator asks for t + dt of each
// (sub)step it takes, so halved substeps follow the handle curves exactly.
using PinFunction = std::function<void(double t, std::vector<Pin>& out)>;

struct StepStats {
  int newtonIterations = 0;  // summed over the (sub)steps taken
  int halvings = 0;          // how many times a step was split
  int solves = 0;            // Cholesky factorisations
  double finalStepNorm = 0.0;
  double contactMs = 0.0;  // wall time of contact detection and the failsafe (timing only)
};

class ElasticSheet {
 public:
  // Rest state = the mesh's pattern; initial state = its positions, zero velocity.
  ElasticSheet(const mesh::SheetMesh& mesh, const Material& material, const SimParams& params);
  ~ElasticSheet();
  ElasticSheet(ElasticSheet&&) noexcept;
  ElasticSheet& operator=(ElasticSheet&&) noexcept;

  // Interior edges (hinges) of the mesh, in mesh::buildEdges order.
  const std::vector<mesh::MeshEdge>& hinges() const;
  // Bending rest angle (rad, signed as the dihedral angle) and stiffness
  // factor (>= 0, default 1) of a hinge; the crumpling model sets them.
  void setHingeRestAngle(std::size_t hinge, double angle);
  void setHingeStiffnessFactor(std::size_t hinge, double factor);

  // Advance from time t to t + dt. Pinned vertices move to pins(t + dt) with
  // velocity (x(t+dt) - x(t)) / dt. A Newton solve that fails (factorisation
  // failure, non-finite values, no convergence) restarts the step as two
  // halves, down to params.maxHalvings; after that throws NumericalError
  // (stage "elastic") and leaves the state as it was before the call.
  StepStats advance(double t, double dt, const PinFunction& pins);

  // Contacts (issue 5): free vertices keep `contactDistance` (m, > 0; the
  // paper's thickness) from every collider of the set: a penalty on frozen
  // tangent planes in the implicit step, then a projection failsafe, so that
  // no free vertex ends a step nearer than contactDistance. The set is not
  // owned and must outlive the sheet or the next call; the caller moves
  // animated colliders before each advance(). nullptr switches contacts off
  // (the default: a scene without colliders pays nothing).
  void setColliders(const ColliderSet* colliders, double contactDistance);
  // Vertex-steps with a contact plane since construction (statistics).
  long contactVertexSteps() const;

  const std::vector<Vec3>& positions() const;
  const std::vector<Vec3>& velocities() const;
  void setPositions(const std::vector<Vec3>& x);
  void setVelocities(const std::vector<Vec3>& v);

  double kineticEnergy() const;   // J
  double membraneEnergy() const;  // J
  double bendingEnergy() const;   // J
  // Max over triangles of the largest absolute principal Green strain.
  double maxMembraneStrain() const;

  // Additions beyond the original interface (diagnostics and tests).
  double hingeRestAngle(std::size_t hinge) const;
  double hingeStiffnessFactor(std::size_t hinge) const;
  // Current signed dihedral angle of a hinge (rad; see sim/energies.hpp for
  // the sign convention: > 0 when the hinge is convex on the normal side).
  double hingeAngle(std::size_t hinge) const;
  // How many times CHOLMOD's symbolic analysis ran (once per pin set).
  int analyzeCount() const;
  // True when the system is large enough for CHOLMOD's supernodal LL^T
  // (simplicial below ~3000 free DOFs).
  bool supernodalFactorization() const;
  // Mean pattern edge length (m): the length scale of newtonTolerance.
  double typicalEdgeLength() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crumple::sim
