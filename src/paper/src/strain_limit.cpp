// Strain limiting of S_P: Levenberg-Marquardt length projection, the rigid
// carried start (Kabsch 1976) and the transfer of positions by pattern
// (strain_limit.hpp).
#include "crumple/paper/strain_limit.hpp"

#include <Eigen/SVD>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>
#include <utility>

#include "crumple/core/index.hpp"
#include "crumple/core/work_budget.hpp"

namespace crumple::paper {

LengthProjector::LengthProjector(const std::vector<Vec2>& pattern,
                                 const std::vector<std::array<int, 3>>& triangles)
    : vertexCount_(pattern.size()), triangles_(triangles), pattern_(pattern) {
  std::map<std::pair<int, int>, int> seen;
  std::vector<char> used(pattern.size(), 0);
  for (const auto& t : triangles)
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      used[idx(a)] = 1;
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      if (!seen.emplace(key, 0).second) continue;
      const double rest = (pattern[idx(a)] - pattern[idx(b)]).norm();
      if (!(rest > 0.0)) continue;  // a degenerate pattern edge has no strain
      edges_.push_back({key.first, key.second});
      rest_.push_back(rest);
    }
  for (std::size_t v = 0; v < used.size(); ++v)
    if (used[v] != 0) used_.push_back(static_cast<int>(v));
}

void LengthProjector::setCrossingGuard(double thickness) {
  crossingGuard_.reset();
  if (thickness > 0.0 && std::isfinite(thickness) && !triangles_.empty())
    crossingGuard_ = std::make_shared<sim::SelfContactDetector>(triangles_, pattern_, thickness);
}

std::size_t LengthProjector::crossings(const std::vector<Vec3>& x) const {
  return crossingGuard_ ? crossingGuard_->crossings(x).size() : 0;
}

std::pair<double, double> LengthProjector::strain(const std::vector<Vec3>& x) const {
  double mx = 0.0, sum = 0.0;
  for (std::size_t k = 0; k < edges_.size(); ++k) {
    const double l = (x[idx(edges_[k][1])] - x[idx(edges_[k][0])]).norm();
    const double r = std::abs(l - rest_[k]) / rest_[k];
    mx = std::max(mx, r);
    sum += r;
  }
  return {mx, edges_.empty() ? 0.0 : sum / static_cast<double>(edges_.size())};
}

LengthProjectionStats LengthProjector::project(std::vector<Vec3>& x, const std::vector<char>& held,
                                               double target, int maxIterations) const {
  return solve(x, held, {}, {}, target, 0.0, maxIterations);
}

LengthProjectionStats LengthProjector::projectTowards(std::vector<Vec3>& x,
                                                      const std::vector<char>& held,
                                                      const std::vector<int>& handles,
                                                      const std::vector<Vec3>& targets,
                                                      double bound, int maxIterations) const {
  return solve(x, held, handles, targets, 0.0, bound, maxIterations);
}

namespace {

// The objective of LengthProjector::solve and its Gauss-Newton model:
// F(x) = sum_e w_e r_e^2 + (kHandleWeight / l^2) sum_h |x_h - t_h|^2 +
// (kHandleWeight / l^2) sum_k min(0, n_k . (x_k - p_k))^2, with
// w_e = 1 + kBoundWeight [|r_e| > kSoftBound bound] (bound > 0 only) and
// l the mean rest length. Free vertex v's coordinates are columns
// 3 column[v] .. 3 column[v] + 2.
class LengthObjective {
 public:
  LengthObjective(const std::vector<std::array<int, 2>>& edges, const std::vector<double>& rest,
                  const std::vector<KeepOut>& keepOut, std::size_t vertexCount,
                  const std::vector<int>& column, const std::vector<int>& handles,
                  const std::vector<Vec3>& targets, double bound)
      : edges_(edges),
        rest_(rest),
        keepOut_(keepOut),
        vertexCount_(vertexCount),
        column_(column),
        handles_(handles),
        targets_(targets),
        bound_(bound),
        soft_(LengthProjector::kSoftBound * bound),
        wall_(edges.size(), 0) {
    double meanRest = 0.0;
    for (double r : rest) meanRest += r;
    meanRest /= std::max<std::size_t>(1, rest.size());
    keepWeight_ = LengthProjector::kHandleWeight / (meanRest * meanRest);
    handleWeight_ = handles.empty() ? 0.0 : keepWeight_;
  }

