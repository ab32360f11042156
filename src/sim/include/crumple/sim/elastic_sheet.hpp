#pragma once
// Elastic sheet simulation (paper Sec. 4; thesis 2.3.1): StVK membrane energy
// from the Green strain, discrete bending on dihedral angles with per-hinge
// rest angle and stiffness factor (Bridson et al. 2003, Grinspun et al. 2003),
// gravity, Rayleigh damping, backward Euler solved by Newton iterations with a
// line search, sparse Cholesky solves through CHOLMOD (symbolic analysis kept
// while the topology is unchanged), handle vertices as hard constraints.
#include <array>
#include <functional>
#include <memory>
#include <vector>

#include "crumple/core/state_io.hpp"
#include "crumple/core/types.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/sim/material.hpp"
#include "crumple/sim/params.hpp"

namespace crumple::sim {

class ColliderSet;

// A hard constraint: vertex `vertex` sits at `position`.
struct Pin {
  int vertex = -1;
  Vec3 position = Vec3::Zero();
};
// Pin positions at any time t (s); the integrator asks for t + dt of each
// (sub)step it takes, so halved substeps follow the handle curves exactly.
using PinFunction = std::function<void(double t, std::vector<Pin>& out)>;

// A soft hold: a finger's contact patch rather than a pinned vertex (paper
// Sec. 4's tangent-plane control spread over an area). The point of
// `triangle` at barycentric `weights` is drawn to `position` by a
// zero-length spring of `stiffness` (N/m): energy k/2 |sum_a w_a x_a - p|^2
// (gripEnergy). `anchor` is the pinned vertex (the handle) whose lag the
// grip follows in a model that lets handles lag (-1: none).
struct Grip {
  int triangle = -1;
  Vec3 weights = Vec3::Zero();
  Vec3 position = Vec3::Zero();
  double stiffness = 0.0;
  int anchor = -1;
};
// Grips at any time t (s), asked for the end time of every (sub)step as the pins are.
using GripFunction = std::function<void(double t, std::vector<Grip>& out)>;

struct StepStats {
  int newtonIterations = 0;  // summed over the (sub)steps taken
  int halvings = 0;          // how many times a step was split
  int solves = 0;            // Cholesky factorisations
  double finalStepNorm = 0.0;
  double contactMs = 0.0;      // collider detection and failsafe, wall time (timing only)
  double selfContactMs = 0.0;  // self-contact gate, detection and failsafe (timing only)
  int selfContactSteps = 0;    // (sub)steps in which self-contact detection ran
  double airMs = 0.0;          // the air's set-up per (sub)step, wall time (timing only)
  // Recovery of a step that failed even after halving (docs/STABILITY.md):
  // taken again with kRetryIterationFactor times the Newton iterations, or
  // else without self-contact (the sheet may pass through itself there).
  int newtonRetried = 0;
  int selfContactDropped = 0;
};
inline constexpr int kRetryIterationFactor = 10;

// The contact failsafe projection acts on vertices the penalty left more
// than this fraction of the contact distance too near (a penalty equilibrium
// is left alone: its gap carries the normal force that friction needs).
inline constexpr double kContactFailsafeSlack = 0.05;

// Self-contact of the sheet (docs/CONTACTS.md): never, at every step, or only while
// the sheet is folded (sheetIsFolded with ContactOptions::foldSpread).
enum class SelfContactMode { Off, On, Auto };

// Contacts of the elastic step (paper Sec. 4; docs/CONTACTS.md).
struct ContactOptions {
  // Colliders the free vertices keep `distance` from (not owned; must
  // outlive the sheet or the next setContacts). Null or empty: none.
  const ColliderSet* colliders = nullptr;
  // Moves animated colliders to time t. Called with the start and then the
  // end time of every (sub)step taken, halved ones included, so the
  // colliders are where the step ends and remember where it began
  // (ColliderSet::surfaceDisplacement, friction on moving surfaces). Empty:
  // the colliders do not move.
  std::function<void(double t)> moveColliders;
  double distance = 0.0;  // contact distance (m, > 0): the paper's thickness
  SelfContactMode self = SelfContactMode::Off;
  double selfFriction = 0.3;               // Coulomb coefficient of paper on paper
  double foldSpread = 1.0471975511965976;  // rad (60 deg): the Auto gate
};

// A vertex touching something at the end of a step (docs/CONTACTS.md: what
// the sound module hears).
struct ContactSample {
  int vertex = -1;
  int collider = -1;         // ColliderSet index, or -1 for the sheet itself
  double slideSpeed = 0.0;   // m/s, tangential, relative to the touched surface
  double normalForce = 0.0;  // N, the contact's penalty force
};

// Checkpoint and resume (docs/CHECKPOINT.md): a list of contact samples in a state.
// restoreContactSamples throws CorruptDataError for a vertex outside
// [0, vertexCount).
void saveContactSamples(StateWriter& out, const std::vector<ContactSample>& samples);
std::vector<ContactSample> restoreContactSamples(StateReader& in, std::size_t vertexCount);

// The contact failsafe on its own, for a caller that moves vertices after
// the elastic step (the crumpling model's isometry projection): free
// vertices (held[v] == 0) nearer than (1 - kContactFailsafeSlack) distance
// to a collider move out to the distance along its normal; faces a
// collider probe came that near move out with their free vertices; and,
// when self-contact runs for this sheet (On, or Auto and folded), vertices
// that near to another layer move out along the pair's normal. Adds the
// wall time of the collider and the self-contact parts (ms) when given.
void projectOutOfContacts(const ContactOptions& options,
                          const std::vector<std::array<int, 3>>& triangles,
                          const std::vector<Vec2>& pattern, const std::vector<char>& held,
                          std::vector<Vec3>& x, double* collidersMs = nullptr,
                          double* selfMs = nullptr);

// Sorts contact samples by (vertex, collider) and merges the samples of one
// pair: forces summed, the fastest slide.
void mergeContactSamples(std::vector<ContactSample>& samples);

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
  // Grips every step from now on holds (none by default). A step throws
  // std::out_of_range for a grip on a missing triangle; a grip with a
  // non-finite or negative value fails the substep like a non-finite pin.
  void setGrips(GripFunction grips);

