// Elastic sheet integrator (paper Sec. 4; thesis 2.3.1): backward Euler as the
// minimisation of the incremental potential
//
//   Phi(x) = 1/(2h^2) |x - x~|_M^2 + alpha/(2h) |x - x_n|_M^2
//            + beta/(2h) (x - x_n)^T K^_n (x - x_n) + V(x),
//   x~ = x_n + h v_n + h^2 g,
//
// whose stationarity condition is exactly the backward Euler update
//   M (v_{n+1} - v_n)/h = -grad V(x_{n+1}) + M g - alpha M v_{n+1} - beta K^_n v_{n+1},
// with v_{n+1} = (x_{n+1} - x_n)/h, lumped masses, Rayleigh damping (alpha =
// massDamping, beta = stiffnessDamping; the stiffness-proportional term uses
// the PSD-projected stiffness K^_n frozen at the start of the step so that it
// remains a potential) and V the membrane + bending energy. Pinned vertices
// are eliminated: they are set to their targets at t + h and only the free
// DOFs enter the Newton system.
//
// Newton: each iteration evaluates the per-element energies, gradients and
// exact Hessians in parallel (one slot per element), assembles them serially
// in element order (bit-identical for any thread count) into the free-DOF
// system M/h^2 + alpha M/h + beta/h K^_n + K(x) and factorises it with
// CHOLMOD's LL^T: simplicial on small systems (no BLAS), supernodal from
// kSupernodalMinDofs on (OpenBLAS pinned to one thread, so no thread-dependent
// rounding); the symbolic analysis is done once per pin set and reused. When
// that factorisation fails because the exact system is indefinite (compressed
// membrane, hinges bent against their rest angle), every 9x9 / 12x12 element
// block is projected to PSD (negative eigenvalues clamped, Eigen's
// SelfAdjointEigenSolver on the 6x6 / 9x9 complement of the translations,
// which the element energies ignore) and the now SPD system is factorised
// instead. Exact
// first keeps Newton's quadratic convergence near the solution (projected
// Hessians alone converge linearly: ~10-12 iterations per step instead of
// 4-6 on the hanging sheet, sometimes more than 30); the projection keeps
// every step a descent direction.
// Then a backtracking (Armijo) line search on Phi: its quadratic part is
// evaluated analytically along the direction and the elastic part as a sum of
// per-element differences, so it sees energy changes far below the rounding
// of Phi itself.
//
// Convergence criterion (SimParams::newtonTolerance): the Newton step's max
// norm |dx|_inf <= newtonTolerance * L, L = mean pattern edge length (default
// 1e-7 L: ~2e-9 m on a 2 cm mesh, i.e. velocity errors ~2e-7 m/s at 1/96 s; on the
// drape sample 1e-8 L needed 6.9 iterations per substep and 11 halvings, 1e-7 L
// 6.2 and 3, with identical handle error and max edge strain).
// The step that meets it is applied in full. The paper reports 10-100
// iterations per step (Sec. 4); here 4-6 are typical for a hanging sheet, and
// not meeting the criterion within maxNewtonIterations (default 30) counts as
// a failure, like a failed factorisation or a non-finite value: the step is
// split in two (recursively, down to maxHalvings levels) and, if that fails
// too, a NumericalError is thrown with the state restored.
#include "crumple/sim/elastic_sheet.hpp"

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
#include "crumple/sim/colliders.hpp"
#include "crumple/sim/energies.hpp"
#include "crumple/sim/self_contact.hpp"

