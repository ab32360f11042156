#pragma once
// The shot's cost guard (docs/RELIABILITY.md "The cost guard"): a frame that
// runs far longer than the shot's own frames, or frames that keep halving
// their substeps, stop the shot with a NumericalError naming the frame, the
// stage and the likely cause, instead of a silent crawl that bills a farm
// node for hours. The cache stays valid up to the last good frame (the
// shot's numerical-failure path). Its seconds are the process's CPU time
// (core/work_budget.hpp): a machine loaded by other work does not stop a
// shot. Internal to the pipeline.
#include <optional>
#include <string>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/core/types.hpp"
#include "crumple/model/handle_rig.hpp"

namespace crumple::pipeline {

class CostGuard {
 public:
  // The floors below are CPU seconds on the development machine's Release
  // build; the guard multiplies them by the process's slowness against it
  // (core/machine_speed.hpp), so that they mean the same work on a slower
  // machine or in a sanitized build.
  //
  // A runaway frame (stopped inside its stages, core/work_budget.hpp): its
  // budget is kFirstFramesBudget until the shot has kWarmUpFrames frames of
  // its own, then the larger of that and kRunawayFactor x their median.
  static constexpr double kFirstFramesBudget = 300.0;  // s
  static constexpr double kRunawayFactor = 100.0;
  static constexpr int kWarmUpFrames = 5;
  // A crawl (judged after each frame): kSlowFrames frames in a row, each
  // slower than kSlowFactor x the median and than kLeastSlowFrame. A tear's
  // dear frames are not one: samples/tear-fast's run of dear frames is
  // 9.4, 8.8, 20.1, 15.7 and 7.8 s against a median of 0.19 s; a handle
  // thrown out of reach costs 62-84 s a frame, frame after frame.
  static constexpr double kSlowFactor = 20.0;
  static constexpr double kLeastSlowFrame = 20.0;  // s
  static constexpr int kSlowFrames = 5;
  // Or kHalvingFrames frames in a row that each halve their substep more
  // than kHalvingsPerFrame times.
  static constexpr long kHalvingsPerFrame = 64;
  static constexpr int kHalvingFrames = 3;

  // fixedBudget: [scene] frame_budget_s. nullopt: the rules above. A number
  // > 0: that budget for every frame instead of the runaway and crawl rules
  // (the halvings rule stays). 0: the guard is off.
  // slowness: the process's, machineSlowness() (> 0; unused with a fixed
  // budget).
  CostGuard(std::optional<double> fixedBudget, double slowness)
      : fixed_(fixedBudget), slowness_(slowness) {}
  // CPU seconds the next frame may take (0: unlimited).
  double budget() const;
  // After a frame: its CPU seconds and halvings. Throws NumericalError
  // (stage "cost guard") on a crawl or on the halvings rule; `cause` is
  // appended.
  void frameDone(int frame, double seconds, long halvings, const std::string& cause);
  // The shot's cost changed regime (a torn crumpling-model sheet handed over
  // to the elastic model on a finer mesh): the frames from now on are judged
  // against their own median, after a new warm-up.
  void newRegime();
  // A NumericalError for a frame whose budget ran out in `stage`.
  NumericalError budgetError(int frame, const std::string& stage, const std::string& cause) const;

 private:
  double median() const;
  std::optional<double> fixed_;
  double slowness_;
  std::vector<double> seconds_;  // the frames so far
  int slow_ = 0;                 // frames in a row over the crawl threshold
  int crawling_ = 0;             // frames in a row over kHalvingsPerFrame
};

// What most likely makes a frame this dear, from the held handles at time t
// and their pattern points (m; a released handle has held[h] false): two
// handles at one point whose pattern points are apart, two handles farther
// apart than the sheet reaches, or a handle that moved farther in the frame
// than a hand can. An empty string when none of these holds.
std::string likelyCostCause(const std::vector<std::string>& names,
                            const std::vector<Vec2>& patternPoints,
                            const std::vector<Vec3>& targets,
                            const std::vector<Vec3>& previousTargets, const std::vector<char>& held,
                            double frameSeconds);

// The same for the rig's handles between times tPrevious and t, their pattern
// points read from `pattern` (the frame's, by handle vertex).
std::string likelyCostCause(const model::HandleRig& rig, const std::vector<Vec2>& pattern, double t,
                            double tPrevious);

}  // namespace crumple::pipeline