  double cost(const std::vector<Vec3>& p) const {
    double s = 0.0;
    for (const KeepOut& k : keepOut_) s += keepWeight_ * inside(k, p) * inside(k, p);
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      const double r = residual(p, k);
      s += r * r + (weight(r) - 1.0) * (std::abs(r) - soft_) * (std::abs(r) - soft_);
    }
    for (std::size_t h = 0; h < handles_.size(); ++h)
      s += handleWeight_ * (p[idx(handles_[h])] - targets_[h]).squaredNorm();
    return s;
  }

  // The Gauss-Newton matrix J^T W J and gradient J^T W r at x; J's rows
  // d r_e / d x are -u, +u on the edge's ends with u = d / (l L).
  void assemble(const std::vector<Vec3>& x, Eigen::SparseMatrix<double>& H, Eigen::VectorXd& g) {
    const Eigen::Index n = g.size();
    triplets_.clear();
    g.setZero();
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      const auto [a, b] = edges_[k];
      const Vec3 d = x[idx(b)] - x[idx(a)];
      const double l = d.norm();
      const double r = (l - rest_[k]) / rest_[k];
      const double w = weight(r);
      const double wModel = wall_[k] != 0 ? 1.0 + LengthProjector::kBoundWeight : w;
      // The penalty's residual is |r| - soft, so its gradient term is
      // (w - 1)(|r| - soft) sign(r) u beside the plain r u.
      const double gr = r + (w - 1.0) * (std::abs(r) - soft_) * (r < 0.0 ? -1.0 : 1.0);
      // A collapsed edge has no direction; its zero block keeps the sparsity
      // pattern the symbolic analysis was made for.
      const Vec3 u = l > 0.0 ? Vec3(d / (l * rest_[k])) : Vec3::Zero();
      const std::array<int, 2> cols{column_[idx(a)], column_[idx(b)]};
      const std::array<double, 2> sign{-1.0, 1.0};
      for (std::size_t i = 0; i < 2; ++i) {
        if (cols[i] < 0) continue;
        g.segment<3>(3 * cols[i]) += sign[i] * gr * u;
        for (std::size_t j = 0; j < 2; ++j) {
          if (cols[j] < 0) continue;
          add(3 * cols[i], 3 * cols[j], wModel * sign[i] * sign[j] * u * u.transpose());
        }
      }
    }
    // The diagonal always in the pattern, so one symbolic analysis serves.
    for (Eigen::Index i = 0; i < n; ++i) triplets_.emplace_back(i, i, 0.0);
    for (std::size_t h = 0; h < handles_.size(); ++h) {
      const int c = column_[idx(handles_[h])];
      if (c < 0) continue;
      g.segment<3>(3 * c) += handleWeight_ * (x[idx(handles_[h])] - targets_[h]);
      add(3 * c, 3 * c, handleWeight_ * Mat3::Identity());
    }
    for (const KeepOut& k : keepOut_) {
      const int c = k.vertex >= 0 && idx(k.vertex) < vertexCount_ ? column_[idx(k.vertex)] : -1;
      const double s = c < 0 ? 0.0 : inside(k, x);
      if (s == 0.0) continue;
      g.segment<3>(3 * c) += keepWeight_ * s * k.normal;
      add(3 * c, 3 * c, keepWeight_ * k.normal * k.normal.transpose());
    }
    H.setFromTriplets(triplets_.begin(), triplets_.end());
  }

  // The bound's penalty max(0, |r| - soft)^2 has no curvature below the
  // soft bound, so a model without it proposes steps that push an edge at
  // the bound through it; the trial is rejected and LM shrinks the step
  // without ever learning why (on samples/crumple the lag search made no
  // step at all from frame 34 and the sheet stood still). The edges that
  // `trial` pushes past the soft bound from below join the model for the
  // rest of the solve (an active-set Gauss-Newton model, Nocedal & Wright
  // 2006, Sec. 16.5). True when any did.
  bool learnBound(const std::vector<Vec3>& x, const std::vector<Vec3>& trial) {
    if (!(bound_ > 0.0)) return false;
    bool learned = false;
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      if (wall_[k] != 0 || std::abs(residual(x, k)) > soft_) continue;
      if (std::abs(residual(trial, k)) > soft_) {
        wall_[k] = 1;
        learned = true;
      }
    }
    return learned;
  }

 private:
  double residual(const std::vector<Vec3>& p, std::size_t k) const {
    return ((p[idx(edges_[k][1])] - p[idx(edges_[k][0])]).norm() - rest_[k]) / rest_[k];
  }
  // An edge's residual weight: over the soft bound it costs kBoundWeight more.
  double weight(double r) const {
    return bound_ > 0.0 && std::abs(r) > soft_ ? 1.0 + LengthProjector::kBoundWeight : 1.0;
  }
  static double inside(const KeepOut& k, const std::vector<Vec3>& p) {
    return std::min(0.0, k.normal.dot(p[idx(k.vertex)] - k.point));
  }
  void add(Eigen::Index row, Eigen::Index col, const Mat3& block) {
    for (int p = 0; p < 3; ++p)
      for (int q = 0; q < 3; ++q) triplets_.emplace_back(row + p, col + q, block(p, q));
  }

  const std::vector<std::array<int, 2>>& edges_;
  const std::vector<double>& rest_;
  const std::vector<KeepOut>& keepOut_;
  std::size_t vertexCount_;
  const std::vector<int>& column_;
  const std::vector<int>& handles_;
  const std::vector<Vec3>& targets_;
  double bound_, soft_, keepWeight_ = 0.0, handleWeight_ = 0.0;
  std::vector<char> wall_;  // edges whose penalty the model carries below the soft bound
  std::vector<Eigen::Triplet<double>> triplets_;
};

}  // namespace

