// How fast this process runs the reference workload
// (core/machine_speed.hpp): measured once, and the slowness is its ratio to
// the development machine's figure.
#include <gtest/gtest.h>

#include <cmath>

#include "crumple/core/machine_speed.hpp"
#include "crumple/core/work_budget.hpp"

namespace crumple {
namespace {

TEST(MachineSpeed, TheReferenceIsMeasuredOnceAndTheSlownessIsItsRatio) {
  const double before = processCpuSeconds();
  const double seconds = referenceWorkSeconds();
  const double spent = processCpuSeconds() - before;
  ASSERT_TRUE(std::isfinite(seconds));
  EXPECT_GT(seconds, 0.0);
  // Three runs, the best kept: the measurement took at least three times it.
  EXPECT_GE(spent, 3.0 * seconds * 0.999);
  const double again = processCpuSeconds();
  EXPECT_EQ(referenceWorkSeconds(), seconds);  // not measured again
  EXPECT_LT(processCpuSeconds() - again, 0.5 * seconds);
  EXPECT_DOUBLE_EQ(machineSlowness(), seconds / kReferenceWorkSeconds);
}

}  // namespace
}  // namespace crumple