namespace crumple::sim {
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
// h = 1/96 s, about 1 % of a sheet's thickness (issue 5).
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
void pinBlasToOneThread() {
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

bool finite(const std::vector<Vec3>& xs) {
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

  // Contacts (issue 5): colliders and self-contact (setContacts).
  ContactOptions contact;
  std::vector<Vec2> pattern;                        // material coordinates, for self-contact
  std::optional<SelfContactDetector> selfDetector;  // built on first use
  // Per step: the frozen contact planes (a vertex may have several).
  struct ContactPlane {
    int vertex;
    int collider;   // ColliderSet index, -1 = the sheet itself
    Vec3 point;     // on the touched surface, where it is at the end of the step
    Vec3 normal;    // unit, out of the touched surface
    Vec3 motion;    // the touched surface's displacement over the step
    double mu;      // Coulomb friction coefficient
    double lambda;  // lagged normal force (N) at the start of the step
    double k;       // penalty stiffness (N/m)
    // An edge or corner contact with another layer (SelfContactPair::face
    // false) keeps the distance to that triangle, frozen where the layer's
    // velocity carries it, rather than to a plane: a plane through an edge
    // would stand in the way of vertices that pass the triangle by.
    bool toTriangle = false;
    std::array<Vec3, 3> triangle{};
    // The penalty's gap (contact distance minus the distance) at x, and the
    // direction it pushes along.
    double gap(const Vec3& x, double distance, Vec3* direction) const {
      if (!toTriangle) {
        if (direction != nullptr) *direction = normal;
        return distance - normal.dot(x - point);
      }
      const Vec3 d = x - closestPointOnTriangle(x, triangle[0], triangle[1], triangle[2]);
      const double len = d.norm();
      if (direction != nullptr) *direction = len > 0.0 ? Vec3(d / len) : normal;
      return distance - len;
    }
  };
  std::vector<ContactPlane> contactPlanes;
  // A collider probe (a ball's centre, a box's corner) near the inside of a
  // triangle: the triangle's point w keeps radius + D from it along the
  // normal frozen at the start of the step (vertex contacts alone let a
  // ball through a coarse mesh). The penalty acts on the triangle's
  // vertices through w, in the triangle's own block.
  struct FaceContact {
    int triangle;
    int collider;
    std::array<double, 3> w;
    Vec3 probe;  // where the probe ends the step
    double radius;
    Vec3 normal;  // unit, from the probe toward the sheet
    double k;
    double gap(const std::vector<Vec3>& xs, const std::array<int, 3>& t, double distance) const {
      Vec3 q = Vec3::Zero();
      for (std::size_t a = 0; a < 3; ++a) q += w[a] * xs[static_cast<std::size_t>(t[a])];
      return radius + distance - normal.dot(q - probe);
    }
  };
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

  // ---- step scratch ----
  std::vector<Pin> pinBuffer;
  std::vector<int> pinTarget;  // vertex -> index into pinBuffer, -1 if free

  Impl(const mesh::SheetMesh& m, const Material& material, const SimParams& p);
  bool buildSystem(const std::vector<int>& pinned);
  void evaluate(const std::vector<Vec3>& xs, bool derivatives, bool project);
  void evaluateEnergies(const std::vector<Vec3>& xs);
  void projectHessians();
  bool substep(double t0, double t1, const PinFunction& pins, StepStats& stats, std::string& why);
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

ElasticSheet::Impl::Impl(const mesh::SheetMesh& m, const Material& material, const SimParams& p)
    : params(p) {
  if (const std::string problem = mesh::validate(m); !problem.empty())
    throw std::invalid_argument("ElasticSheet: invalid mesh: " + problem);
  if (!(material.thickness > 0.0) || !(material.density > 0.0) || !(material.youngsModulus > 0.0) ||
      !(material.poissonRatio > -1.0) || !(material.poissonRatio < 0.5) ||
      !std::isfinite(material.thickness) || !std::isfinite(material.density) ||
      !std::isfinite(material.youngsModulus))
    throw std::invalid_argument("ElasticSheet: material '" + material.name +
                                "' needs positive thickness, density and Young's modulus and "
                                "-1 < Poisson ratio < 0.5");
  if (!p.gravity.allFinite() || !(p.massDamping >= 0.0) || !(p.stiffnessDamping >= 0.0) ||
      !std::isfinite(p.massDamping) || !std::isfinite(p.stiffnessDamping) ||
      p.maxNewtonIterations < 1 || !(p.newtonTolerance > 0.0) || p.maxHalvings < 0 ||
      !(p.membraneScale > 0.0) || !std::isfinite(p.membraneScale) ||
      !(p.minVertexMassFraction >= 0.0) || !(p.minVertexMassFraction <= 1.0))
    throw std::invalid_argument("ElasticSheet: invalid simulation parameters");

  moduli = membraneModuli(material);
  moduli.lambda *= p.membraneScale;
  moduli.mu *= p.membraneScale;
  bendingRigidity = material.bendingStiffness();
  vertexCount = m.vertexCount();
  triangles = m.triangles;
  pattern = m.pattern;
  x = m.positions;
  v.assign(vertexCount, Vec3::Zero());

  // Rest state and lumped mass (areal density * area / 3 per corner).
  triangleRests.reserve(triangles.size());
  mass.assign(vertexCount, 0.0);
  active.assign(vertexCount, 0);
  for (const auto& t : triangles) {
    const auto i0 = static_cast<std::size_t>(t[0]), i1 = static_cast<std::size_t>(t[1]),
               i2 = static_cast<std::size_t>(t[2]);
    triangleRests.push_back(triangleRest(m.pattern[i0], m.pattern[i1], m.pattern[i2]));
    const double third = material.arealDensity() * triangleRests.back().area / 3.0;
    for (const std::size_t i : {i0, i1, i2}) {
      mass[i] += third;
      active[i] = 1;
    }
  }
  // Mass floor (SimParams::minVertexMassFraction): a vertex of sliver
  // triangles gets at least this fraction of the mean vertex mass.
  if (p.minVertexMassFraction > 0.0 && vertexCount > 0) {
    double total = 0.0;
    std::size_t used = 0;
    for (std::size_t i = 0; i < vertexCount; ++i) {
      if (active[i]) total += mass[i], ++used;
    }
    const double floor =
        used > 0 ? p.minVertexMassFraction * total / static_cast<double>(used) : 0.0;
    for (std::size_t i = 0; i < vertexCount; ++i) {
      if (active[i]) mass[i] = std::max(mass[i], floor);
    }
  }

  // Hinges, with (x0, x1) ordered as triangle A traverses the edge.
  const std::vector<mesh::MeshEdge> edges = mesh::buildEdges(m);
  double edgeSum = 0.0;
  for (const auto& e : edges) {
    const auto a = static_cast<std::size_t>(e.v[0]), b = static_cast<std::size_t>(e.v[1]);
    edgeSum += (m.pattern[a] - m.pattern[b]).norm();
    if (!e.interior()) continue;
    const auto& ta = triangles[static_cast<std::size_t>(e.triangles[0])];
    int k = 0;
    while (ta[static_cast<std::size_t>(k)] != e.v[0]) ++k;
    const bool forward = ta[static_cast<std::size_t>((k + 1) % 3)] == e.v[1];
    const int x0 = forward ? e.v[0] : e.v[1];
    const int x1 = forward ? e.v[1] : e.v[0];
    hinges.push_back(e);
    hingeVertices.push_back({x0, x1, e.opposite[0], e.opposite[1]});
    hingeBase.push_back(
        hingeStiffness(bendingRigidity, 1.0, (m.pattern[a] - m.pattern[b]).squaredNorm(),
                       triangleRests[static_cast<std::size_t>(e.triangles[0])].area,
                       triangleRests[static_cast<std::size_t>(e.triangles[1])].area));
  }
  typicalEdge = edges.empty() ? 1.0 : edgeSum / static_cast<double>(edges.size());
  hingeFactor.assign(hinges.size(), 1.0);
  hingeRest.assign(hinges.size(), 0.0);
  hingeBranch.assign(hinges.size(), 0.0);
  trackBranches(m.positions);

  triEnergy.assign(triangles.size(), 0.0);
  triTrial.assign(triangles.size(), 0.0);
  triGrad.resize(triangles.size());
  triHess.resize(triangles.size());
  hingeEnergy.assign(hinges.size(), 0.0);
  hingeTrial.assign(hinges.size(), 0.0);
  hingeGrad.resize(hinges.size());
  hingeHess.resize(hinges.size());

  // Quiet CHOLMOD (failures are reported through info()). Fill-reducing
  // ordering: the better (least fill) of AMD and CHOLMOD's nested dissection
  // (NESDIS, METIS-based, deterministic); AMD wins on small sheets, NESDIS
  // saves ~40% of the flops at 10k triangles. Chosen once per analysis.
  solver.cholmod().print = 0;
  solver.cholmod().nmethods = 2;
  solver.cholmod().method[0].ordering = CHOLMOD_AMD;
  solver.cholmod().method[1].ordering = CHOLMOD_NESDIS;
  solver.cholmod().postorder = 1;
}

// Sparsity pattern of the free-DOF Hessian (lower triangle), the scatter maps
// from element blocks into it, and CHOLMOD's symbolic analysis.
bool ElasticSheet::Impl::buildSystem(const std::vector<int>& pinned) {
  freeIndex.assign(vertexCount, -1);
  std::vector<char> isPinned(vertexCount, 0);
  for (const int p : pinned) isPinned[static_cast<std::size_t>(p)] = 1;
  freeCount = 0;
  for (std::size_t i = 0; i < vertexCount; ++i)
    if (active[i] && !isPinned[i]) freeIndex[i] = freeCount++;

  std::vector<std::vector<int>> blockRows(static_cast<std::size_t>(freeCount));
  for (int f = 0; f < freeCount; ++f) blockRows[static_cast<std::size_t>(f)].push_back(f);
  auto couple = [&](const int* vs, int n) {
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const int fa = freeIndex[static_cast<std::size_t>(vs[a])];
        const int fb = freeIndex[static_cast<std::size_t>(vs[b])];
        if (fa > fb && fb >= 0) blockRows[static_cast<std::size_t>(fb)].push_back(fa);
      }
  };
  for (const auto& t : triangles) couple(t.data(), 3);
  for (const auto& h : hingeVertices) couple(h.data(), 4);

  const int n = 3 * freeCount;
  std::vector<int> outer(static_cast<std::size_t>(n) + 1, 0);
  std::vector<int> inner;
  for (int j = 0; j < freeCount; ++j) {
    auto& rows = blockRows[static_cast<std::size_t>(j)];
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    for (int q = 0; q < 3; ++q) {
      const int col = 3 * j + q;
      for (const int i : rows)
        for (int p = 0; p < 3; ++p)
          if (3 * i + p >= col) inner.push_back(3 * i + p);
      outer[static_cast<std::size_t>(col) + 1] = static_cast<int>(inner.size());
    }
  }
  matrix.resize(n, n);
  matrix.resizeNonZeros(static_cast<Eigen::Index>(inner.size()));
  std::copy(outer.begin(), outer.end(), matrix.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), matrix.innerIndexPtr());
  std::fill(matrix.valuePtr(), matrix.valuePtr() + inner.size(), 0.0);

  auto find = [&](int row, int col) -> int {
    const int* begin = inner.data() + outer[static_cast<std::size_t>(col)];
    const int* end = inner.data() + outer[static_cast<std::size_t>(col) + 1];
    const int* it = std::lower_bound(begin, end, row);
    return static_cast<int>(it - inner.data());
  };
  auto offsets = [&](const int* vs, int nv, int* out) {
    const int dim = 3 * nv;
    for (int r = 0; r < dim; ++r)
      for (int c = 0; c < dim; ++c) {
        const int fr = freeIndex[static_cast<std::size_t>(vs[r / 3])];
        const int fc = freeIndex[static_cast<std::size_t>(vs[c / 3])];
        const int row = 3 * fr + r % 3, col = 3 * fc + c % 3;
        // Column-major element blocks (Eigen's default storage).
        out[c * dim + r] = (fr < 0 || fc < 0 || row < col) ? -1 : find(row, col);
      }
  };
  triOffset.assign(triangles.size() * 81, -1);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    offsets(triangles[t].data(), 3, triOffset.data() + t * 81);
  hingeOffset.assign(hingeVertices.size() * 144, -1);
  for (std::size_t k = 0; k < hingeVertices.size(); ++k)
    offsets(hingeVertices[k].data(), 4, hingeOffset.data() + k * 144);
  diagOffset.resize(static_cast<std::size_t>(n));
  for (int d = 0; d < n; ++d) diagOffset[static_cast<std::size_t>(d)] = find(d, d);
  vertexOffset.assign(static_cast<std::size_t>(freeCount) * 9, -1);
  for (int f = 0; f < freeCount; ++f)
    for (int c = 0; c < 3; ++c)
      for (int r = c; r < 3; ++r)
        vertexOffset[static_cast<std::size_t>(f * 9 + c * 3 + r)] = find(3 * f + r, 3 * f + c);

  pinnedSet = pinned;
  systemBuilt = true;
  if (n > 0) {
    supernodal = n >= kSupernodalMinDofs;
    if (supernodal) pinBlasToOneThread();
    solver.setMode(supernodal ? Eigen::CholmodSupernodalLLt : Eigen::CholmodSimplicialLLt);
    solver.analyzePattern(matrix);
    ++analyzeCount;
    if (solver.cholmod().status < 0) {  // out of memory or an invalid pattern
      systemBuilt = false;
      return false;
    }
  }
  return true;
}

// Per-element energies (and gradients / Hessians, PSD-projected when asked)
// at xs, in parallel; every element writes only its own slot.
void ElasticSheet::Impl::evaluate(const std::vector<Vec3>& xs, bool derivatives, bool project) {
  const std::size_t nt = triangles.size();
  parallelFor(
      nt + hinges.size(),
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
          if (i < nt) {
            const auto& t = triangles[i];
            const Vec3& a = xs[static_cast<std::size_t>(t[0])];
            const Vec3& b = xs[static_cast<std::size_t>(t[1])];
            const Vec3& c = xs[static_cast<std::size_t>(t[2])];
            if (!derivatives) {
              triEnergy[i] = sim::membraneEnergy(a, b, c, triangleRests[i], moduli);
              continue;
            }
            triEnergy[i] =
                sim::membraneEnergy(a, b, c, triangleRests[i], moduli, &triGrad[i], &triHess[i]);
            if (project) projectTranslationInvariantToPsd(triHess[i]);
          } else {
            const std::size_t k = i - nt;
            const double stiffness = hingeStiffnessOf(k);
            if (stiffness == 0.0) {
              hingeEnergy[k] = 0.0;
              if (derivatives) {
                hingeGrad[k].setZero();
                hingeHess[k].setZero();
              }
              continue;
            }
            const auto& h = hingeVertices[k];
            const Vec3& p0 = xs[static_cast<std::size_t>(h[0])];
            const Vec3& p1 = xs[static_cast<std::size_t>(h[1])];
            const Vec3& p2 = xs[static_cast<std::size_t>(h[2])];
            const Vec3& p3 = xs[static_cast<std::size_t>(h[3])];
            if (!derivatives) {
              const double d = deviation(k, dihedralAngle(p0, p1, p2, p3));
              hingeEnergy[k] = stiffness * d * d;
              continue;
            }
            // E = k d^2: gradient 2k d g, Hessian 2k (g g^T + d H_theta).
            Vec12 g;
            const double d = deviation(k, dihedralAngle(p0, p1, p2, p3, &g, &hingeHess[k]));
            hingeEnergy[k] = stiffness * d * d;
            hingeGrad[k] = (2.0 * stiffness * d) * g;
            hingeHess[k] *= 2.0 * stiffness * d;
            hingeHess[k].noalias() += (2.0 * stiffness) * g * g.transpose();
            if (project) projectTranslationInvariantToPsd(hingeHess[k]);
          }
        }
      },
      kMinChunk);
}

