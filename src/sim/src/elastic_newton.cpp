// ElasticSheet's backward Euler step: Newton on the incremental potential
// with a backtracking line search, substep halving and the recovery of a
// step that failed at every halving (the method: elastic_sheet.cpp's header
// comment; paper Sec. 4, thesis 2.3.1).
#include "crumple/core/debug.hpp"
#include "crumple/core/work_budget.hpp"
#include "crumple/sim/elastic_sheet.hpp"
#include "elastic_sheet_impl.hpp"

namespace crumple::sim {

bool ElasticSheet::Impl::collectPins(double t1, const PinFunction& pins, std::string& why) {
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
  return true;
}

bool ElasticSheet::Impl::collectGrips(double t1, std::string& why) {
  gripBuffer.clear();
  if (grips) grips(t1, gripBuffer);
  for (const Grip& g : gripBuffer) {
    if (g.triangle < 0 || static_cast<std::size_t>(g.triangle) >= triangles.size())
      throw std::out_of_range("ElasticSheet: grip on triangle " + std::to_string(g.triangle) +
                              " (mesh has " + std::to_string(triangles.size()) + ")");
    if (!g.position.allFinite() || !g.weights.allFinite() || !std::isfinite(g.stiffness) ||
        g.stiffness < 0.0) {
      why = "non-finite or negative grip on triangle " + std::to_string(g.triangle);
      return false;
    }
  }
  return true;
}

double ElasticSheet::Impl::gripEnergy(const std::vector<Vec3>& xs) const {
  double e = 0.0;
  for (const Grip& g : gripBuffer) {
    const auto& t = triangles[static_cast<std::size_t>(g.triangle)];
    e += sim::gripEnergy(xs[static_cast<std::size_t>(t[0])], xs[static_cast<std::size_t>(t[1])],
                         xs[static_cast<std::size_t>(t[2])], g.weights, g.position, g.stiffness);
  }
  return e;
}

void ElasticSheet::Impl::startNewton(NewtonState& s) {
  const double h = s.h;
  const std::size_t nv = vertexCount;
  s.massDiag = 1.0 / (h * h) + params.massDamping / h;
  s.dampScale = params.stiffnessDamping / h;
  s.frictionEps = kFrictionSpeed * h;
  s.xTilde.resize(nv);
  s.xk.resize(nv);
  s.xTrial.resize(nv);
  s.disp.resize(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    s.xTilde[i] = x[i] + h * v[i] + (h * h) * params.gravity;
    if (pinTarget[i] >= 0)
      s.xk[i] = pinBuffer[static_cast<std::size_t>(pinTarget[i])].position;
    else if (freeIndex[i] >= 0)
      s.xk[i] = x[i] + h * v[i];  // predictor
    else
      s.xk[i] = x[i];  // a vertex in no triangle stays put
  }
  const int n = 3 * freeCount;
  s.gradQ.resize(n);
  s.gradV.resize(n);
  s.grad.resize(n);
  s.dx.resize(n);
  // Rayleigh stiffness damping: projected element stiffness frozen at x_n.
  if (params.stiffnessDamping > 0.0) {
    evaluate(x, true, true);
    triDamp = triHess;
    hingeDamp = hingeHess;
  }
}

void ElasticSheet::Impl::dampProduct(const std::vector<Vec3>& u, double dampScale,
                                     VecX& out) const {
  scatterProducts(triangles, triDamp, u, freeIndex, dampScale, out);
  scatterProducts(hingeVertices, hingeDamp, u, freeIndex, dampScale, out);
}

double ElasticSheet::Impl::contactEnergy(const std::vector<Vec3>& xs, double eps) const {
  double e = 0.0;
  for (const auto& cp : contactPlanes) {
    const auto vi = static_cast<std::size_t>(cp.vertex);
    if (double penalty = 0.0; cp.penalty(xs[vi], contact.distance, penalty, nullptr, nullptr))
      e += penalty;
    e += cp.friction(xs[vi], x[vi], eps, nullptr, nullptr);
  }
  for (const auto& fc : faceContacts) {
    const auto& tri = triangles[static_cast<std::size_t>(fc.triangle)];
    if (double penalty = 0.0; fc.penalty(
            xs[static_cast<std::size_t>(tri[0])], xs[static_cast<std::size_t>(tri[1])],
            xs[static_cast<std::size_t>(tri[2])], contact.distance, penalty, nullptr, nullptr))
      e += penalty;
  }
  return e;
}

bool ElasticSheet::Impl::newtonGradient(NewtonState& s, std::string& why) {
  // Gradient over the free DOFs: quadratic (inertia, gravity, damping) + elastic.
  const std::size_t nv = vertexCount;
  const double h = s.h;
  const double alpha = params.massDamping;
  const std::vector<Vec3>& xk = s.xk;
  s.gradQ.setZero();
  s.gradV.setZero();
  for (std::size_t i = 0; i < nv; ++i) {
    const int fi = freeIndex[i];
    if (fi < 0) continue;
    s.gradQ.segment<3>(3 * fi) =
        mass[i] * ((xk[i] - s.xTilde[i]) / (h * h) + (alpha / h) * (xk[i] - x[i]));
  }
  if (params.stiffnessDamping > 0.0) {
    for (std::size_t i = 0; i < nv; ++i) s.disp[i] = xk[i] - x[i];
    dampProduct(s.disp, s.dampScale, s.gradQ);
  }
  scatterVectors(triangles, triGrad, freeIndex, 1.0, s.gradV);
  scatterVectors(hingeVertices, hingeGrad, freeIndex, 1.0, s.gradV);
  for (const auto& cp : contactPlanes) {
    const auto vi = static_cast<std::size_t>(cp.vertex);
    double penalty = 0.0;
    if (Vec3 g; cp.penalty(xk[vi], contact.distance, penalty, &g, nullptr))
      s.gradV.segment<3>(3 * freeIndex[vi]) += g;
    Vec3 g = Vec3::Zero();
    cp.friction(xk[vi], x[vi], s.frictionEps, &g, nullptr);
    s.gradV.segment<3>(3 * freeIndex[vi]) += g;
  }
  for (const auto& fc : faceContacts) {
    const auto& tri = triangles[static_cast<std::size_t>(fc.triangle)];
    double penalty = 0.0;
    Vec9 g;
    if (!fc.penalty(xk[static_cast<std::size_t>(tri[0])], xk[static_cast<std::size_t>(tri[1])],
                    xk[static_cast<std::size_t>(tri[2])], contact.distance, penalty, &g, nullptr))
      continue;
    for (std::size_t a = 0; a < 3; ++a) {
      const int fi = freeIndex[static_cast<std::size_t>(tri[a])];
      if (fi >= 0) s.gradV.segment<3>(3 * fi) += g.segment<3>(3 * static_cast<int>(a));
    }
  }
  for (const Grip& grip : gripBuffer) {
    const auto& tri = triangles[static_cast<std::size_t>(grip.triangle)];
    Vec9 g;
    sim::gripEnergy(xk[static_cast<std::size_t>(tri[0])], xk[static_cast<std::size_t>(tri[1])],
                    xk[static_cast<std::size_t>(tri[2])], grip.weights, grip.position,
                    grip.stiffness, &g);
    for (std::size_t a = 0; a < 3; ++a) {
      const int fi = freeIndex[static_cast<std::size_t>(tri[a])];
      if (fi >= 0) s.gradV.segment<3>(3 * fi) += g.segment<3>(3 * static_cast<int>(a));
    }
  }
  if (air) {
    const auto begin = std::chrono::steady_clock::now();
    addAirGradient(xk, h, s.gradV);
    s.airMs += msSince(begin);
  }
  s.grad = s.gradQ + s.gradV;
  if (!s.grad.allFinite()) {
    why = "non-finite forces";
    return false;
  }
  return true;
}

// Hessian: lumped mass / damping diagonal + element blocks, serially in
// element order (bit-identical for any thread count).
bool ElasticSheet::Impl::assembleSystem(const NewtonState& s) {
  const std::vector<Vec3>& xk = s.xk;
  double* values = matrix.valuePtr();
  std::fill(values, values + matrix.nonZeros(), 0.0);
  for (std::size_t i = 0; i < vertexCount; ++i) {
    const int fi = freeIndex[i];
    if (fi < 0) continue;
    for (int c = 0; c < 3; ++c)
      values[diagOffset[static_cast<std::size_t>(3 * fi + c)]] += mass[i] * s.massDiag;
  }
  const bool damped = params.stiffnessDamping > 0.0;
  if (air) {
    // Not timed as the air's: it adds 9 blocks per triangle to the
    // membrane's own scatter (airMs has their computation, in the gradient).
    scatterTrianglesWithAir(s.dampScale, values);
  } else {
    scatterBlocks(triHess, damped ? &triDamp : nullptr, s.dampScale, triOffset, values);
  }
  scatterBlocks(hingeHess, damped ? &hingeDamp : nullptr, s.dampScale, hingeOffset, values);
  for (const auto& cp : contactPlanes) {
    const auto vi = static_cast<std::size_t>(cp.vertex);
    Mat3 block = Mat3::Zero();
    // Gauss-Newton for a triangle's distance (VertexContact::penalty).
    double penalty = 0.0;
    if (Mat3 hp; cp.penalty(xk[vi], contact.distance, penalty, nullptr, &hp)) block += hp;
    Vec3 g;
    Mat3 hf = Mat3::Zero();
    cp.friction(xk[vi], x[vi], s.frictionEps, &g, &hf);
    block += hf;
    const int* off = vertexOffset.data() + 9 * freeIndex[vi];
    for (int col = 0; col < 3; ++col)
      for (int row = col; row < 3; ++row) values[off[col * 3 + row]] += block(row, col);
  }
  for (const auto& fc : faceContacts) {
    const auto& tri = triangles[static_cast<std::size_t>(fc.triangle)];
    double penalty = 0.0;
    Mat9 block;
    if (!fc.penalty(xk[static_cast<std::size_t>(tri[0])], xk[static_cast<std::size_t>(tri[1])],
                    xk[static_cast<std::size_t>(tri[2])], contact.distance, penalty, nullptr,
                    &block))
      continue;
    const int* off = triOffset.data() + 81 * fc.triangle;
    for (int i = 0; i < 81; ++i)
      if (off[i] >= 0) values[off[i]] += block.data()[i];
  }
  for (const Grip& grip : gripBuffer) {
    // k (w w^T) (x) I_3: constant, positive semi-definite.
    const int* off = triOffset.data() + 81 * grip.triangle;
    for (int b = 0; b < 3; ++b)
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) {
          const int i = (3 * b + c) * 9 + (3 * a + c);  // column-major (row 3a+c, column 3b+c)
          if (off[i] >= 0) values[off[i]] += grip.stiffness * grip.weights(a) * grip.weights(b);
        }
  }
  return Eigen::Map<const VecX>(values, matrix.nonZeros()).allFinite();
}

