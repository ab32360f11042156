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
  CostGuard guard(std::nullopt);
  EXPECT_EQ(guard.budget(), CostGuard::kFirstFramesBudget);
  for (int f = 0; f < CostGuard::kWarmUpFrames - 1; ++f) guard.frameDone(f, 20.0, 0, "");
  EXPECT_EQ(guard.budget(), CostGuard::kFirstFramesBudget);
  guard.frameDone(4, 1000.0, 0, "");  // one dear frame does not move the median
  EXPECT_DOUBLE_EQ(guard.budget(), CostGuard::kRunawayFactor * 20.0);
  CostGuard fast(std::nullopt);
  for (int f = 0; f < 9; ++f) fast.frameDone(f, 0.01, 0, "");
  EXPECT_EQ(fast.budget(), CostGuard::kFirstFramesBudget);
  EXPECT_EQ(CostGuard(7.5).budget(), 7.5);
  EXPECT_EQ(CostGuard(0.0).budget(), 0.0);
}

// A dear frame between cheap ones (a tear) goes on; frames that stay dear
// stop the shot.
TEST(CostGuard, ItStopsAfterFramesInARowThatStayDear) {
  CostGuard guard(std::nullopt);
  for (int f = 0; f < 10; ++f) guard.frameDone(f, 0.5, 0, "");
  guard.frameDone(10, 30.0, 0, "x");  // 60x the median, alone
  guard.frameDone(11, 0.5, 0, "x");
  guard.frameDone(12, 30.0, 0, "x");
  guard.frameDone(13, 30.0, 0, "x");
  guard.frameDone(14, 9.0, 0, "x");  // 18x: not dear enough to count
  guard.frameDone(15, 30.0, 0, "x");
  guard.frameDone(16, 30.0, 0, "x");
  try {
    guard.frameDone(17, 50.0, 0, "handle 'a' moves at 1e+06 m/s");
    FAIL() << "no stop";
  } catch (const NumericalError& e) {
    EXPECT_EQ(e.frame(), 17);
    EXPECT_EQ(e.stage(), "cost guard");
    EXPECT_NE(e.problem().find("3 frames in a row each took more than 10 s"), std::string::npos)
        << e.what();
    EXPECT_NE(e.problem().find("likely cause: handle 'a'"), std::string::npos) << e.what();
  }
  // A fixed budget replaces the crawl rule; 0 turns every rule off.
  for (const double fixed : {60.0, 0.0}) {
    CostGuard given(fixed);
    for (int f = 0; f < 10; ++f) given.frameDone(f, f < 5 ? 0.5 : 30.0, 0, "");
  }
  CostGuard off(0.0);
  for (int f = 0; f < 10; ++f) off.frameDone(f, 1.0, 1000, "");
}

// A hand-over to a dearer model starts a new regime: its frames are not
// judged against the cheap frames before it.
TEST(CostGuard, ANewRegimeIsJudgedAgainstItsOwnFrames) {
  CostGuard guard(std::nullopt);
  for (int f = 0; f < 10; ++f) guard.frameDone(f, 0.2, 0, "");
  guard.newRegime();
  EXPECT_EQ(guard.budget(), CostGuard::kFirstFramesBudget);
  for (int f = 10; f < 20; ++f) guard.frameDone(f, 12.0, 0, "");  // 60x the old median
  EXPECT_DOUBLE_EQ(guard.budget(), CostGuard::kRunawayFactor * 12.0);
  CostGuard same(std::nullopt);
  for (int f = 0; f < 10; ++f) same.frameDone(f, 0.2, 0, "");
  EXPECT_THROW(for (int f = 10; f < 20; ++f) same.frameDone(f, 12.0, 0, ""), NumericalError);
}

TEST(CostGuard, ItStopsAfterFramesInARowThatKeepHalving) {
  CostGuard guard(std::nullopt);
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