// Project every element Hessian to PSD in place (parallel, per element).
void ElasticSheet::Impl::projectHessians() {
  const std::size_t nt = triangles.size();
  parallelFor(
      nt + hinges.size(),
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
          if (i < nt)
            projectTranslationInvariantToPsd(triHess[i]);
          else if (hingeStiffnessOf(i - nt) != 0.0)
            projectTranslationInvariantToPsd(hingeHess[i - nt]);
        }
      },
      kMinChunk);
}

// Energies only, into the trial slots (line search).
void ElasticSheet::Impl::evaluateEnergies(const std::vector<Vec3>& xs) {
  const std::size_t nt = triangles.size();
  parallelFor(
      nt + hinges.size(),
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
          if (i < nt) {
            const auto& t = triangles[i];
            triTrial[i] = sim::membraneEnergy(
                xs[static_cast<std::size_t>(t[0])], xs[static_cast<std::size_t>(t[1])],
                xs[static_cast<std::size_t>(t[2])], triangleRests[i], moduli);
          } else {
            const std::size_t k = i - nt;
            const double stiffness = hingeStiffnessOf(k);
            const auto& h = hingeVertices[k];
            if (stiffness == 0.0) {
              hingeTrial[k] = 0.0;
              continue;
            }
            const double d = deviation(k, dihedralAngle(xs[static_cast<std::size_t>(h[0])],
                                                        xs[static_cast<std::size_t>(h[1])],
                                                        xs[static_cast<std::size_t>(h[2])],
                                                        xs[static_cast<std::size_t>(h[3])]));
            hingeTrial[k] = stiffness * d * d;
          }
        }
      },
      kMinChunk);
}

// One backward Euler step from the current state at t0 to t1.
// On failure returns false with a reason and leaves the state untouched.
// Contacts (issue 5; paper Sec. 4): a free vertex that may come within the
// contact distance D of a collider, or of another layer of the sheet, during
// the step gets that surface's tangent plane (point p, outward normal m) at
// the start of the step, frozen for the step, and the penalty
// k/2 max(0, D - m.(x - p))^2 with k = kContactScale * mass / h^2 (a stiff
// spring on the inertia's scale). A collider's plane is taken where the
// collider ends the step; a layer's where its velocity carries it (each side
// of a self-contact sees the other one frozen: a Jacobi split that keeps the
// system's sparsity, the reaction reaching the other layer through its own
// vertices' contacts). resolveContacts is the failsafe.
void ElasticSheet::Impl::findContacts(const std::vector<Vec3>& xn, const std::vector<Vec3>& xk,
                                      double h, StepStats& stats) {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
  };
  contactPlanes.clear();
  faceContacts.clear();
  selfPairs.clear();
  const double dist = contact.distance;
  // The predictor leaves out what gravity adds over the step.
  const double fall = h * h * params.gravity.norm();
  if (collidersOn()) {
    const auto start = Clock::now();
    const ColliderSet& set = *contact.colliders;
    for (std::size_t i = 0; i < vertexCount; ++i) {
      if (freeIndex[i] < 0) continue;
      const double reach = 2.0 * dist + kReachMoves * (xk[i] - xn[i]).norm() + fall;
      if (const auto c = set.nearest(xn[i], reach)) {
        const double k = kContactScale * mass[i] / (h * h);
        // The normal force the penalty exerted at x_n, lagged for friction.
        const double lambda = k * std::max(0.0, dist - c->distance);
        contactPlanes.push_back({static_cast<int>(i), c->collider, c->point, c->normal,
                                 set.surfaceDisplacement(c->collider, c->point),
                                 set.friction(c->collider), lambda, k});
      }
    }
    findFaceContacts(xn, xk, h, fall);
    stats.contactMs += since(start);
  }
  if (contact.self != SelfContactMode::Off) {
    const auto start = Clock::now();
    if (contact.self == SelfContactMode::On || sheetIsFolded(triangles, xn, contact.foldSpread)) {
      ++stats.selfContactSteps;
      // Pairs that may come within 2 D over the predicted move.
      if (!selfDetector) selfDetector.emplace(triangles, pattern, dist);
      std::vector<char> mask(vertexCount, 0);
      for (std::size_t i = 0; i < vertexCount; ++i) mask[i] = freeIndex[i] >= 0 ? 1 : 0;
      selfPairs = selfDetector->find(xn, xk, 2.0 * dist + 2.0 * fall, &mask);
      for (const SelfContactPair& p : selfPairs) {
        const auto& t = triangles[static_cast<std::size_t>(p.triangle)];
        Vec3 at = Vec3::Zero(), motion = Vec3::Zero();
        for (std::size_t a = 0; a < 3; ++a) {
          const auto j = static_cast<std::size_t>(t[a]);
          at += p.weights[a] * xn[j];
          motion += p.weights[a] * (xk[j] - xn[j]);  // the predictor: x_n + h v_n, or the pin
        }
        const auto vi = static_cast<std::size_t>(p.vertex);
        const double k = kContactScale * mass[vi] / (h * h);
        ContactPlane plane{p.vertex,
                           -1,
                           at + motion,
                           p.normal,
                           motion,
                           contact.selfFriction,
                           k * std::max(0.0, dist - p.distance),
                           k};
        if (!p.face) {
          plane.toTriangle = true;
          for (std::size_t a = 0; a < 3; ++a)
            plane.triangle[a] = xk[static_cast<std::size_t>(t[a])];
        }
        contactPlanes.push_back(plane);
      }
    }
    stats.selfContactMs += since(start);
  }
  contactVertexSteps += static_cast<long>(contactPlanes.size() + faceContacts.size());
}

