#include "crumple/core/work_budget.hpp"

#include <time.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>

namespace crumple {
namespace {

// The process's CPU time in nanoseconds.
std::int64_t cpuNanoseconds() {
  timespec t{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1000000000 + t.tv_nsec;
}

// The deadline in CPU nanoseconds; 0 when unarmed.
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

double processCpuSeconds() { return static_cast<double>(cpuNanoseconds()) * 1e-9; }

void armWorkBudget(double seconds) {
  const double span = std::min(seconds * 1e9, 1e17);  // within the clock's range
  budgetSeconds.store(seconds, std::memory_order_relaxed);
  deadline.store(std::max<std::int64_t>(1, cpuNanoseconds() + static_cast<std::int64_t>(span)),
                 std::memory_order_relaxed);
}

void disarmWorkBudget() { deadline.store(0, std::memory_order_relaxed); }

void checkWorkBudget(const char* stage) {
  const std::int64_t at = deadline.load(std::memory_order_relaxed);
  if (at == 0 || cpuNanoseconds() < at) return;
  throw WorkBudgetExceeded(stage, budgetSeconds.load(std::memory_order_relaxed));
}

ScopedWorkBudget::ScopedWorkBudget(double seconds) {
  if (seconds > 0.0) armWorkBudget(seconds);
}

ScopedWorkBudget::~ScopedWorkBudget() { disarmWorkBudget(); }

}  // namespace crumple