// The Levenberg-Marquardt core of project and projectTowards on
// LengthObjective. With no handles it stops at max |r_e| <= target and
// returns the least-max iterate; with handles it runs to convergence and
// returns the last (least-F) iterate, its Gauss-Newton model learning the
// bound where a rejected trial broke it (LengthObjective::learnBound; the
// projections with no handles keep their model).
LengthProjectionStats LengthProjector::solve(std::vector<Vec3>& x, const std::vector<char>& held,
                                             const std::vector<int>& handles,
                                             const std::vector<Vec3>& targets, double target,
                                             double bound, int maxIterations) const {
  LengthProjectionStats stats;
  std::tie(stats.maxBefore, stats.meanBefore) = strain(x);
  stats.maxAfter = stats.maxBefore;
  stats.meanAfter = stats.meanBefore;
  const bool towards = !handles.empty();
  if ((!towards && stats.maxBefore <= target) || maxIterations <= 0) return stats;
  std::vector<int> column(vertexCount_, -1);
  int free = 0;
  for (int v : used_)
    if (!inRange(held, v) || held[idx(v)] == 0) column[idx(v)] = free++;
  if (free == 0) return stats;
  LengthObjective objective(edges_, rest_, keepOut_, vertexCount_, column, handles, targets, bound);
  const Eigen::Index n = 3 * static_cast<Eigen::Index>(free);
  Eigen::SparseMatrix<double> H(n, n);
  Eigen::VectorXd g(n);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  bool analysed = false;
  double f = objective.cost(x), mu = 1e-4;
  std::size_t crossed = crossings(x);
  // The iterate with the smallest max |r_e|: the objective is the sum of
  // squares, the bound is on the max.
  std::vector<Vec3> bestX = x;
  double bestMax = stats.maxBefore;
  for (int it = 0; it < maxIterations; ++it) {
    checkWorkBudget("strain limit");  // the shot's cost guard (core/work_budget.hpp)
    objective.assemble(x, H, g);
    Eigen::VectorXd diag = H.diagonal();
    double floor = 1e-9 * std::max(1e-300, diag.maxCoeff());
    bool accepted = false;
    for (int tries = 0; tries < 12 && !accepted; ++tries) {
      Eigen::SparseMatrix<double> A = H;
      for (Eigen::Index i = 0; i < n; ++i) A.coeffRef(i, i) += mu * (diag(i) + floor);
      if (!analysed) {
        ldlt.analyzePattern(A);
        analysed = true;
      }
      ldlt.factorize(A);
      if (ldlt.info() != Eigen::Success) {
        mu *= 10.0;
        continue;
      }
      const Eigen::VectorXd step = ldlt.solve(-g);
      if (!step.allFinite()) {
        mu *= 10.0;
        continue;
      }
      std::vector<Vec3> trial = x;
      for (int v : used_)
        if (const int c = column[idx(v)]; c >= 0) trial[idx(v)] += step.segment<3>(3 * c);
      const double ft = objective.cost(trial);
      const std::size_t trialCrossed = ft < f ? crossings(trial) : crossed;
      if (ft < f && trialCrossed <= crossed) {
        crossed = trialCrossed;
        const double gain = f - ft;
        x = std::move(trial);
        f = ft;
        mu = std::max(1e-12, mu / 3.0);
        accepted = true;
        ++stats.iterations;
        if (gain < 1e-6 * f) it = maxIterations;  // converged: the last gain is negligible
      } else if (towards && objective.learnBound(x, trial)) {
        objective.assemble(x, H, g);  // the same damping on the model that now sees the bound
        diag = H.diagonal();
        floor = 1e-9 * std::max(1e-300, diag.maxCoeff());
      } else {
        mu *= 4.0;
      }
    }
    if (!accepted) break;
    if (towards) continue;
    const double mx = strain(x).first;
    if (mx < bestMax) {
      bestMax = mx;
      bestX = x;
    }
    if (mx <= target) break;
  }
  if (!towards) x = std::move(bestX);
  std::tie(stats.maxAfter, stats.meanAfter) = strain(x);
  return stats;
}