void ElasticSheet::Impl::findFaceContacts(const std::vector<Vec3>& xn, const std::vector<Vec3>& xk,
                                          double h, double fall) {
  const std::vector<ColliderProbe> probes = contact.colliders->probes();
  if (probes.empty()) return;
  const double dist = contact.distance;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    const auto i0 = static_cast<std::size_t>(tri[0]), i1 = static_cast<std::size_t>(tri[1]),
               i2 = static_cast<std::size_t>(tri[2]);
    if (freeIndex[i0] < 0 && freeIndex[i1] < 0 && freeIndex[i2] < 0) continue;
    const Vec3 lo = xn[i0].cwiseMin(xn[i1]).cwiseMin(xn[i2]);
    const Vec3 hi = xn[i0].cwiseMax(xn[i1]).cwiseMax(xn[i2]);
    const double moves =
        std::max({(xk[i0] - xn[i0]).norm(), (xk[i1] - xn[i1]).norm(), (xk[i2] - xn[i2]).norm()});
    for (const ColliderProbe& p : probes) {
      const double reach = p.radius + 2.0 * dist + kReachMoves * moves + fall;
      if (((p.point - lo).array() < -reach).any() || ((p.point - hi).array() > reach).any())
        continue;
      const std::array<double, 3> w = closestBarycentricOnTriangle(p.point, xn[i0], xn[i1], xn[i2]);
      if (std::max({w[0], w[1], w[2]}) > 1.0 - 1e-9) continue;  // at a vertex: its own contact
      const Vec3 q = w[0] * xn[i0] + w[1] * xn[i1] + w[2] * xn[i2];
      const double d = (q - p.point).norm();
      if (!(d < reach)) continue;
      Vec3 n = (xn[i1] - xn[i0]).cross(xn[i2] - xn[i0]);
      if (d > 1e-9 * dist) {
        n = (q - p.point) / d;
      } else if (n.norm() > 0.0) {
        n.normalize();  // the probe is on the face: push the face along its normal
      } else {
        continue;
      }
      const double m = w[0] * mass[i0] + w[1] * mass[i1] + w[2] * mass[i2];
      faceContacts.push_back(
          {static_cast<int>(t), p.collider, w, p.point, p.radius, n, kContactScale * m / (h * h)});
    }
  }
}

// Failsafe: a free vertex the penalty left nearer than (1 - slack) D to a
// collider (a contact the frozen plane missed), or nearer than that to a
// triangle of another layer or through it, is moved out to D, and loses its
// velocity into that surface (pushed). Then the step's contact samples:
// every plane whose penalty is active at the solution, or whose vertex was
// pushed, merged per (vertex, collider).
void ElasticSheet::Impl::resolveContacts(const std::vector<Vec3>& xn, std::vector<Vec3>& xk,
                                         double h, StepStats& stats, std::vector<Pushed>& pushed) {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
  };
  const double dist = contact.distance;
  const double minGap = (1.0 - kFailsafeSlack) * dist;
  // Samples from the solution the penalty reached (before any projection).
  std::vector<ContactSample> samples;
  for (const auto& cp : contactPlanes) {
    const auto vi = static_cast<std::size_t>(cp.vertex);
    const double gap = cp.gap(xk[vi], dist, nullptr);
    if (!(gap > 0.0)) continue;
    const Mat3 t = Mat3::Identity() - cp.normal * cp.normal.transpose();
    samples.push_back(
        {cp.vertex, cp.collider, (t * ((xk[vi] - xn[vi]) - cp.motion)).norm() / h, cp.k * gap});
  }
  if (collidersOn()) {
    const auto start = Clock::now();
    const ColliderSet& set = *contact.colliders;
    for (std::size_t i = 0; i < vertexCount; ++i) {
      if (freeIndex[i] < 0) continue;
      if (const auto c = set.nearest(xk[i], dist); c && c->distance < minGap) {
        const Vec3 surfaceVelocity = set.surfaceDisplacement(c->collider, c->point) / h;
        samples.push_back({static_cast<int>(i), c->collider,
                           ((Mat3::Identity() - c->normal * c->normal.transpose()) *
                            ((xk[i] - xn[i]) / h - surfaceVelocity))
                               .norm(),
                           kContactScale * mass[i] / (h * h) * (dist - c->distance)});
        xk[i] += (dist - c->distance) * c->normal;
        pushed.push_back({i, c->normal, surfaceVelocity});
      }
    }
    // Faces a probe came through or too near: the triangle moves out.
    for (const FaceContact& fc : faceContacts) {
      const auto& tri = triangles[static_cast<std::size_t>(fc.triangle)];
      const std::array<Vec3, 3> corner{xk[static_cast<std::size_t>(tri[0])],
                                       xk[static_cast<std::size_t>(tri[1])],
                                       xk[static_cast<std::size_t>(tri[2])]};
      const std::array<double, 3> w =
          closestBarycentricOnTriangle(fc.probe, corner[0], corner[1], corner[2]);
      const Vec3 q = w[0] * corner[0] + w[1] * corner[1] + w[2] * corner[2];
      const double along = fc.normal.dot(q - fc.probe);
      const double gap = fc.radius + dist - along;
      if (along < fc.radius + minGap) {
        const Vec3 surfaceVelocity = set.surfaceDisplacement(fc.collider, fc.probe) / h;
        std::size_t heaviest = 0;
        for (std::size_t a = 0; a < 3; ++a) {
          if (w[a] > w[heaviest]) heaviest = a;
          const auto v = static_cast<std::size_t>(tri[a]);
          if (freeIndex[v] < 0) continue;
          xk[v] += gap * fc.normal;
          pushed.push_back({v, fc.normal, surfaceVelocity});
        }
        samples.push_back({tri[heaviest], fc.collider, 0.0, fc.k * gap});
      } else if (gap > 0.0) {
        std::size_t heaviest = 0;
        for (std::size_t a = 1; a < 3; ++a)
          if (w[a] > w[heaviest]) heaviest = a;
        samples.push_back({tri[heaviest], fc.collider, 0.0, fc.k * gap});
      }
    }
    stats.contactMs += since(start);
  }
  if (!selfPairs.empty()) {
    const auto start = Clock::now();
    for (const SelfContactPair& p : selfPairs) {
      const auto vi = static_cast<std::size_t>(p.vertex);
      const auto& t = triangles[static_cast<std::size_t>(p.triangle)];
      const Vec3& a = xk[static_cast<std::size_t>(t[0])];
      const Vec3& b = xk[static_cast<std::size_t>(t[1])];
      const Vec3& c = xk[static_cast<std::size_t>(t[2])];
      const Vec3 q = closestPointOnTriangle(xk[vi], a, b, c);
      const Vec3 d = xk[vi] - q;
      const double gap = d.norm();
      const double side = d.dot(p.normal);
      // Through the triangle: the closest point is inside it and the vertex
      // is on the other side of where it started.
      const Vec3 face = (b - a).cross(c - a);
      const bool inside =
          face.norm() > 0.0 && std::abs(d.normalized().dot(face.normalized())) > 1.0 - 1e-9;
      const bool through = side < 0.0 && inside;
      if (gap >= minGap && !through) continue;
      const Vec3 out = (side >= 0.0 && gap > 1e-9 * dist) ? Vec3(d / gap) : p.normal;
      Vec3 surfaceVelocity = Vec3::Zero();
      for (std::size_t k = 0; k < 3; ++k) {
        const auto j = static_cast<std::size_t>(t[k]);
        surfaceVelocity += p.weights[k] * (xk[j] - xn[j]) / h;
      }
      samples.push_back(
          {p.vertex, -1,
           ((Mat3::Identity() - out * out.transpose()) * ((xk[vi] - xn[vi]) / h - surfaceVelocity))
               .norm(),
           kContactScale * mass[vi] / (h * h) * std::max(0.0, dist - gap)});
      xk[vi] = q + dist * out;
      pushed.push_back({vi, out, surfaceVelocity});
    }
    stats.selfContactMs += since(start);
  }
  mergeContactSamples(samples);
  lastContacts = std::move(samples);
}

