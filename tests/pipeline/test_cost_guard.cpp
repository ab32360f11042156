// The shot's cost guard (pipeline/src/cost_guard.hpp, docs/RELIABILITY.md
// "The cost guard"): its budget, its halvings rule and the causes it names.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "cost_guard.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/work_budget.hpp"

namespace crumple::pipeline {
namespace {

TEST(CostGuard, TheRunawayBudgetFollowsTheShotsOwnMedianFrame) {
  CostGuard guard(std::nullopt, 1.0);
  EXPECT_EQ(guard.budget(), CostGuard::kFirstFramesBudget);
  for (int f = 0; f < CostGuard::kWarmUpFrames - 1; ++f) guard.frameDone(f, 20.0, 0, "");
  EXPECT_EQ(guard.budget(), CostGuard::kFirstFramesBudget);
  guard.frameDone(4, 1000.0, 0, "");  // one dear frame does not move the median
  EXPECT_DOUBLE_EQ(guard.budget(), CostGuard::kRunawayFactor * 20.0);
  CostGuard fast(std::nullopt, 1.0);
  for (int f = 0; f < 9; ++f) fast.frameDone(f, 0.01, 0, "");
  EXPECT_EQ(fast.budget(), CostGuard::kFirstFramesBudget);
  EXPECT_EQ(CostGuard(7.5, 1.0).budget(), 7.5);
  EXPECT_EQ(CostGuard(0.0, 1.0).budget(), 0.0);
}

// A run of dear frames that ends (a tear) goes on; frames that stay dear
// stop the shot.
TEST(CostGuard, ItStopsAfterFramesInARowThatStayDear) {
  // samples/tear-fast's CPU seconds per frame (Release, development machine).
  const std::vector<double> tearFast = {0.14, 0.06, 0.03, 0.03, 0.03, 0.02, 0.03,  0.71,
                                        0.59, 0.70, 4.91, 2.07, 9.43, 8.75, 20.08, 15.73,
                                        7.78, 0.62, 0.39, 0.28, 0.24, 0.20, 0.19,  0.19};
  CostGuard tear(std::nullopt, 1.0);
  for (std::size_t f = 0; f < tearFast.size(); ++f)
    tear.frameDone(static_cast<int>(f), tearFast[f], 0, "");
  // Twice as dear, a run of three over the floor, still goes on.
  CostGuard dearer(std::nullopt, 1.0);
  for (std::size_t f = 0; f < tearFast.size(); ++f)
    dearer.frameDone(static_cast<int>(f), 2.0 * tearFast[f], 0, "");
  // A handle thrown out of reach: 40-83 s a frame from frame 31 on (62-84 s
  // re-measured; the first report of the case had 40-83 s).
  CostGuard guard(std::nullopt, 1.0);
  for (int f = 0; f < 31; ++f) guard.frameDone(f, 0.11, 0, "x");
  for (int f = 31; f < 31 + CostGuard::kSlowFrames - 1; ++f) guard.frameDone(f, 40.0, 0, "x");
  try {
    guard.frameDone(35, 83.0, 0, "handle 'a' moves at 1e+06 m/s");
    FAIL() << "no stop";
  } catch (const NumericalError& e) {
    EXPECT_EQ(e.frame(), 35);
    EXPECT_EQ(e.stage(), "cost guard");
    EXPECT_NE(e.problem().find("5 frames in a row each took more than 20 s"), std::string::npos)
        << e.what();
    EXPECT_NE(e.problem().find("likely cause: handle 'a'"), std::string::npos) << e.what();
  }
  // A fixed budget replaces the crawl rule; 0 turns every rule off.
  for (const double fixed : {60.0, 0.0}) {
    CostGuard given(fixed, 1.0);
    for (int f = 0; f < 20; ++f) given.frameDone(f, f < 5 ? 0.5 : 30.0, 0, "");
  }
  CostGuard off(0.0, 1.0);
  for (int f = 0; f < 10; ++f) off.frameDone(f, 1.0, 1000, "");
}

// The floors are the reference machine's seconds times the process's
// slowness: tear-fast run 10x slower (a sanitized build on a slower machine)
// goes on with the slowness it measured, and is stopped as crawling by a
// guard that took it for the reference machine. The first frames' budget
// scales too: tear-cylinder's hand-over frame (57 s in Release) would take
// about 400 s at 7x, past the unscaled 300 s.
TEST(CostGuard, ItsFloorsScaleWithTheMachinesSlowness) {
  const std::vector<double> tearFast = {0.14, 0.06, 0.03, 0.03, 0.03, 0.02, 0.03,  0.71,
                                        0.59, 0.70, 4.91, 2.07, 9.43, 8.75, 20.08, 15.73,
                                        7.78, 0.62, 0.39, 0.28, 0.24, 0.20, 0.19,  0.19};
  const double slowness = 10.0;
  CostGuard scaled(std::nullopt, slowness);
  EXPECT_DOUBLE_EQ(scaled.budget(), slowness * CostGuard::kFirstFramesBudget);
  for (std::size_t f = 0; f < tearFast.size(); ++f)
    scaled.frameDone(static_cast<int>(f), slowness * tearFast[f], 0, "");
  CostGuard unscaled(std::nullopt, 1.0);
  try {
    for (std::size_t f = 0; f < tearFast.size(); ++f)
      unscaled.frameDone(static_cast<int>(f), slowness * tearFast[f], 0, "");
    FAIL() << "no stop";
  } catch (const NumericalError& e) {
    EXPECT_EQ(e.frame(), 14);
  }
  EXPECT_LT(CostGuard(std::nullopt, 1.0).budget(), 400.0);
  EXPECT_GT(CostGuard(std::nullopt, 7.0).budget(), 400.0);
  // The stop says what the budget is here and on the reference machine.
  const std::string problem = CostGuard(std::nullopt, 2.0).budgetError(3, "elastic", "").problem();
  EXPECT_NE(problem.find("budget of 600 s (the first frames' budget: 600 s here, 300 s on the "
                         "reference machine times this one's slowness, 2)"),
            std::string::npos)
      << problem;
}

// A hand-over to a dearer model starts a new regime: its frames are not
// judged against the cheap frames before it.
TEST(CostGuard, ANewRegimeIsJudgedAgainstItsOwnFrames) {
  CostGuard guard(std::nullopt, 1.0);
  for (int f = 0; f < 10; ++f) guard.frameDone(f, 0.2, 0, "");
  guard.newRegime();
  EXPECT_EQ(guard.budget(), CostGuard::kFirstFramesBudget);
  for (int f = 10; f < 20; ++f) guard.frameDone(f, 25.0, 0, "");  // 125x the old median
  EXPECT_DOUBLE_EQ(guard.budget(), CostGuard::kRunawayFactor * 25.0);
  CostGuard same(std::nullopt, 1.0);
  for (int f = 0; f < 10; ++f) same.frameDone(f, 0.2, 0, "");
  EXPECT_THROW(for (int f = 10; f < 20; ++f) same.frameDone(f, 25.0, 0, ""), NumericalError);
}

TEST(CostGuard, ItStopsAfterFramesInARowThatKeepHalving) {
  CostGuard guard(std::nullopt, 1.0);
  const long many = CostGuard::kHalvingsPerFrame + 1;
  guard.frameDone(1, 1.0, many, "x");
  guard.frameDone(2, 1.0, 0, "x");  // a calm frame resets the count
  for (int f = 3; f < 3 + CostGuard::kHalvingFrames - 1; ++f) guard.frameDone(f, 1.0, many, "x");
  try {
    guard.frameDone(9, 1.0, many, "handles 'a' and 'b' are at one point");
    FAIL() << "no stop";
  } catch (const NumericalError& e) {
    EXPECT_EQ(e.frame(), 9);
    EXPECT_EQ(e.stage(), "cost guard");
    EXPECT_NE(e.problem().find("likely cause: handles 'a' and 'b' are at one point"),
              std::string::npos)
        << e.what();
  }
}

TEST(CostGuard, ItNamesCoincidentOutOfReachAndJumpingHandles) {
  const std::vector<std::string> names = {"left", "right", "free"};
  const std::vector<Vec2> pattern = {Vec2(0, 0.3), Vec2(0.2, 0.3), Vec2(0.1, 0)};
  const std::vector<char> held = {1, 1, 0};
  const Vec3 a(0, 1, 0);
  // At one point: 0.5 mm apart, 20 cm apart in the pattern.
  std::string cause = likelyCostCause(names, pattern, {a, a + Vec3(5e-4, 0, 0), Vec3(9, 9, 9)},
                                      {a, a, a}, held, 1.0 / 24);
  EXPECT_NE(cause.find("'left' and 'right' are at one point"), std::string::npos) << cause;
  // Out of reach: 1 km apart.
  cause = likelyCostCause(names, pattern, {a, a + Vec3(1000, 0, 0), a}, {a, a, a}, held, 1.0);
  EXPECT_NE(cause.find("farther than the sheet reaches"), std::string::npos) << cause;
  // One handle alone, jumping 10 m in 1/24 s (240 m/s).
  cause = likelyCostCause({"left"}, {Vec2(0, 0)}, {a + Vec3(10, 0, 0)}, {a}, {1}, 1.0 / 24);
  EXPECT_NE(cause.find("'left' moves at 240 m/s"), std::string::npos) << cause;
  // Within reach, at a hand's speed, a released handle far away: nothing.
  EXPECT_EQ(likelyCostCause(names, pattern, {a, a + Vec3(0.15, 0, 0), a + Vec3(1000, 0, 0)},
                            {a, a + Vec3(0.14, 0, 0), a}, held, 1.0 / 24),
            "");
}

TEST(WorkBudget, AnArmedBudgetThatRanOutStopsTheNextCheck) {
  checkWorkBudget("unarmed");  // no deadline: nothing happens
  {
    const ScopedWorkBudget budget(1e-9);
    volatile double sink = 0.0;
    for (int i = 0; i < 100000; ++i) sink = sink + i;
    try {
      checkWorkBudget("elastic");
      FAIL() << "no stop";
    } catch (const WorkBudgetExceeded& e) {
      EXPECT_EQ(e.stage(), "elastic");
    }
  }
  checkWorkBudget("disarmed");  // the scope ended: no deadline
  const ScopedWorkBudget generous(3600.0);
  EXPECT_NO_THROW(checkWorkBudget("elastic"));
}

// Checks read the process's CPU clock (a system call) at most every few
// milliseconds of wall time, so that a loop may check at every sweep: a
// budget that runs out between two reads still stops a check soon after.
TEST(WorkBudget, ABudgetThatRunsOutBetweenClockReadsStillStopsTheLoop) {
  const ScopedWorkBudget budget(0.02);  // 20 ms of CPU time
  checkWorkBudget("isometry");          // within it
  const auto start = std::chrono::steady_clock::now();
  bool stopped = false;
  volatile double sink = 0.0;
  while (!stopped && std::chrono::steady_clock::now() - start < std::chrono::seconds(30)) {
    for (int i = 0; i < 1000; ++i) sink = sink + i;
    try {
      checkWorkBudget("isometry");
    } catch (const WorkBudgetExceeded&) {
      stopped = true;
    }
  }
  EXPECT_TRUE(stopped) << "an armed budget never stopped a busy loop";
}

}  // namespace
}  // namespace crumple::pipeline