void LengthProjector::holdAwayFrom(const std::vector<Vec3>& x, double above, int rings,
                                   std::vector<char>& held) const {
  std::vector<char> near(vertexCount_, 0);
  for (std::size_t k = 0; k < edges_.size(); ++k) {
    const double l = (x[idx(edges_[k][1])] - x[idx(edges_[k][0])]).norm();
    if (std::abs(l - rest_[k]) > above * rest_[k])
      near[idx(edges_[k][0])] = near[idx(edges_[k][1])] = 1;
  }
  for (int ring = 0; ring < rings; ++ring) {
    std::vector<char> grown = near;
    for (const auto& e : edges_)
      if (near[idx(e[0])] != 0 || near[idx(e[1])] != 0) grown[idx(e[0])] = grown[idx(e[1])] = 1;
    near = std::move(grown);
  }
  held.resize(vertexCount_, 0);
  for (std::size_t v = 0; v < vertexCount_; ++v)
    if (near[v] == 0) held[v] = 1;
}

RigidMotion fitRigidMotion(const std::vector<Vec3>& from, const std::vector<Vec3>& to) {
  RigidMotion m;
  const std::size_t n = std::min(from.size(), to.size());
  if (n == 0) return m;
  Vec3 ca = Vec3::Zero(), cb = Vec3::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    ca += from[i];
    cb += to[i];
  }
  ca /= static_cast<double>(n);
  cb /= static_cast<double>(n);
  Mat3 cov = Mat3::Zero();
  double spread = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    cov += (to[i] - cb) * (from[i] - ca).transpose();
    spread = std::max(spread, (from[i] - ca).norm());
  }
  if (n >= 2 && spread > 0.0) {
    const Eigen::JacobiSVD<Mat3> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Vector3d s = svd.singularValues();
    if (s(1) > 1e-9 * s(0)) {
      // Kabsch: R = U diag(1, 1, det(U V^T)) V^T.
      Mat3 d = Mat3::Identity();
      d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
      m.rotation = svd.matrixU() * d * svd.matrixV().transpose();
    } else if (s(0) > 0.0) {
      // Collinear points: the smallest rotation taking one line onto the other.
      const Vec3 a = svd.matrixV().col(0), b = svd.matrixU().col(0);
      m.rotation = Quat::FromTwoVectors(a, b).toRotationMatrix();
    }
  }
  m.translation = cb - m.rotation * ca;
  return m;
}