bool ElasticSheet::Impl::substep(double t0, double t1, const PinFunction& pins, StepStats& stats,
                                 std::string& why) {
  const double h = t1 - t0;
  // Animated colliders: where the step begins, then where it ends.
  if (collidersOn() && contact.moveColliders) {
    contact.moveColliders(t0);
    contact.moveColliders(t1);
  }
  // Handle targets at t1 (paper Sec. 4: handles are hard constraints).
  pinBuffer.clear();
  if (pins) pins(t1, pinBuffer);
  pinTarget.assign(vertexCount, -1);
  std::vector<int> pinned;
  pinned.reserve(pinBuffer.size());
  for (std::size_t i = 0; i < pinBuffer.size(); ++i) {
    const int vtx = pinBuffer[i].vertex;
    if (vtx < 0 || static_cast<std::size_t>(vtx) >= vertexCount)
      throw std::out_of_range("ElasticSheet: pin on vertex " + std::to_string(vtx) + " (mesh has " +
                              std::to_string(vertexCount) + ")");
    if (!pinBuffer[i].position.allFinite()) {
      why = "non-finite pin target for vertex " + std::to_string(vtx);
      return false;
    }
    if (pinTarget[static_cast<std::size_t>(vtx)] < 0) pinned.push_back(vtx);
    pinTarget[static_cast<std::size_t>(vtx)] = static_cast<int>(i);  // the last one wins
  }
  std::sort(pinned.begin(), pinned.end());
  if ((!systemBuilt || pinned != pinnedSet) && !buildSystem(pinned)) {
    why = "symbolic Cholesky analysis failed";
    return false;
  }

  const std::size_t nv = vertexCount;
  const double alpha = params.massDamping;
  const double beta = params.stiffnessDamping;
  const std::vector<Vec3>& xn = x;
  const std::vector<Vec3>& vn = v;
  std::vector<Vec3> xTilde(nv), xk(nv), xTrial(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    xTilde[i] = xn[i] + h * vn[i] + (h * h) * params.gravity;
    if (pinTarget[i] >= 0)
      xk[i] = pinBuffer[static_cast<std::size_t>(pinTarget[i])].position;
    else if (freeIndex[i] >= 0)
      xk[i] = xn[i] + h * vn[i];  // predictor
    else
      xk[i] = xn[i];  // a vertex in no triangle stays put
  }

  const int n = 3 * freeCount;

  // Rayleigh stiffness damping: projected element stiffness frozen at x_n.
  const double dampScale = beta / h;
  if (beta > 0.0) {
    evaluate(xn, true, true);
    triDamp = triHess;
    hingeDamp = hingeHess;
  }
  auto dampProduct = [&](const std::vector<Vec3>& u, VecX& out) {  // out += beta/h K^_n u
    scatterProducts(triangles, triDamp, u, freeIndex, dampScale, out);
    scatterProducts(hingeVertices, hingeDamp, u, freeIndex, dampScale, out);
  };

  const double massDiag = 1.0 / (h * h) + alpha / h;

  findContacts(xn, xk, h, stats);
  // Coulomb friction with the lagged normal force (IPC's smoothed friction
  // potential, Li et al. 2020, Sec. 5): the tangential displacement over the
  // step u = T (x - x_n) costs mu lambda f0(|u|), where f0 is |u| beyond
  // eps = kFrictionSpeed h and a cubic below it (static friction as a stiff,
  // capped spring). frictionTerms gives the energy, and the gradient and
  // (PSD) Hessian block of one contact.
  const double eps = kFrictionSpeed * h;
  auto frictionTerms = [&](const ContactPlane& cp, const Vec3& xi, const Vec3& xni, Vec3* grad,
                           Mat3* hess) {
    if (!(cp.mu > 0.0) || !(cp.lambda > 0.0)) return 0.0;
    const Mat3 t = Mat3::Identity() - cp.normal * cp.normal.transpose();
    const Vec3 u = t * ((xi - xni) - cp.motion);
    const double y = u.norm();
    const double scale = cp.mu * cp.lambda;
    const double f0 = y >= eps ? y : -y * y * y / (3.0 * eps * eps) + y * y / eps + eps / 3.0;
    if (grad != nullptr) {
      const double f1OverY = y >= eps ? 1.0 / y : -y / (eps * eps) + 2.0 / eps;
      const double f1Prime = y >= eps ? 0.0 : -2.0 * y / (eps * eps) + 2.0 / eps;
      *grad = scale * f1OverY * u;
      if (hess != nullptr) {
        Mat3 inner = f1OverY * Mat3::Identity();
        if (y > 1e-300) {
          const Vec3 d = u / y;
          inner += (f1Prime - f1OverY) * d * d.transpose();
        }
        *hess = scale * t * inner * t;
      }
    }
    return scale * f0;
  };
  // Penalty and friction energy of the contacts at xs.
  auto contactEnergy = [&](const std::vector<Vec3>& xs) {
    double e = 0.0;
    for (const auto& cp : contactPlanes) {
      const auto vi = static_cast<std::size_t>(cp.vertex);
      const double gap = cp.gap(xs[vi], contact.distance, nullptr);
      if (gap > 0.0) e += 0.5 * cp.k * gap * gap;
      e += frictionTerms(cp, xs[vi], xn[vi], nullptr, nullptr);
    }
    for (const auto& fc : faceContacts) {
      const double gap =
          fc.gap(xs, triangles[static_cast<std::size_t>(fc.triangle)], contact.distance);
      if (gap > 0.0) e += 0.5 * fc.k * gap * gap;
    }
    return e;
  };
  static const bool debugNewton = [] {
    const char* e = std::getenv("CRUMPLE_DEBUG_NEWTON");
    return e != nullptr && e[0] == '1';
  }();
  const double tol = params.newtonTolerance * typicalEdge;
  VecX gradQ(n), gradV(n), grad(n), dx(n);
  std::vector<Vec3> disp(nv);
  // Nothing to solve when every vertex is pinned: the step is the pins.
  bool converged = n == 0;
  for (int it = 0; !converged && it < params.maxNewtonIterations; ++it) {
    // Exact element Hessians first (quadratic convergence); projected to PSD
    // only if the assembled system turns out not to be positive definite.
    evaluate(xk, true, false);
    ++stats.newtonIterations;

    // Gradient over the free DOFs: quadratic (inertia, gravity, damping) + elastic.
    gradQ.setZero();
    gradV.setZero();
    for (std::size_t i = 0; i < nv; ++i) {
      const int fi = freeIndex[i];
      if (fi < 0) continue;
      gradQ.segment<3>(3 * fi) =
          mass[i] * ((xk[i] - xTilde[i]) / (h * h) + (alpha / h) * (xk[i] - xn[i]));
    }
    if (beta > 0.0) {
      for (std::size_t i = 0; i < nv; ++i) disp[i] = xk[i] - xn[i];
      dampProduct(disp, gradQ);
    }
    scatterVectors(triangles, triGrad, freeIndex, 1.0, gradV);
    scatterVectors(hingeVertices, hingeGrad, freeIndex, 1.0, gradV);
    for (const auto& cp : contactPlanes) {
      const auto vi = static_cast<std::size_t>(cp.vertex);
      Vec3 n;
      const double gap = cp.gap(xk[vi], contact.distance, &n);
      if (gap > 0.0) gradV.segment<3>(3 * freeIndex[vi]) -= cp.k * gap * n;
      Vec3 g = Vec3::Zero();
      frictionTerms(cp, xk[vi], xn[vi], &g, nullptr);
      gradV.segment<3>(3 * freeIndex[vi]) += g;
    }
    for (const auto& fc : faceContacts) {
      const auto& tri = triangles[static_cast<std::size_t>(fc.triangle)];
      const double gap = fc.gap(xk, tri, contact.distance);
      if (!(gap > 0.0)) continue;
      for (std::size_t a = 0; a < 3; ++a) {
        const int fi = freeIndex[static_cast<std::size_t>(tri[a])];
        if (fi >= 0) gradV.segment<3>(3 * fi) -= fc.k * gap * fc.w[a] * fc.normal;
      }
    }
    grad = gradQ + gradV;
    if (!grad.allFinite()) {
      why = "non-finite forces";
      return false;
    }

    // Hessian: lumped mass / damping diagonal + element blocks, serially in
    // element order (bit-identical for any thread count).
    auto assemble = [&]() {
      double* values = matrix.valuePtr();
      std::fill(values, values + matrix.nonZeros(), 0.0);
      for (std::size_t i = 0; i < nv; ++i) {
        const int fi = freeIndex[i];
        if (fi < 0) continue;
        for (int c = 0; c < 3; ++c)
          values[diagOffset[static_cast<std::size_t>(3 * fi + c)]] += mass[i] * massDiag;
      }
      scatterBlocks(triHess, beta > 0.0 ? &triDamp : nullptr, dampScale, triOffset, values);
      scatterBlocks(hingeHess, beta > 0.0 ? &hingeDamp : nullptr, dampScale, hingeOffset, values);
      for (const auto& cp : contactPlanes) {
        const auto vi = static_cast<std::size_t>(cp.vertex);
        Mat3 block = Mat3::Zero();
        // Gauss-Newton for a triangle's distance: the curvature term of
        // |x - q| is left out (it would make the block indefinite).
        Vec3 n;
        if (cp.gap(xk[vi], contact.distance, &n) > 0.0) block += cp.k * n * n.transpose();
        Vec3 g;
        Mat3 hf = Mat3::Zero();
        frictionTerms(cp, xk[vi], xn[vi], &g, &hf);
        block += hf;
        const int* off = vertexOffset.data() + 9 * freeIndex[vi];
        for (int col = 0; col < 3; ++col)
          for (int row = col; row < 3; ++row) values[off[col * 3 + row]] += block(row, col);
      }
      for (const auto& fc : faceContacts) {
        const auto& tri = triangles[static_cast<std::size_t>(fc.triangle)];
        if (!(fc.gap(xk, tri, contact.distance) > 0.0)) continue;
        Vec9 g;
        for (int a = 0; a < 3; ++a)
          g.segment<3>(3 * a) = fc.w[static_cast<std::size_t>(a)] * fc.normal;
        const Mat9 block = fc.k * g * g.transpose();
        const int* off = triOffset.data() + 81 * fc.triangle;
        for (int i = 0; i < 81; ++i)
          if (off[i] >= 0) values[off[i]] += block.data()[i];
      }
      return Eigen::Map<const VecX>(values, matrix.nonZeros()).allFinite();
    };
    if (!assemble()) {
      why = "non-finite stiffness matrix";
      return false;
    }
    solver.factorize(matrix);
    ++stats.solves;
    bool projected = false;
    if (solver.info() != Eigen::Success) {
      projected = true;
      // Indefinite (compressed membrane, bent hinges): project every element
      // block to PSD; with the positive mass term the system is then SPD.
      projectHessians();
      if (!assemble()) {
        why = "non-finite stiffness matrix";
        return false;
      }
      solver.factorize(matrix);
      ++stats.solves;
      if (solver.info() != Eigen::Success) {
        why = "Cholesky factorisation failed";
        return false;
      }
    }
    dx = solver.solve(-grad);
    if (solver.info() != Eigen::Success || !dx.allFinite()) {
      why = "Cholesky solve failed";
      return false;
    }
    const double stepNorm = dx.lpNorm<Eigen::Infinity>();
    stats.finalStepNorm = stepNorm;

    auto applyStep = [&](double s) {
      xTrial = xk;
      for (std::size_t i = 0; i < nv; ++i) {
        const int fi = freeIndex[i];
        if (fi >= 0) xTrial[i] = xk[i] + s * dx.segment<3>(3 * fi);
      }
    };
    if (stepNorm <= tol) {
      applyStep(1.0);
      xk.swap(xTrial);
      converged = true;
      break;
    }

    // Backtracking line search on Phi (Armijo).
    const double slope = grad.dot(dx);
    if (!(slope < 0.0)) {
      why = "Newton direction is not a descent direction";
      return false;
    }
    // Exact change of the quadratic part: s gradQ.dx + s^2/2 dx^T Q dx.
    double curvature = 0.0;
    for (std::size_t i = 0; i < nv; ++i) {
      const int fi = freeIndex[i];
      if (fi >= 0) curvature += mass[i] * massDiag * dx.segment<3>(3 * fi).squaredNorm();
    }
    if (beta > 0.0) {
      for (std::size_t i = 0; i < nv; ++i) {
        const int fi = freeIndex[i];
        disp[i] = fi >= 0 ? Vec3(dx.segment<3>(3 * fi)) : Vec3::Zero();
      }
      VecX kd = VecX::Zero(n);
      dampProduct(disp, kd);
      curvature += kd.dot(dx);
    }
    const double slopeQ = gradQ.dot(dx);
    const double contactNow = contactEnergy(xk);
    double s = 1.0;
    bool accepted = false;
    for (int ls = 0; ls <= kMaxLineSearchHalvings; ++ls, s *= 0.5) {
      applyStep(s);
      evaluateEnergies(xTrial);
      double deltaV = 0.0;
      for (std::size_t i = 0; i < triangles.size(); ++i) deltaV += triTrial[i] - triEnergy[i];
      for (std::size_t k = 0; k < hinges.size(); ++k) deltaV += hingeTrial[k] - hingeEnergy[k];
      if (!contactPlanes.empty() || !faceContacts.empty())
        deltaV += contactEnergy(xTrial) - contactNow;
      const double deltaPhi = s * slopeQ + 0.5 * s * s * curvature + deltaV;
      if (std::isfinite(deltaPhi) && deltaPhi <= kArmijo * s * slope) {
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      // Within a hundred tolerances of the solution the energy decrease of
      // the Newton step is below Phi's rounding: the iterate is as converged
      // as the arithmetic allows.
      if (stepNorm <= 100.0 * tol) {
        converged = true;
        break;
      }
      why = "line search found no decrease";
      return false;
    }
    if (debugNewton) {
      std::size_t worst = 0;
      double wn = -1.0;
      for (std::size_t i = 0; i < nv; ++i) {
        const int fi = freeIndex[i];
        if (fi >= 0 && dx.segment<3>(3 * fi).norm() > wn) {
          wn = dx.segment<3>(3 * fi).norm();
          worst = i;
        }
      }
      std::fprintf(
          stderr, "[newton] h %.3g it %d step %.3e s %.3g worst v %zu mass %.3g (mean %.3g)%s\n", h,
          it, stepNorm, s, worst, mass[worst], std::accumulate(mass.begin(), mass.end(), 0.0) / nv,
          projected ? " projected" : "");
    }
    xk.swap(xTrial);
  }
  if (!converged) {
    std::ostringstream os;
    os << "Newton did not converge in " << params.maxNewtonIterations << " iterations (last step "
       << stats.finalStepNorm << " m)";
    why = os.str();
    return false;
  }
  if (!finite(xk)) {
    why = "non-finite positions";
    return false;
  }
  std::vector<Pushed> pushed;
  lastContacts.clear();
  if (!contactPlanes.empty() || !faceContacts.empty() || collidersOn())
    resolveContacts(xn, xk, h, stats, pushed);
  for (std::size_t i = 0; i < nv; ++i) {
    v[i] = (xk[i] - xn[i]) / h;
    x[i] = xk[i];
  }
  // A pushed vertex keeps no velocity into the surface it was pushed out of
  // (relative to that surface's own velocity).
  for (const Pushed& p : pushed)
    v[p.vertex] -= std::min(0.0, (v[p.vertex] - p.surfaceVelocity).dot(p.normal)) * p.normal;
  trackBranches(x);
  return true;
}

// Substep halving: a failed step is retried as two halves, recursively. The
// end times are passed through exactly, so the last substep asks the pins
// for exactly t + dt.
bool ElasticSheet::Impl::stepRecursive(double t0, double t1, const PinFunction& pins, int depth,
                                       StepStats& stats, std::string& why) {
  if (substep(t0, t1, pins, stats, why)) return true;
  if (depth >= params.maxHalvings) return false;
  ++stats.halvings;
  const double mid = t0 + 0.5 * (t1 - t0);
  if (!stepRecursive(t0, mid, pins, depth + 1, stats, why)) return false;
  return stepRecursive(mid, t1, pins, depth + 1, stats, why);
}

// ---------------------------------------------------------------------------

ElasticSheet::ElasticSheet(const mesh::SheetMesh& mesh, const Material& material,
                           const SimParams& params)
    : impl_(std::make_unique<Impl>(mesh, material, params)) {}
ElasticSheet::~ElasticSheet() = default;
ElasticSheet::ElasticSheet(ElasticSheet&&) noexcept = default;
ElasticSheet& ElasticSheet::operator=(ElasticSheet&&) noexcept = default;

const std::vector<mesh::MeshEdge>& ElasticSheet::hinges() const { return impl_->hinges; }

void ElasticSheet::setHingeRestAngle(std::size_t hinge, double angle) {
  if (hinge >= impl_->hinges.size()) throw std::out_of_range("ElasticSheet: hinge index");
  if (!std::isfinite(angle)) throw std::invalid_argument("ElasticSheet: non-finite rest angle");
  impl_->hingeRest[hinge] = angle;
}

void ElasticSheet::setHingeStiffnessFactor(std::size_t hinge, double factor) {
  if (hinge >= impl_->hinges.size()) throw std::out_of_range("ElasticSheet: hinge index");
  if (!(factor >= 0.0) || !std::isfinite(factor))
    throw std::invalid_argument("ElasticSheet: stiffness factor must be finite and >= 0");
  impl_->hingeFactor[hinge] = factor;
}

double ElasticSheet::hingeRestAngle(std::size_t hinge) const { return impl_->hingeRest.at(hinge); }
double ElasticSheet::hingeStiffnessFactor(std::size_t hinge) const {
  return impl_->hingeFactor.at(hinge);
}
double ElasticSheet::hingeAngle(std::size_t hinge) const {
  if (hinge >= impl_->hingeVertices.size()) throw std::out_of_range("ElasticSheet::hingeAngle");
  return impl_->continuousAngle(hinge, impl_->x);
}

StepStats ElasticSheet::advance(double t, double dt, const PinFunction& pins) {
  if (!(dt > 0.0) || !std::isfinite(dt) || !std::isfinite(t))
    throw std::invalid_argument("ElasticSheet::advance: need finite t and dt > 0");
  StepStats stats;
  const std::vector<Vec3> x0 = impl_->x, v0 = impl_->v;
  std::string why;
  bool ok = false;
  try {
    ok = impl_->stepRecursive(t, t + dt, pins, 0, stats, why);
  } catch (...) {
    impl_->x = x0;
    impl_->v = v0;
    throw;
  }
  // Recovery (issue 9, stability), only for a step that failed at every
  // halving (a path the samples never take). If self-contact ran, the step
  // is taken again without it: its penalty can keep a handle jumping through
  // the sheet or a tight twist from converging. Then, as the projected Newton
  // iteration converges only linearly near tight folds, with
  // kRetryIterationFactor times the iterations (and up to 3 halvings), with
  // self-contact and, if it ran, without. Only then does the shot stop.
  const auto retry = [&](int maxIterations, SelfContactMode self, int depth, const char* what) {
    impl_->x = x0;
    impl_->v = v0;
    const int savedIterations = impl_->params.maxNewtonIterations;
    const SelfContactMode savedSelf = impl_->contact.self;
    impl_->params.maxNewtonIterations = maxIterations;
    impl_->contact.self = self;
    StepStats more;
    std::string moreWhy;
    bool done = false;
    try {
      done = impl_->stepRecursive(t, t + dt, pins, depth, more, moreWhy);
    } catch (...) {
      impl_->params.maxNewtonIterations = savedIterations;
      impl_->contact.self = savedSelf;
      impl_->x = x0;
      impl_->v = v0;
      throw;
    }
    impl_->params.maxNewtonIterations = savedIterations;
    impl_->contact.self = savedSelf;
    stats.newtonIterations += more.newtonIterations;
    stats.halvings += more.halvings;
    stats.solves += more.solves;
    stats.finalStepNorm = more.finalStepNorm;
    stats.contactMs += more.contactMs;
    stats.selfContactMs += more.selfContactMs;
    if (!done) why += std::string("; ") + what + ": " + moreWhy;
    return done;
  };
  const SimParams& p = impl_->params;
  const bool selfRan = impl_->contact.self != SelfContactMode::Off && stats.selfContactSteps > 0;
  if (!ok && selfRan && p.recoverFailedSteps) {
    ok = retry(p.maxNewtonIterations, SelfContactMode::Off, 0, "without self-contact");
    if (ok) stats.selfContactDropped = 1;
  }
  const SelfContactMode modes[] = {impl_->contact.self, SelfContactMode::Off};
  for (int k = 0; k < (selfRan ? 2 : 1) && !ok && p.recoverFailedSteps; ++k) {
    ok = retry(kRetryIterationFactor * p.maxNewtonIterations, modes[k],
               std::max(0, p.maxHalvings - 3),
               k == 1 ? "with more Newton iterations, without self-contact"
                      : "with more Newton iterations");
    if (ok) stats.newtonRetried = 1;
    if (ok && k == 1) stats.selfContactDropped = 1;
  }
  if (!ok) {
    impl_->x = x0;
    impl_->v = v0;
    std::ostringstream os;
    os << "step from t = " << t << " s by " << dt << " s failed after " << stats.halvings
       << " halvings (maxHalvings " << impl_->params.maxHalvings << "): " << why;
    throw NumericalError("elastic", os.str());
  }
  return stats;
}

void mergeContactSamples(std::vector<ContactSample>& samples) {
  std::sort(samples.begin(), samples.end(), [](const ContactSample& l, const ContactSample& r) {
    return l.vertex != r.vertex ? l.vertex < r.vertex : l.collider < r.collider;
  });
  std::vector<ContactSample> merged;
  merged.reserve(samples.size());
  for (const ContactSample& s : samples) {
    if (!merged.empty() && merged.back().vertex == s.vertex &&
        merged.back().collider == s.collider) {
      merged.back().normalForce += s.normalForce;
      merged.back().slideSpeed = std::max(merged.back().slideSpeed, s.slideSpeed);
    } else {
      merged.push_back(s);
    }
  }
  samples = std::move(merged);
}

void ElasticSheet::setContacts(ContactOptions options) {
  const bool any = (options.colliders != nullptr && options.colliders->size() > 0) ||
                   options.self != SelfContactMode::Off;
  if (any && !(options.distance > 0.0 && std::isfinite(options.distance)))
    throw std::invalid_argument("ElasticSheet::setContacts: contact distance must be > 0");
  if (!(options.selfFriction >= 0.0) || !std::isfinite(options.selfFriction))
    throw std::invalid_argument("ElasticSheet::setContacts: friction must be finite and >= 0");
  if (!(options.foldSpread > 0.0) || !std::isfinite(options.foldSpread))
    throw std::invalid_argument("ElasticSheet::setContacts: fold spread must be > 0");
  if (impl_->selfDetector && options.distance != impl_->contact.distance)
    impl_->selfDetector.reset();
  impl_->contact = std::move(options);
  impl_->lastContacts.clear();
}

std::vector<ElasticSheet::TriangleForce> ElasticSheet::membraneForcesOn(int vertex) const {
  const Impl& m = *impl_;
  if (vertex < 0 || static_cast<std::size_t>(vertex) >= m.vertexCount)
    throw std::out_of_range("ElasticSheet::membraneForcesOn: no vertex " + std::to_string(vertex));
  std::vector<TriangleForce> out;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto& tri = m.triangles[t];
    for (int a = 0; a < 3; ++a) {
      if (tri[static_cast<std::size_t>(a)] != vertex) continue;
      Vec9 gradient;
      sim::membraneEnergy(
          m.x[static_cast<std::size_t>(tri[0])], m.x[static_cast<std::size_t>(tri[1])],
          m.x[static_cast<std::size_t>(tri[2])], m.triangleRests[t], m.moduli, &gradient);
      out.push_back({static_cast<int>(t), -gradient.segment<3>(3 * a)});
    }
  }
  return out;
}

