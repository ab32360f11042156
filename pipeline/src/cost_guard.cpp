#include "cost_guard.hpp"

#include <algorithm>
#include <cstdio>

namespace crumple::pipeline {
namespace {

std::string format(const char* pattern, double a, double b = 0.0) {
  char text[160];
  std::snprintf(text, sizeof text, pattern, a, b);
  return text;
}

// A hand holding paper moves at a few m/s; a key that jumps kilometres is
// a typo in the animation.
constexpr double kFastestHandle = 50.0;  // m/s

}  // namespace

double CostGuard::median() const {
  std::vector<double> sorted = seconds_;
  const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
  std::nth_element(sorted.begin(), middle, sorted.end());
  return *middle;
}

double CostGuard::budget() const {
  if (fixed_) return *fixed_;
  const double least = kFirstFramesBudget * slowness_;
  if (static_cast<int>(seconds_.size()) < kWarmUpFrames) return least;
  return std::max(least, kRunawayFactor * median());
}

void CostGuard::frameDone(int frame, double seconds, long halvings, const std::string& cause) {
  if (fixed_ && *fixed_ == 0.0) return;  // frame_budget_s = 0: the guard is off
  const bool warm = static_cast<int>(seconds_.size()) >= kWarmUpFrames;
  const double slowAbove =
      warm ? std::max(kLeastSlowFrame * slowness_, kSlowFactor * median()) : 0.0;
  const double typical = warm ? median() : 0.0;
  seconds_.push_back(seconds);
  slow_ = !fixed_ && warm && seconds > slowAbove ? slow_ + 1 : 0;
  crawling_ = halvings > kHalvingsPerFrame ? crawling_ + 1 : 0;
  std::string problem;
  if (slow_ >= kSlowFrames)
    problem = format("%.0f frames in a row each took more than %.3g s", kSlowFrames, slowAbove) +
              format(" (%.3g s this one; the shot's median frame is %.3g s", seconds, typical) +
              format("; at least %.3g s here, %.3g s on the reference machine",
                     kLeastSlowFrame * slowness_, kLeastSlowFrame) +
              format(" times this one's slowness, %.2g): the shot is crawling", slowness_);
  else if (crawling_ >= kHalvingFrames)
    problem = "the solver halved its substep more than " + std::to_string(kHalvingsPerFrame) +
              " times a frame on " + std::to_string(kHalvingFrames) + " frames in a row (" +
              std::to_string(halvings) + " in this one): the shot is crawling";
  else
    return;
  problem += cause.empty() ? "; no handle looks out of reach: try more [scene] substeps"
                           : "; likely cause: " + cause;
  problem += "; [scene] frame_budget_s = 0 turns the guard off";
  throw NumericalError("cost guard", frame, problem);
}

void CostGuard::newRegime() {
  seconds_.clear();
  slow_ = 0;
}

NumericalError CostGuard::budgetError(int frame, const std::string& stage,
                                      const std::string& cause) const {
  const double b = budget();
  std::string problem = format("the frame ran past its budget of %.3g s", b);
  if (!fixed_ && static_cast<int>(seconds_.size()) >= kWarmUpFrames)
    problem += format(" (%.0fx the shot's median frame, at least %.3g s here", kRunawayFactor,
                      kFirstFramesBudget * slowness_);
  else if (!fixed_)
    problem += format(" (the first frames' budget: %.3g s here", kFirstFramesBudget * slowness_);
  if (!fixed_)
    problem += format(", %.3g s on the reference machine times this one's slowness, %.2g)",
                      kFirstFramesBudget, slowness_);
  problem += cause.empty() ? "" : "; likely cause: " + cause;
  problem += "; [scene] frame_budget_s sets the budget (0: the guard is off)";
  return NumericalError(stage, frame, problem);
}

std::string likelyCostCause(const std::vector<std::string>& names,
                            const std::vector<Vec2>& patternPoints,
                            const std::vector<Vec3>& targets,
                            const std::vector<Vec3>& previousTargets, const std::vector<char>& held,
                            double frameSeconds) {
  const std::size_t n = std::min({names.size(), patternPoints.size(), targets.size(), held.size()});
  for (std::size_t a = 0; a < n; ++a) {
    if (!held[a]) continue;
    for (std::size_t b = a + 1; b < n; ++b) {
      if (!held[b]) continue;
      const double apart = (targets[a] - targets[b]).norm();
      const double pattern = (patternPoints[a] - patternPoints[b]).norm();
      const std::string pair = "handles '" + names[a] + "' and '" + names[b] + "'";
      if (apart < 1e-3 && pattern > 1e-2)
        return pair + format(
                          " are at one point (%.2f mm apart) while their pattern points are "
                          "%.1f cm apart",
                          1e3 * apart, 1e2 * pattern);
      if (apart > 1.5 * pattern + 1e-2)
        return pair + format(
                          " are %.4g m apart, farther than the sheet reaches (their pattern "
                          "points are %.4g m apart)",
                          apart, pattern);
    }
  }
  if (frameSeconds > 0.0)
    for (std::size_t h = 0; h < std::min(n, previousTargets.size()); ++h) {
      const double speed = (targets[h] - previousTargets[h]).norm() / frameSeconds;
      if (held[h] && speed > kFastestHandle)
        return "handle '" + names[h] +
               format(
                   "' moves at %.4g m/s in this frame (a hand moves at a few m/s; is a key of "
                   "its node %.4g m away?)",
                   speed, (targets[h] - previousTargets[h]).norm());
    }
  return {};
}

std::string likelyCostCause(const model::HandleRig& rig, const std::vector<Vec2>& pattern, double t,
                            double tPrevious) {
  std::vector<std::string> names;
  std::vector<Vec2> points;
  std::vector<Vec3> now, before;
  std::vector<char> held;
  for (std::size_t h = 0; h < rig.handles().size(); ++h) {
    const model::BoundHandle& b = rig.handles()[h];
    const bool bound = b.vertex >= 0 && static_cast<std::size_t>(b.vertex) < pattern.size();
    names.push_back(b.name);
    points.push_back(bound ? pattern[static_cast<std::size_t>(b.vertex)] : Vec2::Zero());
    now.push_back(rig.target(h, t));
    before.push_back(rig.target(h, tPrevious));
    held.push_back(bound && !(b.releases && t >= b.releaseTime) ? 1 : 0);
  }
  return likelyCostCause(names, points, now, before, held, t - tPrevious);
}

}  // namespace crumple::pipeline
