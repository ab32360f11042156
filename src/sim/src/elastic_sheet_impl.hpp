#pragma once
// Internal to src/sim (not installed): ElasticSheet's state and the helpers
// its parts share (elastic_sheet.cpp: set-up and element terms;
// elastic_newton.cpp: the backward Euler step; elastic_contacts.cpp: the
// contacts; docs/ARCHITECTURE.md).
#include <dlfcn.h>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <numbers>
#include <numeric>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include "crumple/core/error.hpp"
#include "crumple/core/parallel.hpp"
#include "crumple/sim/air.hpp"
#include "crumple/sim/colliders.hpp"
#include "crumple/sim/contact_energies.hpp"
#include "crumple/sim/elastic_sheet.hpp"
#include "crumple/sim/energies.hpp"
#include "crumple/sim/self_contact.hpp"

namespace crumple::sim {
// Internal linkage: each of the three sources gets its own copy.
namespace {

// Element scatter/gather shared by triangles (N = 3, membrane) and hinges
// (N = 4, bending). Elements are visited in index order, so sums are
// bit-identical whatever the thread count that computed the element terms.
template <std::size_t N>
using ElementVec = Eigen::Matrix<double, 3 * static_cast<int>(N), 1>;
template <std::size_t N>
using ElementMat = Eigen::Matrix<double, 3 * static_cast<int>(N), 3 * static_cast<int>(N)>;

// out(free DOFs) += scale * v_e for every element e.
template <std::size_t N>
void scatterVectors(const std::vector<std::array<int, N>>& elements,
                    const std::vector<ElementVec<N>>& v, const std::vector<int>& freeIndex,
                    double scale, Eigen::VectorXd& out) {
  for (std::size_t e = 0; e < elements.size(); ++e)
    for (std::size_t a = 0; a < N; ++a) {
      const int fi = freeIndex[static_cast<std::size_t>(elements[e][a])];
      if (fi >= 0)
        out.segment<3>(3 * fi) += scale * v[e].template segment<3>(3 * static_cast<int>(a));
    }
}

// out(free DOFs) += scale * K_e u_e for every element e (u per vertex).
template <std::size_t N>
void scatterProducts(const std::vector<std::array<int, N>>& elements,
                     const std::vector<ElementMat<N>>& k, const std::vector<Vec3>& u,
                     const std::vector<int>& freeIndex, double scale, Eigen::VectorXd& out) {
  for (std::size_t e = 0; e < elements.size(); ++e) {
    ElementVec<N> ue;
    for (std::size_t a = 0; a < N; ++a)
      ue.template segment<3>(3 * static_cast<int>(a)) = u[static_cast<std::size_t>(elements[e][a])];
    const ElementVec<N> f = scale * (k[e] * ue);
    for (std::size_t a = 0; a < N; ++a) {
      const int fi = freeIndex[static_cast<std::size_t>(elements[e][a])];
      if (fi >= 0) out.segment<3>(3 * fi) += f.template segment<3>(3 * static_cast<int>(a));
    }
  }
}

// values[offset] += H_e (+ dampScale * D_e) for every element block entry
// that lands on a free-DOF pair (offsets: (3N)^2 per element, -1 = pinned).
template <int M>
void scatterBlocks(const std::vector<Eigen::Matrix<double, M, M>>& hess,
                   const std::vector<Eigen::Matrix<double, M, M>>* damp, double dampScale,
                   const std::vector<int>& offsets, double* values) {
  for (std::size_t e = 0; e < hess.size(); ++e) {
    const int* off = offsets.data() + e * M * M;
    const double* hv = hess[e].data();
    const double* dv = damp ? (*damp)[e].data() : nullptr;
    for (int i = 0; i < M * M; ++i)
      if (off[i] >= 0) values[off[i]] += dv ? hv[i] + dampScale * dv[i] : hv[i];
  }
}

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using Solver = Eigen::CholmodDecomposition<SpMat, Eigen::Lower>;
using VecX = Eigen::VectorXd;

// From this many free DOFs on, the supernodal LL^T (dense BLAS kernels on
// supernodes) beats the simplicial one (bench_sim, one substep, medians:
// 96 triangles 0.37 vs 0.47 ms, 1 064 triangles 13.8 vs 13.9 ms, 10 080
// triangles 413 vs 183 ms for simplicial vs supernodal).
// Contact penalty stiffness in units of the vertex's mass / h^2: the gap
// left by a force F is F h^2 / (kContactScale m), 1e-6 m for gravity at
// h = 1/96 s, about 1 % of a sheet's thickness (docs/CONTACTS.md).
constexpr double kContactScale = 1000.0;
constexpr double kFailsafeSlack = kContactFailsafeSlack;
// Contacts are looked for within 2 D plus this many times the predicted move
// of a vertex over the step (plus what gravity adds): other forces (a handle
// pulling) can make it move farther than predicted.
constexpr double kReachMoves = 1.5;
// Below this tangential speed (m/s) friction acts as a stiff spring (static
// friction, smoothed); above it, as Coulomb's constant force.
constexpr double kFrictionSpeed = 1e-3;

constexpr int kSupernodalMinDofs = 3000;

// OpenBLAS (Debian's libblas.so.3 with libopenblas0) threads its kernels;
// pinned to one thread, the supernodal factorisation gives bit-identical
// results whatever --threads says. No-op under another BLAS.
inline void pinBlasToOneThread() {
  static std::once_flag once;
  std::call_once(once, [] {
    using SetThreads = void (*)(int);
    if (auto* set = reinterpret_cast<SetThreads>(::dlsym(RTLD_DEFAULT, "openblas_set_num_threads")))
      set(1);
  });
}

constexpr std::size_t kMinChunk = 64;       // elements per parallelFor task
constexpr double kArmijo = 1e-4;            // sufficient-decrease constant
constexpr int kMaxLineSearchHalvings = 30;  // alpha down to ~1e-9
// The air's corrector (correctAir): its one linear step is kept when no
// vertex moves more than this many typical edges, else Newton polishes it.
constexpr double kCorrectorLinearStep = 0.01;

inline bool finite(const std::vector<Vec3>& xs) {
  for (const Vec3& p : xs)
    if (!p.allFinite()) return false;
  return true;
}

}  // namespace

struct ElasticSheet::Impl {
  // ---- model (fixed topology, rest state from the pattern) ----
  SimParams params;
  MembraneModuli moduli;
  double bendingRigidity = 0.0;  // D (N m)
  std::size_t vertexCount = 0;
  std::vector<std::array<int, 3>> triangles;
  std::vector<TriangleRest> triangleRests;
  std::vector<mesh::MeshEdge> hinges;
  std::vector<std::array<int, 4>> hingeVertices;  // (x0, x1, x2, x3) as in dihedralAngle
  std::vector<double> hingeBase;                  // hingeStiffness(D, 1, ...)
  std::vector<double> hingeFactor;
  std::vector<double> hingeRest;
  // Continuous (unwrapped) dihedral angle of each hinge at the last accepted
  // state: atan2 wraps at +-pi, which would make a hinge folded past pi
  // (sheets pass through themselves without contacts) jump to the other
  // branch and the energy's gradient flip sign; angles are measured on the
  // branch nearest to this one instead.
  std::vector<double> hingeBranch;
  // The branch is followed up to 1.5 pi (a flap folded half a turn through
  // its neighbour) and re-based beyond: a vertex moved by the caller (the
  // hybrid model's isometry step) could otherwise wind a hinge by whole turns,
  // whose bending force then tries to unwind them (crumple: hinges at 15-100
  // rad, 4 m/s, twice the Newton iterations; docs/CRUMPLING.md).
  static constexpr double kMaxTrackedHinge = 1.5 * std::numbers::pi;
  std::vector<double> mass;  // lumped, kg
  std::vector<char> active;  // vertex belongs to a triangle
  double typicalEdge = 0.0;  // mean pattern edge length (m)