long ElasticSheet::contactVertexSteps() const { return impl_->contactVertexSteps; }
const std::vector<ContactSample>& ElasticSheet::contacts() const { return impl_->lastContacts; }

void ElasticSheet::saveState(StateWriter& out) const {
  const Impl& s = *impl_;
  out.tag("ELAS");
  out.vec3s(s.x);
  out.vec3s(s.v);
  out.f64s(s.hingeRest);
  out.f64s(s.hingeFactor);
  out.f64s(s.hingeBranch);
  saveContactSamples(out, s.lastContacts);
}

void saveContactSamples(StateWriter& out, const std::vector<ContactSample>& samples) {
  out.count(samples.size());
  for (const auto& c : samples) {
    out.i32(c.vertex);
    out.i32(c.collider);
    out.f64(c.slideSpeed);
    out.f64(c.normalForce);
  }
}

std::vector<ContactSample> restoreContactSamples(StateReader& in, std::size_t vertexCount) {
  std::vector<ContactSample> samples(in.count(24));
  for (auto& c : samples) {
    c.vertex = in.i32();
    c.collider = in.i32();
    c.slideSpeed = in.f64();
    c.normalForce = in.f64();
    if (c.vertex < 0 || static_cast<std::size_t>(c.vertex) >= vertexCount)
      in.fail("a contact's vertex is out of range");
  }
  return samples;
}