  // Contacts (docs/CONTACTS.md): free vertices keep options.distance from every
  // collider and, with self-contact, from the triangles of other layers of
  // the sheet: a penalty on tangent planes frozen at the start of the step
  // (each layer sees the other where its velocity carries it), Coulomb
  // friction relative to the touched surface, then a projection failsafe,
  // so that no free vertex ends a step nearer than 0.95 distance. Without
  // colliders and with self-contact off (the default) a step does no contact
  // work at all. Throws std::invalid_argument for a distance <= 0 when any
  // contact is on, or a negative friction.
  void setContacts(ContactOptions options);
  // Vertex-steps with a contact plane since construction (statistics).
  long contactVertexSteps() const;
  // The contacts at the end of the last accepted (sub)step, sorted by
  // (vertex, collider), one per pair (forces summed, the fastest slide).
  const std::vector<ContactSample>& contacts() const;
  // Checkpoint and resume (docs/CHECKPOINT.md): what the sheet carries from one step to
  // the next (positions, velocities, each hinge's rest angle, stiffness
  // factor and branch, the last step's contacts), written for a sheet built
  // again on the same mesh. restoreState throws CorruptDataError when the
  // state does not fit this sheet's mesh.
  void saveState(StateWriter& out) const;
  void restoreState(StateReader& in);

  const std::vector<Vec3>& positions() const;
  const std::vector<Vec3>& velocities() const;
  void setPositions(const std::vector<Vec3>& x);
  void setVelocities(const std::vector<Vec3>& v);

  double kineticEnergy() const;   // J
  double membraneEnergy() const;  // J
  double bendingEnergy() const;   // J
  // Max over triangles of the largest absolute principal Green strain.
  double maxMembraneStrain() const;
  // The sheet's in-plane stiffness (lambda + 2 mu) h as this sheet runs it
  // (N/m): Material::stretchStiffness times SimParams::membraneScale. A
  // grip as firm as the sheet itself has this stiffness.
  double inPlaneStiffness() const;

  // The membrane (Green strain) force each triangle around `vertex` exerts
  // on it at the current positions: minus the gradient of that triangle's
  // membrane energy with respect to the vertex (N). What a tear tip feels
  // from the elastic step (thesis 3.3.3); bending forces, orders of
  // magnitude weaker, are left out as there. Sorted by triangle.
  struct TriangleForce {
    int triangle = -1;
    Vec3 force = Vec3::Zero();
  };
  std::vector<TriangleForce> membraneForcesOn(int vertex) const;

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
