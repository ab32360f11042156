#pragma once
// Parameters of the elastic step (ElasticSheet), header-only: the scene's
// [sim] table fills them (io), the simulator runs them. The paper's material
// is sim::Material (material.hpp).
#include <optional>

#include "crumple/core/types.hpp"
#include "crumple/sim/air_params.hpp"

namespace crumple::sim {

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
  // Recovery of a step that failed at every halving (docs/STABILITY.md;
  // ElasticSheet::advance): taken again without self-contact, then with
  // kRetryIterationFactor times maxNewtonIterations. Off by default; a shot
  // (pipeline::runShot) turns it on.
  bool recoverFailedSteps = false;
  // The air (docs/AIR.md): none unless the scene has [air].
  std::optional<AirParams> air;

  bool operator==(const SimParams&) const = default;
};

}  // namespace crumple::sim