void ElasticSheet::restoreState(StateReader& in) {
  Impl& s = *impl_;
  in.tag("ELAS");
  std::vector<Vec3> x = in.vec3s(), v = in.vec3s();
  std::vector<double> rest = in.f64s(), factor = in.f64s(), branch = in.f64s();
  if (x.size() != s.vertexCount || v.size() != s.vertexCount)
    in.fail("the elastic state has " + std::to_string(x.size()) + " vertices, the sheet " +
            std::to_string(s.vertexCount));
  if (rest.size() != s.hinges.size() || factor.size() != s.hinges.size() ||
      branch.size() != s.hinges.size())
    in.fail("the elastic state's hinges do not match the sheet's " +
            std::to_string(s.hinges.size()));
  std::vector<ContactSample> contacts = restoreContactSamples(in, s.vertexCount);
  s.x = std::move(x);
  s.v = std::move(v);
  s.hingeRest = std::move(rest);
  s.hingeFactor = std::move(factor);
  s.hingeBranch = std::move(branch);
  s.lastContacts = std::move(contacts);
}

const std::vector<Vec3>& ElasticSheet::positions() const { return impl_->x; }
const std::vector<Vec3>& ElasticSheet::velocities() const { return impl_->v; }

void ElasticSheet::setPositions(const std::vector<Vec3>& x) {
  if (x.size() != impl_->vertexCount)
    throw std::invalid_argument("ElasticSheet::setPositions: wrong vertex count");
  if (!finite(x)) throw std::invalid_argument("ElasticSheet::setPositions: non-finite position");
  impl_->x = x;
  impl_->trackBranches(x);
}

