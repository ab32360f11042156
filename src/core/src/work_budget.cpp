#include "crumple/core/work_budget.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>

namespace crumple {
namespace {

using Clock = std::chrono::steady_clock;

// The deadline in Clock ticks since its epoch; 0 when unarmed.
std::atomic<std::int64_t> deadline{0};
std::atomic<double> budgetSeconds{0.0};

std::string budgetText(double seconds) {
  char text[96];
  std::snprintf(text, sizeof text, "the frame's budget of %.3g s ran out", seconds);
  return text;
}

}  // namespace

WorkBudgetExceeded::WorkBudgetExceeded(const std::string& stage, double seconds)
    : NumericalError(stage, budgetText(seconds)), seconds_(seconds) {}

void armWorkBudget(double seconds) {
  const auto span =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  budgetSeconds.store(seconds, std::memory_order_relaxed);
  deadline.store(std::max<std::int64_t>(1, (Clock::now() + span).time_since_epoch().count()),
                 std::memory_order_relaxed);
}

void disarmWorkBudget() { deadline.store(0, std::memory_order_relaxed); }

void checkWorkBudget(const char* stage) {
  const std::int64_t at = deadline.load(std::memory_order_relaxed);
  if (at == 0 || Clock::now().time_since_epoch().count() < at) return;
  throw WorkBudgetExceeded(stage, budgetSeconds.load(std::memory_order_relaxed));
}

ScopedWorkBudget::ScopedWorkBudget(double seconds) {
  if (seconds > 0.0) armWorkBudget(seconds);
}

ScopedWorkBudget::~ScopedWorkBudget() { disarmWorkBudget(); }

}  // namespace crumple