  // ---- state ----
  std::vector<Vec3> x, v;

  // ---- per-element scratch (filled in parallel, reduced in element order) ----
  std::vector<double> triEnergy, hingeEnergy, triTrial, hingeTrial;
  std::vector<Vec9> triGrad;
  std::vector<Mat9> triHess, triDamp;
  std::vector<Vec12> hingeGrad;
  std::vector<Mat12> hingeHess, hingeDamp;

  // ---- linear system, rebuilt only when the pin set changes ----
  bool systemBuilt = false;
  std::vector<int> pinnedSet;  // sorted pinned vertices of the current pattern
  std::vector<int> freeIndex;  // vertex -> free block index, -1 if pinned/inactive
  int freeCount = 0;
  SpMat matrix;                   // lower triangle, 3 x 3 blocks
  std::vector<int> triOffset;     // 81 per triangle: value index or -1
  std::vector<int> hingeOffset;   // 144 per hinge
  std::vector<int> diagOffset;    // per free DOF
  std::vector<int> vertexOffset;  // 9 per free vertex: its 3x3 diagonal block (lower part), or -1

  // Contacts (docs/CONTACTS.md): colliders and self-contact (setContacts).
  ContactOptions contact;
  std::vector<Vec2> pattern;                        // material coordinates, for self-contact
  std::optional<SelfContactDetector> selfDetector;  // built on first use
  // Per step: the frozen contacts (a vertex may have several; contact_energies.hpp).
  using ContactPlane = VertexContact;
  std::vector<ContactPlane> contactPlanes;
  std::vector<FaceContact> faceContacts;
  std::vector<SelfContactPair> selfPairs;  // this step's, for the failsafe
  std::vector<ContactSample> lastContacts;
  long contactVertexSteps = 0;  // contacts found, summed over steps (statistics)
  bool collidersOn() const { return contact.colliders != nullptr && contact.colliders->size() > 0; }
  // The contact planes of a step from x_n (xn) to the predictor xk.
  void findContacts(const std::vector<Vec3>& xn, const std::vector<Vec3>& xk, double h,
                    StepStats& stats);
  void findFaceContacts(const std::vector<Vec3>& xn, const std::vector<Vec3>& xk, double h,
                        double fall);
  // Failsafe projection and the step's contact samples.
  struct Pushed {
    std::size_t vertex;
    Vec3 normal;           // pushed out along
    Vec3 surfaceVelocity;  // of the surface it was pushed out of
  };
  void resolveContacts(const std::vector<Vec3>& xn, std::vector<Vec3>& xk, double h,
                       StepStats& stats, std::vector<Pushed>& pushed);
  Solver solver;
  int analyzeCount = 0;
  bool supernodal = false;  // which CHOLMOD factorisation the last analysis chose