void ElasticSheet::setVelocities(const std::vector<Vec3>& v) {
  if (v.size() != impl_->vertexCount)
    throw std::invalid_argument("ElasticSheet::setVelocities: wrong vertex count");
  if (!finite(v)) throw std::invalid_argument("ElasticSheet::setVelocities: non-finite velocity");
  impl_->v = v;
}

double ElasticSheet::kineticEnergy() const {
  double e = 0.0;
  for (std::size_t i = 0; i < impl_->vertexCount; ++i)
    e += 0.5 * impl_->mass[i] * impl_->v[i].squaredNorm();
  return e;
}

double ElasticSheet::membraneEnergy() const {
  const Impl& m = *impl_;
  double e = 0.0;
  for (std::size_t i = 0; i < m.triangles.size(); ++i) {
    const auto& t = m.triangles[i];
    e += sim::membraneEnergy(m.x[static_cast<std::size_t>(t[0])],
                             m.x[static_cast<std::size_t>(t[1])],
                             m.x[static_cast<std::size_t>(t[2])], m.triangleRests[i], m.moduli);
  }
  return e;
}

double ElasticSheet::bendingEnergy() const {
  const Impl& m = *impl_;
  double e = 0.0;
  for (std::size_t k = 0; k < m.hingeVertices.size(); ++k) {
    const double d = m.deviation(k, m.rawAngle(k, m.x));
    e += m.hingeStiffnessOf(k) * d * d;
  }
  return e;
}

double ElasticSheet::maxMembraneStrain() const {
  const Impl& m = *impl_;
  double worst = 0.0;
  for (std::size_t i = 0; i < m.triangles.size(); ++i) {
    const auto& t = m.triangles[i];
    worst = std::max(worst,
                     maxAbsPrincipal(greenStrain(
                         m.x[static_cast<std::size_t>(t[0])], m.x[static_cast<std::size_t>(t[1])],
                         m.x[static_cast<std::size_t>(t[2])], m.triangleRests[i])));
  }
  return worst;
}

int ElasticSheet::analyzeCount() const { return impl_->analyzeCount; }
bool ElasticSheet::supernodalFactorization() const { return impl_->supernodal; }
double ElasticSheet::typicalEdgeLength() const { return impl_->typicalEdge; }

}  // namespace crumple::sim
