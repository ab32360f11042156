// Isometry projection (paper Sec. 6.3, eqs. (3)-(7)). See isometry.hpp for the
// scheme and for every deviation from the paper.
#include "crumple/paper/isometry.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "crumple/core/error.hpp"
#include "crumple/core/index.hpp"
#include "crumple/core/work_budget.hpp"
#include "pattern_edges.hpp"

namespace crumple::paper {

namespace {

constexpr const char* kStage = "isometry";

}  // namespace

struct IsometryProjector::Impl {
  std::vector<Vec2> pattern;
  std::vector<std::array<int, 3>> triangles;
  // Edges (i < j, sorted), lbar_e, triangle-edge incidence and signs (eq. (3)).
  std::optional<detail::PatternEdges> graph;
  double lengthScale = 1.0;  // mean lbar_e: Phase I works in lbar / lengthScale
  // Phase II (eq. (7)): graph Laplacian restricted to the free vertices.
  std::optional<detail::EdgeFitSolver> phaseTwoSolver;

  IsometryOptions options;

  void build(std::vector<int> fixedVertices);
  int phaseOne(const std::vector<Vec3>& u0, std::vector<Vec3>& u, int maxIterations) const;
  std::vector<Vec3> phaseTwo(const std::vector<Vec3>& input, const std::vector<Vec3>& u) const;
  int polishLengths(std::vector<Vec3>& p) const;
};

// Gauss-Seidel projection of every edge onto its pattern length, fixed
// vertices immobile (our extension after Phase II; deviation 7 in the
// header). Every sweep walks the edges in their sorted order; it stops once
// the largest relative error is below options.lengthTolerance. Returns the
// sweeps run.
int IsometryProjector::Impl::polishLengths(std::vector<Vec3>& p) const {
  // The edges with a free end, in sorted order, with what the projection
  // needs inline (an edge between two fixed vertices never moves).
  struct Rod {
    int i, j;
    bool freeI, freeJ;
    double rest, weightSum;  // pattern length; inverse masses summed (1 or 2)
  };
  const auto& edges = graph->edges;
  const auto& restLength = graph->restLength;
  std::vector<char> isFixed(idx(graph->n), 0);
  for (int v : graph->fixed) isFixed[idx(v)] = 1;
  std::vector<Rod> rods;
  rods.reserve(edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const int i = edges[e][0], j = edges[e][1];
    const bool fi = isFixed[idx(i)] == 0;
    const bool fj = isFixed[idx(j)] == 0;
    if (fi || fj)
      rods.push_back({i, j, fi, fj, restLength[e], (fi ? 1.0 : 0.0) + (fj ? 1.0 : 0.0)});
  }
  int sweeps = 0;
  while (sweeps < options.lengthSweeps) {
    checkWorkBudget("isometry");  // the shot's cost guard (core/work_budget.hpp)
    double worst = 0.0;
    for (const Rod& r : rods) {
      Vec3& pi = p[idx(r.i)];
      Vec3& pj = p[idx(r.j)];
      const Vec3 d = pj - pi;
      const double len = d.norm();
      if (!(len > 1e-14 * r.rest)) continue;  // a collapsed edge has no direction
      const Vec3 corr = ((len - r.rest) / (len * r.weightSum)) * d;
      if (r.freeI) pi += corr;
      if (r.freeJ) pj -= corr;
      worst = std::max(worst, std::abs((len - r.rest) / r.rest));
    }
    ++sweeps;
    if (worst < options.lengthTolerance) break;
  }
  return sweeps;
}

// Edge list, triangle-edge incidence with orientation signs (eq. (3)), and
// the Phase II matrix of eq. (7), factored once per topology.
void IsometryProjector::Impl::build(std::vector<int> fixedVertices) {
  if (options.rounds < 1) throw std::invalid_argument("isometry: rounds must be >= 1");
  if (!(options.tolerance > 0.0)) throw std::invalid_argument("isometry: tolerance must be > 0");
  if (options.lengthSweeps < 0) throw std::invalid_argument("isometry: negative lengthSweeps");
  if (!(options.lengthTolerance >= 0.0))
    throw std::invalid_argument("isometry: lengthTolerance must be >= 0");
  graph.emplace(pattern, triangles, std::move(fixedVertices), kStage);
  double sum = 0.0;
  for (const double l : graph->restLength) sum += l;
  lengthScale = graph->edges.empty() ? 1.0 : sum / static_cast<double>(graph->edges.size());
  // Eq. (7): normal equations are the graph Laplacian on the free vertices.
  phaseTwoSolver.emplace(*graph, std::vector<double>{}, kStage, "Phase II");
}

// Paper Sec. 6.3, Phase I, eqs. (3)-(6): iterates the unit edge directions u
// (in/out, starting at u0) towards C_unit = 0 and C_closed = 0 with two
// Lagrange multipliers and H = I. Returns the number of iterations taken.
int IsometryProjector::Impl::phaseOne(const std::vector<Vec3>& u0, std::vector<Vec3>& u,
                                      int maxIterations) const {
  const auto& restLength = graph->restLength;
  const auto& triEdges = graph->triEdges;
  const auto& triSigns = graph->triSigns;
  const std::size_t m = graph->edges.size(), nt = triangles.size();
  if (m == 0 || nt == 0) return 0;
  const bool anchored = options.objective == PhaseOneObjective::Anchored;
  const double tol = options.tolerance;
  std::vector<double> lhat(m);  // lbar_e in units of the mean pattern edge
  for (std::size_t e = 0; e < m; ++e) lhat[e] = restLength[e] / lengthScale;
  std::vector<Vec3> g1(m), g2(m), gradE(m, Vec3::Zero()), step(m), r(nt);
  int it = 0;
  for (; it < maxIterations; ++it) {
    // C_unit = sum_e (u_e.u_e - 1)^2 (eq. (4)) and its gradient 4 (u.u - 1) u.
    double c1 = 0.0;
    for (std::size_t e = 0; e < m; ++e) {
      const double s = u[e].squaredNorm() - 1.0;
      c1 += s * s;
      g1[e] = (4.0 * s) * u[e];
    }
    // C_closed = sum_t |lbar_ij u_ij + lbar_jk u_jk + lbar_ki u_ki|^2 (eq. (3)),
    // each edge entering with the sign of the triangle's walk along it.
    double c2 = 0.0;
    for (std::size_t t = 0; t < nt; ++t) {
      Vec3 rt = Vec3::Zero();
      for (int k = 0; k < 3; ++k) {
        const int e = triEdges[t][k];
        rt += (triSigns[t][k] * lhat[e]) * u[e];
      }
      r[t] = rt;
      c2 += rt.squaredNorm();
    }
    for (auto& g : g2) g.setZero();
    for (std::size_t t = 0; t < nt; ++t) {
      for (int k = 0; k < 3; ++k) {
        const int e = triEdges[t][k];
        g2[e] += (2.0 * triSigns[t][k] * lhat[e]) * r[t];
      }
    }
    const bool met1 = std::sqrt(c1 / static_cast<double>(m)) < tol;
    const bool met2 = std::sqrt(c2 / static_cast<double>(nt)) < tol;
    if (met1 && met2) break;  // both constraints satisfied

    // Eq. (5) with H = I reduces to eq. (6):
    //   L^T L dlambda = L^T b_x - b_lambda,  dx = b_x - L dlambda,
    // b_x = -grad E - L lambda, b_lambda = -C. Substituting b_x, the old
    // lambda cancels: L^T L lambda' = C - L^T grad E with lambda' = lambda +
    // dlambda, and dx = -grad E - L lambda'. We solve for lambda' directly,
    // which is eq. (6) without the cancellation of the diverging multipliers
    // the paper warns about. grad E = u - u0 (Anchored, the paper's E) or 0
    // (Recentred: E measured from the current iterate, see the header).
    if (anchored) {
      for (std::size_t e = 0; e < m; ++e) gradE[e] = u[e] - u0[e];
    }
    double g11 = 0.0, g12 = 0.0, g22 = 0.0, a1 = 0.0, a2 = 0.0;
    for (std::size_t e = 0; e < m; ++e) {
      g11 += g1[e].squaredNorm();
      g12 += g1[e].dot(g2[e]);
      g22 += g2[e].squaredNorm();
    }
    if (anchored) {  // grad E = 0 otherwise
      for (std::size_t e = 0; e < m; ++e) {
        a1 += g1[e].dot(gradE[e]);
        a2 += g2[e].dot(gradE[e]);
      }
    }
    const double rhs1 = c1 - a1, rhs2 = c2 - a2;
    // Guarded 2x2 solve. A constraint already met (its gradient is then
    // rounding noise, e.g. C_unit at the unit start vectors u0) or whose
    // gradient vanishes is dropped, leaving a 1x1 system; otherwise the system
    // is Jacobi scaled, [1 c; c 1] mu = D rhs with D = diag(1/|grad C_k|), and
    // parallel gradients (1 - c^2 tiny) take the minimum-norm rank-one solution.
    constexpr double kNegligibleGradient = 1e-150;  // keeps |grad C|^2 a normal double
    const double n1 = std::sqrt(g11), n2 = std::sqrt(g22);
    const bool act1 = !met1 && n1 > kNegligibleGradient;
    const bool act2 = !met2 && n2 > kNegligibleGradient;
    if (!act1 && !act2) break;  // nothing left to linearise: stop rather than divide by 0
    double l1 = 0.0, l2 = 0.0;
    if (act1 && act2) {
      const double c = std::clamp(g12 / (n1 * n2), -1.0, 1.0);
      const double b1 = rhs1 / n1, b2 = rhs2 / n2;
      const double det = 1.0 - c * c;
      if (det > 1e-10) {
        l1 = (b1 - c * b2) / det / n1;
        l2 = (b2 - c * b1) / det / n2;
      } else {
        const double sgn = c >= 0.0 ? 1.0 : -1.0;
        const double mu = 0.25 * (b1 + sgn * b2);  // [1 s; s 1]^+ b along (1, s)
        l1 = mu / n1;
        l2 = sgn * mu / n2;
      }
    } else if (act1) {
      l1 = rhs1 / g11;
    } else {
      l2 = rhs2 / g22;
    }
    if (!std::isfinite(l1) || !std::isfinite(l2)) break;  // keep the last finite iterate
    double maxStep2 = 0.0;  // the largest |step_e|^2 (one square root below)
    for (std::size_t e = 0; e < m; ++e) {
      step[e] =
          anchored ? Vec3(-gradE[e] - l1 * g1[e] - l2 * g2[e]) : Vec3(-(l1 * g1[e]) - l2 * g2[e]);
      maxStep2 = std::max(maxStep2, step[e].squaredNorm());
    }
    const double maxStep = std::sqrt(maxStep2);
    if (!std::isfinite(maxStep)) break;
    // Safety cap (never reached in the tests): no direction moves by more than
    // kMaxStep per iteration, so a near-null gradient cannot fling u away.
    constexpr double kMaxStep = 0.5;
    const double scale = maxStep > kMaxStep ? kMaxStep / maxStep : 1.0;
    for (std::size_t e = 0; e < m; ++e) u[e] += scale * step[e];
  }
  return it;
}

// Paper Sec. 6.3, Phase II, eq. (7): min 1/2 sum_e |(p_j - p_i) - lbar_e u_e|^2
// over the free vertices; fixed and anchor vertices keep their `input`
// positions (detail::EdgeFitSolver).
std::vector<Vec3> IsometryProjector::Impl::phaseTwo(const std::vector<Vec3>& input,
                                                    const std::vector<Vec3>& u) const {
  std::vector<Vec3> target(u.size());
  for (std::size_t e = 0; e < u.size(); ++e) target[e] = graph->restLength[e] * u[e];
  return phaseTwoSolver->solve(input, target);
}

IsometryProjector::IsometryProjector(std::vector<Vec2> pattern,
                                     std::vector<std::array<int, 3>> triangles,
                                     std::vector<int> fixedVertices, IsometryOptions options)
    : impl_(std::make_unique<Impl>()) {
  impl_->pattern = std::move(pattern);
  impl_->triangles = std::move(triangles);
  impl_->options = options;
  impl_->build(std::move(fixedVertices));
}

IsometryProjector::~IsometryProjector() = default;
IsometryProjector::IsometryProjector(IsometryProjector&&) noexcept = default;
IsometryProjector& IsometryProjector::operator=(IsometryProjector&&) noexcept = default;

int IsometryProjector::vertexCount() const { return impl_->graph->n; }
int IsometryProjector::edgeCount() const { return static_cast<int>(impl_->graph->edges.size()); }

bool IsometryProjector::sameTopology(const std::vector<std::array<int, 3>>& triangles,
                                     const std::vector<int>& fixedVertices) const {
  if (triangles != impl_->triangles) return false;
  std::vector<int> f = fixedVertices;
  std::sort(f.begin(), f.end());
  f.erase(std::unique(f.begin(), f.end()), f.end());
  return f == impl_->graph->fixed;
}

// Paper Sec. 6.3: Phase I (eqs. (3)-(6)) then Phase II (eq. (7)), `rounds` times.
IsometryStats IsometryProjector::project(std::vector<Vec3>& positions, int maxIterations) const {
  const Impl& im = *impl_;
  const detail::PatternEdges& g = *im.graph;
  if (maxIterations < 0) throw std::invalid_argument("isometry: negative iteration cap");
  g.checkPositions(positions, kStage);
  const std::size_t m = g.edges.size();
  IsometryStats stats;
  double dummy = 0.0;
  g.lengthErrors(positions, stats.meanLengthErrorBefore, dummy);

  std::vector<Vec3> current = positions;
  std::vector<Vec3> u0(m), u(m);
  for (int round = 0; round < im.options.rounds; ++round) {
    // u0: the current normalised edge directions (the start of Phase I).
    for (std::size_t e = 0; e < m; ++e) {
      const Vec3 d = current[g.edges[e][1]] - current[g.edges[e][0]];
      const double len = d.norm();
      if (!(len > 1e-14 * g.restLength[e])) {
        throw NumericalError(kStage, "edge (" + std::to_string(g.edges[e][0]) + ", " +
                                         std::to_string(g.edges[e][1]) +
                                         ") has collapsed to zero length");
      }
      u0[e] = d / len;
    }
    u = u0;
    stats.phaseOneIterations += im.phaseOne(u0, u, maxIterations);
    // Renormalise (deviation 2 in the header); an edge whose direction did not
    // survive Phase I keeps its input direction.
    for (std::size_t e = 0; e < m; ++e) {
      const double len = u[e].norm();
      u[e] = std::isfinite(len) && len > 0.5 && len < 2.0 ? Vec3(u[e] / len) : u0[e];
    }
    current = im.phaseTwo(current, u);
  }
  stats.lengthSweeps = im.polishLengths(current);
  for (const Vec3& x : current) {
    if (!x.allFinite()) throw NumericalError(kStage, "non-finite position after the length sweeps");
  }

  g.lengthErrors(current, stats.meanLengthErrorAfter, stats.maxLengthErrorAfter);
  stats.meanDisplacement = detail::meanDisplacement(current, positions);
  positions = std::move(current);
  return stats;
}

}  // namespace crumple::paper