std::vector<Vec3> transferByPattern(const std::vector<Vec2>& oldPattern,
                                    const std::vector<std::array<int, 3>>& oldTriangles,
                                    const std::vector<Vec3>& oldPositions,
                                    const std::vector<Vec2>& pattern) {
  std::vector<Vec3> out(pattern.size(), Vec3::Zero());
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    const Vec2& p = pattern[i];
    double best = std::numeric_limits<double>::infinity();
    Vec3 placed = Vec3::Zero();
    for (const auto& t : oldTriangles) {
      const Vec2 &a = oldPattern[idx(t[0])], &b = oldPattern[idx(t[1])], &c = oldPattern[idx(t[2])];
      const Mat2 e = (Mat2() << b - a, c - a).finished();
      const double det = e.determinant();
      if (std::abs(det) < 1e-300) continue;
      const Vec2 uv = e.inverse() * (p - a);
      const double w0 = 1.0 - uv.x() - uv.y();
      // Distance outside the triangle in barycentric units; 0 inside.
      const double outside = std::max({0.0, -w0, -uv.x(), -uv.y()});
      if (outside >= best) continue;
      best = outside;
      // Clamped barycentrics so a point just outside stays on the triangle.
      Eigen::Vector3d w(std::max(0.0, w0), std::max(0.0, uv.x()), std::max(0.0, uv.y()));
      w /= std::max(1e-300, w.sum());
      placed = w(0) * oldPositions[idx(t[0])] + w(1) * oldPositions[idx(t[1])] +
               w(2) * oldPositions[idx(t[2])];
      if (outside == 0.0) break;
    }
    out[i] = placed;
  }
  return out;
}

namespace {

// The projections aim at half the bound, so the next step does not start at
// the limit.
constexpr double kAim = 0.5;
// The local first attempt frees the vertices this many edges around the
// edges over the bound.
constexpr int kLocalRings = 2;
// Levenberg-Marquardt steps of a projectTowards solve (it runs to
// convergence, not to a bound). The search goes on from where the last
// animation step left the sheet, so a few steps per animation step
// suffice: on samples/crumple 20 leave the largest lag within 5 % of 60's
// at a quarter of the stage's cost (docs/CRUMPLING.md "The lag search").
constexpr int kTowardsIterations = 20;

void placeHandles(std::vector<Vec3>& x, const std::vector<int>& handles,
                  const std::vector<Vec3>& where) {
  for (std::size_t h = 0; h < handles.size(); ++h) x[idx(handles[h])] = where[h];
}

}  // namespace

void mergeHandleLags(const std::vector<std::pair<int, double>>& from,
                     std::vector<std::pair<int, double>>& into) {
  for (const auto& [vertex, lag] : from) {
    auto it = std::find_if(into.begin(), into.end(),
                           [v = vertex](const auto& e) { return e.first == v; });
    if (it == into.end())
      into.emplace_back(vertex, lag);
    else
      it->second = std::max(it->second, lag);
  }
}

