#include "crumple/core/work_budget.hpp"

#include <time.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>

namespace crumple {
namespace {

// A clock's reading in nanoseconds: the process's CPU time
// (CLOCK_PROCESS_CPUTIME_ID) or the monotonic wall clock (a vDSO read, about
// 25 ns here).
std::int64_t nanoseconds(clockid_t clock) {
  timespec t{};
  ::clock_gettime(clock, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1000000000 + t.tv_nsec;
}
std::int64_t cpuNanoseconds() { return nanoseconds(CLOCK_PROCESS_CPUTIME_ID); }
std::int64_t wallNanoseconds() { return nanoseconds(CLOCK_MONOTONIC); }

// The process's CPU clock is a system call (about 550 ns a read on the
// development machine, against 25 ns for the monotonic clock), and the
// isometry projection checks the budget once per length sweep, a few
// microseconds each: read at every check, it cost the crumpling model 3-7 %
// of a frame (bench_hybrid). A check reads it at most once per
// kCpuReadIntervalNs of wall time; the deadline is then late by at most that
// interval times the threads, against budgets of minutes.
constexpr std::int64_t kCpuReadIntervalNs = 5000000;  // 5 ms

// The deadline in CPU nanoseconds; 0 when unarmed.
std::atomic<std::int64_t> deadline{0};
// The wall time (monotonic ns) from which the next check reads the CPU clock.
std::atomic<std::int64_t> nextCpuRead{0};
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
  nextCpuRead.store(0, std::memory_order_relaxed);  // the first check reads the CPU clock
}

void disarmWorkBudget() { deadline.store(0, std::memory_order_relaxed); }

void checkWorkBudget(const char* stage) {
  const std::int64_t at = deadline.load(std::memory_order_relaxed);
  if (at == 0) return;
  const std::int64_t now = wallNanoseconds();
  if (now < nextCpuRead.load(std::memory_order_relaxed)) return;
  nextCpuRead.store(now + kCpuReadIntervalNs, std::memory_order_relaxed);
  if (cpuNanoseconds() < at) return;
  throw WorkBudgetExceeded(stage, budgetSeconds.load(std::memory_order_relaxed));
}

ScopedWorkBudget::ScopedWorkBudget(double seconds) {
  if (seconds > 0.0) armWorkBudget(seconds);
}

ScopedWorkBudget::~ScopedWorkBudget() { disarmWorkBudget(); }

}  // namespace crumple