  // The air (docs/AIR.md; elastic_air.cpp): none unless params.air.
  std::optional<AirModel> air;
  // The air's part of the incremental potential at xs (J): its implicit
  // terms and the work of its explicit forces.
  double airEnergy(const std::vector<Vec3>& xs, double h) const;
  // The gradient at xs, keeping every triangle's Hessian block there
  // (airHess: the centroid's Hessian / 9) for the assembly that follows.
  std::vector<Mat3> airHess;
  // Wall-time milliseconds since `start` (the air's timing).
  static double msSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
  }
  void addAirGradient(const std::vector<Vec3>& xs, double h, VecX& out);
  // The triangles' element blocks (membrane, its damping, the air's) into
  // the matrix, one scatter per triangle.
  void scatterTrianglesWithAir(double dampScale, double* values) const;

  // ---- step scratch ----
  std::vector<Pin> pinBuffer;
  std::vector<int> pinTarget;  // vertex -> index into pinBuffer, -1 if free
  GripFunction grips;
  std::vector<Grip> gripBuffer;  // the grips at the substep's end time

  Impl(const mesh::SheetMesh& m, const Material& material, const SimParams& p);
  bool buildSystem(const std::vector<int>& pinned);
  void evaluate(const std::vector<Vec3>& xs, bool derivatives, bool project);
  void evaluateEnergies(const std::vector<Vec3>& xs);
  void projectHessians();
  bool substep(double t0, double t1, const PinFunction& pins, StepStats& stats, std::string& why);
  // One backward Euler substep over h from x_n = x (substep(),
  // elastic_newton.cpp): the incremental potential's fixed parts, the
  // Newton iterate and its scratch.
  struct NewtonState {
    double t0 = 0.0;
    double h = 0.0;
    // The air's terms (set-up, energy, gradient, Hessian), wall time; the
    // Hessian's assembly adds to it through a const state.
    mutable double airMs = 0.0;
    double massDiag = 0.0;     // lumped mass / damping diagonal: 1/h^2 + alpha/h
    double dampScale = 0.0;    // Rayleigh stiffness damping beta / h
    double frictionEps = 0.0;  // kFrictionSpeed h: static friction below it
    // The air's energy at xk when the last line search computed it there
    // (its accepted trial), reset whenever xk or the air's terms change.
    std::optional<double> airAtXk;
    std::vector<Vec3> xTilde, xk, xTrial, disp;
    VecX gradQ, gradV, grad, dx;
  };
  // Reads the pins at t1 into pinBuffer / pinTarget and (re)builds the
  // system when the pinned set changed. False with `why` on bad input.
  bool collectPins(double t1, const PinFunction& pins, std::string& why);
  // Reads the grips at t1 into gripBuffer. False with `why` on bad values.
  bool collectGrips(double t1, std::string& why);
  // Energy of the grips at xs (gripEnergy).
  double gripEnergy(const std::vector<Vec3>& xs) const;
  // x~ = x_n + h v_n + h^2 g, the predictor as the first iterate, and the
  // stiffness damping frozen at x_n.
  void startNewton(NewtonState& s);
  // out += beta/h K^_n u (Rayleigh damping with the stiffness frozen at x_n).
  void dampProduct(const std::vector<Vec3>& u, double dampScale, VecX& out) const;
  // Penalty and friction energy of the contacts at xs.
  double contactEnergy(const std::vector<Vec3>& xs, double eps) const;
  // The incremental potential's gradient at s.xk over the free DOFs (the
  // element terms must have been evaluated there).
  bool newtonGradient(NewtonState& s, std::string& why);
  // The Hessian at s.xk into `matrix`; false when not finite.
  bool assembleSystem(const NewtonState& s);
  // s.dx = -H^-1 grad, the element blocks projected to PSD when H is not
  // positive definite. Sets `projected`.
  bool newtonDirection(NewtonState& s, StepStats& stats, bool& projected, std::string& why);
  // s.xTrial = s.xk + step s.dx over the free DOFs.
  void applyStep(NewtonState& s, double step) const;
  // Backtracking (Armijo) line search along s.dx; the accepted point is left
  // in s.xTrial and its length in `step`.
  enum class LineSearchResult { Accepted, Converged, Failed };
  LineSearchResult lineSearch(NewtonState& s, double stepNorm, double tol, double& step,
                              std::string& why);
  void traceNewtonIteration(const NewtonState& s, int it, double stepNorm, double step,
                            bool projected) const;
  // Newton iterations from s.xk until the step falls below the tolerance;
  // false with `why` when they do not within maxNewtonIterations.
  bool newtonLoop(NewtonState& s, StepStats& stats, std::string& why);
  // The air's explicit forces and drag corrected at the solved step s.xk
  // (Heun's trapezoid, AirModel::correctStep), and the step moved to the
  // corrected minimiser: one solve with the last factorisation, then Newton
  // if that step is too long for its linearisation. False with `why`.
  bool correctAir(NewtonState& s, StepStats& stats, std::string& why);
  // Contacts' failsafe, velocities and the new state from the converged s.xk.
  bool finishSubstep(NewtonState& s, StepStats& stats, std::string& why);
  bool stepRecursive(double t0, double t1, const PinFunction& pins, int depth, StepStats& stats,
                     std::string& why);
  double hingeStiffnessOf(std::size_t k) const { return hingeBase[k] * hingeFactor[k]; }
  // The raw (wrapped) dihedral angle of hinge k at xs.
  double rawAngle(std::size_t k, const std::vector<Vec3>& xs) const {
    const auto& h = hingeVertices[k];
    return dihedralAngle(xs[static_cast<std::size_t>(h[0])], xs[static_cast<std::size_t>(h[1])],
                         xs[static_cast<std::size_t>(h[2])], xs[static_cast<std::size_t>(h[3])]);
  }
  // A raw angle of hinge k moved onto the branch nearest to hingeBranch[k].
  double onBranch(std::size_t k, double raw) const {
    return hingeBranch[k] + std::remainder(raw - hingeBranch[k], 2.0 * std::numbers::pi);
  }
  // Hinge k's angle at xs on the branch nearest to hingeBranch[k].
  double continuousAngle(std::size_t k, const std::vector<Vec3>& xs) const {
    return onBranch(k, rawAngle(k, xs));
  }
  // Deviation of hinge k from its rest angle on that branch, given its raw angle.
  double deviation(std::size_t k, double raw) const { return onBranch(k, raw) - hingeRest[k]; }
  // Moves every hinge's branch to its angle at xs (after an accepted step
  // or a teleport by the caller).
  void trackBranches(const std::vector<Vec3>& xs) {
    for (std::size_t k = 0; k < hingeVertices.size(); ++k) {
      hingeBranch[k] = continuousAngle(k, xs);
      if (std::abs(hingeBranch[k]) > kMaxTrackedHinge)
        hingeBranch[k] -= std::copysign(2.0 * std::numbers::pi, hingeBranch[k]);
    }
  }
};

}  // namespace crumple::sim