namespace {

// The stage above; with `outOfItselfFirst` no candidate is taken that passes
// more of S_P's edges through another layer than `x` does.
StrainLimitStats limitStrainOnce(const StrainLimitInput& in, std::vector<Vec3>& x,
                                 bool outOfItselfFirst) {
  StrainLimitStats s;
  LengthProjector projector(in.pattern, in.triangles);
  projector.setKeepOut(in.keepOut);
  projector.setCrossingGuard(in.crossingGuard);
  std::tie(s.maxBefore, s.meanAfter) = projector.strain(x);
  s.maxAfter = s.maxBefore;
  const auto finish = [&](std::vector<Vec3> chosen) {
    x = std::move(chosen);
    std::tie(s.maxAfter, s.meanAfter) = projector.strain(x);
    s.handleLags.clear();
    for (std::size_t h = 0; h < in.handles.size(); ++h) {
      const double d = (x[idx(in.handles[h])] - in.targets[h]).norm();
      s.handleLags.emplace_back(in.handles[h], d);
      if (d > s.lag) {
        s.lag = d;
        s.lagVertex = in.handles[h];
      }
    }
    return s;
  };
  if (s.maxBefore <= in.bound) return finish(x);
  s.ran = true;
  // With the crossing guard on, no candidate may pass more of S_P's edges
  // through another layer than the sheet it was given: a handle placed on
  // its target, or a carried start, can put an edge through a layer that
  // the projection's own guard then keeps there.
  const bool guarded = outOfItselfFirst && in.crossingGuard > 0.0;
  const std::size_t crossingsGiven = guarded ? projector.crossings(x) : 0;
  const auto outOfItself = [&](const std::vector<Vec3>& p) {
    return !guarded || projector.crossings(p) <= crossingsGiven;
  };
  const double aim = kAim * in.bound;
  std::vector<char> held(in.pattern.size(), 0);
  for (int h : in.handles) held[idx(h)] = 1;
  // 1. The stepped sheet, handles on their targets, first with the pins held
  // too. The projection lowers sum_e r_e^2, not the max, so the given sheet
  // stays a candidate.
  std::vector<Vec3> best = x;
  double bestMax = s.maxBefore;
  {
    std::vector<char> pinHeld = held;
    for (int v : in.pins)
      if (inRange(pinHeld, v)) pinHeld[idx(v)] = 1;
    projector.holdAwayFrom(x, in.bound, kLocalRings, pinHeld);
    std::vector<Vec3> pinnedStep = x;
    placeHandles(pinnedStep, in.handles, in.targets);
    const auto pinStats = projector.project(pinnedStep, pinHeld, aim, in.iterations);
    s.iterations += pinStats.iterations;
    if (pinStats.maxAfter <= in.bound && outOfItself(pinnedStep))
      return finish(std::move(pinnedStep));
  }
  std::vector<Vec3> stepped = x;
  placeHandles(stepped, in.handles, in.targets);
  auto stats = projector.project(stepped, held, aim, in.iterations);
  s.iterations += stats.iterations;
  if (stats.maxAfter < bestMax && outOfItself(stepped)) {
    best = std::move(stepped);
    bestMax = stats.maxAfter;
  }
  if (bestMax <= in.bound) return finish(std::move(best));
  // 2. The carried start: the step's start moved rigidly with the handles.
  std::vector<Vec3> from;
  for (int h : in.handles) from.push_back(in.beforePositions[idx(h)]);
  const RigidMotion motion = fitRigidMotion(from, in.targets);
  std::vector<Vec3> base = in.sameMesh ? in.beforePositions
                                       : transferByPattern(in.beforePattern, in.beforeTriangles,
                                                           in.beforePositions, in.pattern);
  for (Vec3& p : base) p = motion.apply(p);
  std::vector<Vec3> carried = base;
  placeHandles(carried, in.handles, in.targets);
  stats = projector.project(carried, held, aim, in.iterations);
  s.iterations += stats.iterations;
  if (stats.maxAfter < bestMax && outOfItself(carried)) {
    best = std::move(carried);
    bestMax = stats.maxAfter;
    s.carried = true;
  }
  if (bestMax <= in.bound) return finish(std::move(best));
  // 3. Lag: the handles on the way from their carried positions to their
  // targets, as far as the bound allows (bisection).
  std::vector<Vec3> start;
  for (int h : in.handles) start.push_back(base[idx(h)]);
  std::vector<Vec3> feasible = base;
  stats = projector.project(feasible, held, aim, in.iterations);
  s.iterations += stats.iterations;
  if (stats.maxAfter > in.bound && !in.keepOut.empty()) {
    // The contacts and the bound conflict from the carried start (its
    // vertices sit elsewhere than the failsafe's half-spaces): the bound
    // wins, the next contact round or step pushes the sheet out again.
    projector.setKeepOut({});
    feasible = base;
    stats = projector.project(feasible, held, aim, in.iterations);
    s.iterations += stats.iterations;
    s.droppedKeepOut = true;
  }
  if (stats.maxAfter > in.bound || !outOfItself(feasible)) {
    // Not even the carried step's start meets the bound (or it passes
    // through itself): the best attempt.
    if (stats.maxAfter < bestMax && outOfItself(feasible)) {
      best = std::move(feasible);
      s.carried = true;
    }
    return finish(std::move(best));
  }
  // 3a. Each handle as near its target as the bound lets it
  // (projectTowards) from the carried start. (Started from the stepped sheet
  // as well, it never gave the better result on crumple and cost 37 % more.)
  {
    const std::vector<char> none(in.pattern.size(), 0);
    const auto sumLag = [&](const std::vector<Vec3>& p) {
      double sum = 0.0;
      for (std::size_t h = 0; h < in.handles.size(); ++h)
        sum += (p[idx(in.handles[h])] - in.targets[h]).squaredNorm();
      return sum;
    };
    std::vector<Vec3> towards = feasible;
    stats = projector.projectTowards(towards, none, in.handles, in.targets, in.bound,
                                     kTowardsIterations);
    s.iterations += stats.iterations;
    if (stats.maxAfter <= in.bound && sumLag(towards) < sumLag(feasible) && outOfItself(towards)) {
      s.carried = true;
      return finish(std::move(towards));
    }
  }
  // 3b. Else all handles on the way from their carried positions to their
  // targets together, as far as the bound allows (bisection).
  double lo = 0.0, hi = 1.0;
  for (int k = 0; k < 5; ++k) {
    const double mid = 0.5 * (lo + hi);
    std::vector<Vec3> where(in.handles.size());
    for (std::size_t h = 0; h < where.size(); ++h)
      where[h] = start[h] + mid * (in.targets[h] - start[h]);
    std::vector<Vec3> trial = feasible;
    placeHandles(trial, in.handles, where);
    stats = projector.project(trial, held, aim, in.iterations);
    s.iterations += stats.iterations;
    if (stats.maxAfter <= in.bound && outOfItself(trial)) {
      lo = mid;
      feasible = std::move(trial);
    } else {
      hi = mid;
    }
  }
  s.carried = true;
  return finish(std::move(feasible));
}

}  // namespace