bool ElasticSheet::Impl::newtonDirection(NewtonState& s, StepStats& stats, bool& projected,
                                         std::string& why) {
  if (!assembleSystem(s)) {
    why = "non-finite stiffness matrix";
    return false;
  }
  solver.factorize(matrix);
  ++stats.solves;
  projected = false;
  if (solver.info() != Eigen::Success) {
    projected = true;
    // Indefinite (compressed membrane, bent hinges): project every element
    // block to PSD; with the positive mass term the system is then SPD.
    projectHessians();
    if (!assembleSystem(s)) {
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
  s.dx = solver.solve(-s.grad);
  if (solver.info() != Eigen::Success || !s.dx.allFinite()) {
    why = "Cholesky solve failed";
    return false;
  }
  return true;
}

void ElasticSheet::Impl::applyStep(NewtonState& s, double step) const {
  s.xTrial = s.xk;
  for (std::size_t i = 0; i < vertexCount; ++i) {
    const int fi = freeIndex[i];
    if (fi >= 0) s.xTrial[i] = s.xk[i] + step * s.dx.segment<3>(3 * fi);
  }
}

ElasticSheet::Impl::LineSearchResult ElasticSheet::Impl::lineSearch(NewtonState& s, double stepNorm,
                                                                    double tol, double& step,
                                                                    std::string& why) {
  // Backtracking line search on Phi (Armijo).
  const double slope = s.grad.dot(s.dx);
  if (!(slope < 0.0)) {
    why = "Newton direction is not a descent direction";
    return LineSearchResult::Failed;
  }
  // Exact change of the quadratic part: s gradQ.dx + s^2/2 dx^T Q dx.
  const std::size_t nv = vertexCount;
  double curvature = 0.0;
  for (std::size_t i = 0; i < nv; ++i) {
    const int fi = freeIndex[i];
    if (fi >= 0) curvature += mass[i] * s.massDiag * s.dx.segment<3>(3 * fi).squaredNorm();
  }
  if (params.stiffnessDamping > 0.0) {
    for (std::size_t i = 0; i < nv; ++i) {
      const int fi = freeIndex[i];
      s.disp[i] = fi >= 0 ? Vec3(s.dx.segment<3>(3 * fi)) : Vec3::Zero();
    }
    VecX kd = VecX::Zero(3 * freeCount);
    dampProduct(s.disp, s.dampScale, kd);
    curvature += kd.dot(s.dx);
  }
  const double slopeQ = s.gradQ.dot(s.dx);
  const double contactNow = contactEnergy(s.xk, s.frictionEps) + gripEnergy(s.xk);
  const auto airTimed = [&](const std::vector<Vec3>& xs) {
    const auto begin = std::chrono::steady_clock::now();
    const double e = airEnergy(xs, s.h);
    s.airMs += msSince(begin);
    return e;
  };
  // The air's energy at xk is the accepted trial's of the last line search
  // when nothing moved xk since (NewtonState::airAtXk).
  const double airNow = air ? (s.airAtXk ? *s.airAtXk : airTimed(s.xk)) : 0.0;
  s.airAtXk.reset();
  step = 1.0;
  for (int ls = 0; ls <= kMaxLineSearchHalvings; ++ls, step *= 0.5) {
    applyStep(s, step);
    evaluateEnergies(s.xTrial);
    double deltaV = 0.0;
    for (std::size_t i = 0; i < triangles.size(); ++i) deltaV += triTrial[i] - triEnergy[i];
    for (std::size_t k = 0; k < hinges.size(); ++k) deltaV += hingeTrial[k] - hingeEnergy[k];
    if (!contactPlanes.empty() || !faceContacts.empty() || !gripBuffer.empty())
      deltaV += contactEnergy(s.xTrial, s.frictionEps) + gripEnergy(s.xTrial) - contactNow;
    const double airTrial = air ? airTimed(s.xTrial) : 0.0;
    if (air) deltaV += airTrial - airNow;
    const double deltaPhi = step * slopeQ + 0.5 * step * step * curvature + deltaV;
    if (std::isfinite(deltaPhi) && deltaPhi <= kArmijo * step * slope) {
      if (air) s.airAtXk = airTrial;  // xTrial becomes xk
      return LineSearchResult::Accepted;
    }
  }
  // Within a hundred tolerances of the solution the energy decrease of the
  // Newton step is below Phi's rounding: the iterate is as converged as the
  // arithmetic allows.
  if (stepNorm <= 100.0 * tol) return LineSearchResult::Converged;
  why = "line search found no decrease";
  return LineSearchResult::Failed;
}

void ElasticSheet::Impl::traceNewtonIteration(const NewtonState& s, int it, double stepNorm,
                                              double step, bool projected) const {
  std::size_t worst = 0;
  double wn = -1.0;
  for (std::size_t i = 0; i < vertexCount; ++i) {
    const int fi = freeIndex[i];
    if (fi >= 0 && s.dx.segment<3>(3 * fi).norm() > wn) {
      wn = s.dx.segment<3>(3 * fi).norm();
      worst = i;
    }
  }
  std::fprintf(stderr,
               "[newton] h %.3g it %d step %.3e s %.3g worst v %zu mass %.3g (mean %.3g)%s\n", s.h,
               it, stepNorm, step, worst, mass[worst],
               std::accumulate(mass.begin(), mass.end(), 0.0) / static_cast<double>(vertexCount),
               projected ? " projected" : "");
}

bool ElasticSheet::Impl::finishSubstep(NewtonState& s, StepStats& stats, std::string& why) {
  if (!finite(s.xk)) {
    why = "non-finite positions";
    return false;
  }
  std::vector<Pushed> pushed;
  lastContacts.clear();
  if (!contactPlanes.empty() || !faceContacts.empty() || collidersOn())
    resolveContacts(x, s.xk, s.h, stats, pushed);
  for (std::size_t i = 0; i < vertexCount; ++i) {
    v[i] = (s.xk[i] - x[i]) / s.h;
    x[i] = s.xk[i];
  }
  // A pushed vertex keeps no velocity into the surface it was pushed out of
  // (relative to that surface's own velocity).
  for (const Pushed& p : pushed)
    v[p.vertex] -= std::min(0.0, (v[p.vertex] - p.surfaceVelocity).dot(p.normal)) * p.normal;
  trackBranches(x);
  return true;
}

bool ElasticSheet::Impl::newtonLoop(NewtonState& s, StepStats& stats, std::string& why) {
  const bool debugNewton = debugOptions().newton;
  const double tol = params.newtonTolerance * typicalEdge;
  // Nothing to solve when every vertex is pinned: the step is the pins.
  bool converged = freeCount == 0;
  for (int it = 0; !converged && it < params.maxNewtonIterations; ++it) {
    checkWorkBudget("elastic");  // the shot's cost guard (core/work_budget.hpp)
    // Exact element Hessians first (quadratic convergence); projected to PSD
    // only if the assembled system turns out not to be positive definite.
    evaluate(s.xk, true, false);
    ++stats.newtonIterations;
    if (!newtonGradient(s, why)) return false;
    bool projected = false;
    if (!newtonDirection(s, stats, projected, why)) return false;
    const double stepNorm = s.dx.lpNorm<Eigen::Infinity>();
    stats.finalStepNorm = stepNorm;
    if (stepNorm <= tol) {
      applyStep(s, 1.0);
      s.xk.swap(s.xTrial);
      s.airAtXk.reset();
      converged = true;
      break;
    }
    double step = 1.0;
    const LineSearchResult found = lineSearch(s, stepNorm, tol, step, why);
    if (found == LineSearchResult::Failed) return false;
    if (found == LineSearchResult::Converged) {
      converged = true;
      break;
    }
    if (debugNewton) traceNewtonIteration(s, it, stepNorm, step, projected);
    s.xk.swap(s.xTrial);
  }
  if (!converged) {
    std::ostringstream os;
    os << "Newton did not converge in " << params.maxNewtonIterations << " iterations (last step "
       << stats.finalStepNorm << " m)";
    why = os.str();
    return false;
  }
  return true;
}

bool ElasticSheet::Impl::correctAir(NewtonState& s, StepStats& stats, std::string& why) {
  const auto begin = std::chrono::steady_clock::now();
  const double airBefore = s.airMs;
  std::vector<Vec3> v1(vertexCount);
  for (std::size_t i = 0; i < vertexCount; ++i) v1[i] = (s.xk[i] - x[i]) / s.h;
  const std::vector<Vec3> change = air->correctStep(s.xk, v1);
  // The corrected forces' minimiser, one Newton step away with the last
  // factorisation (the potential's gradient at s.xk is now -change).
  VecX rhs = VecX::Zero(3 * freeCount);
  for (std::size_t i = 0; i < vertexCount; ++i)
    if (const int fi = freeIndex[i]; fi >= 0) rhs.segment<3>(3 * fi) = change[i];
  s.dx = solver.solve(rhs);
  ++stats.solves;
  if (solver.info() != Eigen::Success || !s.dx.allFinite()) {
    why = "the air's corrector: Cholesky solve failed";
    return false;
  }
  applyStep(s, 1.0);
  s.xk.swap(s.xTrial);
  s.airAtXk.reset();  // the corrected forces are another energy, at another xk
  // That linearisation errs by about |dx|^2 / edge: below 1e-4 edges for a
  // step under kCorrectorLinearStep edges, far below backward Euler's own
  // error over the step (h^2 |a|); a longer step is polished by Newton.
  const double moved = s.dx.lpNorm<Eigen::Infinity>();
  const bool ok = moved <= kCorrectorLinearStep * typicalEdge || newtonLoop(s, stats, why);
  s.airMs = airBefore + msSince(begin);
  return ok;
}

bool ElasticSheet::Impl::substep(double t0, double t1, const PinFunction& pins, StepStats& stats,
                                 std::string& why) {
  // Animated colliders: where the step begins, then where it ends.
  if (collidersOn() && contact.moveColliders) {
    contact.moveColliders(t0);
    contact.moveColliders(t1);
  }
  if (!collectPins(t1, pins, why) || !collectGrips(t1, why)) return false;
  NewtonState s;
  s.t0 = t0;
  s.h = t1 - t0;
  startNewton(s);
  if (air) {
    const auto begin = std::chrono::steady_clock::now();
    air->beginStep(x, v, t0, t1, collidersOn() ? contact.colliders : nullptr);
    s.airMs += msSince(begin);
  }
  findContacts(x, s.xk, s.h, stats);
  if (!newtonLoop(s, stats, why)) return false;
  // The corrected step's cost, all of it, is the air's.
  if (air && freeCount > 0 && !correctAir(s, stats, why)) return false;
  stats.airMs += s.airMs;
  return finishSubstep(s, stats, why);
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

void ElasticSheet::setGrips(GripFunction grips) { impl_->grips = std::move(grips); }

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
  // Recovery (docs/STABILITY.md), only for a step that failed at every
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
    stats.airMs += more.airMs;
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

}  // namespace crumple::sim