StrainLimitStats limitStrain(const StrainLimitInput& in, std::vector<Vec3>& x) {
  const std::vector<Vec3> given = in.crossingGuard > 0.0 ? x : std::vector<Vec3>{};
  StrainLimitStats s = limitStrainOnce(in, x, true);
  if (s.maxAfter <= in.bound || !(in.crossingGuard > 0.0)) return s;
  // No candidate meets the bound without passing S_P further through
  // itself: paper stays paper first (the crossings the sheet already had
  // may then grow; the projections' own guard still holds within each).
  std::vector<Vec3> second = given;
  StrainLimitStats t = limitStrainOnce(in, second, false);
  t.iterations += s.iterations;
  if (t.maxAfter >= s.maxAfter) {
    s.iterations = t.iterations;  // the first result stays: it is no worse
    return s;
  }
  x = std::move(second);
  return t;
}

std::vector<KeepOut> keepOutOfContacts(const sim::ContactOptions& options,
                                       const std::vector<std::array<int, 3>>& triangles,
                                       const std::vector<Vec2>& pattern,
                                       const std::vector<char>& held, std::vector<Vec3>& x,
                                       double* collidersMs, double* selfMs) {
  const std::vector<Vec3> before = x;
  sim::projectOutOfContacts(options, triangles, pattern, held, x, collidersMs, selfMs);
  std::vector<KeepOut> out;
  for (std::size_t v = 0; v < x.size(); ++v) {
    const Vec3 moved = x[v] - before[v];
    if (moved.norm() > 0.0) out.push_back({static_cast<int>(v), x[v], moved.normalized()});
  }
  return out;
}

}  // namespace crumple::paper
