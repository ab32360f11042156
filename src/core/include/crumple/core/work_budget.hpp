#pragma once
// A budget of CPU time for one unit of work (the shot's cost guard: one
// frame), checked by the long loops inside the stages (the elastic model's
// Newton iterations, the crumpling model's length projections). The shot arms
// it before a frame and disarms it after; a loop that finds the deadline
// passed throws WorkBudgetExceeded, a NumericalError naming its stage, which
// unwinds the stage as any numerical failure does (positions restored, the
// cache kept valid up to the last good frame). Unarmed, a check is one
// relaxed atomic load. Process-wide: one shot runs per process. The clock is
// the process's CPU time (every thread's), not the wall clock: a machine
// loaded by other work slows a frame's wall time several times over without
// its costing more, and must not stop a shot.
#include <string>

#include "crumple/core/error.hpp"

namespace crumple {

class WorkBudgetExceeded : public NumericalError {
 public:
  WorkBudgetExceeded(const std::string& stage, double seconds);
  double seconds() const { return seconds_; }

 private:
  double seconds_;
};

// The process's CPU time so far (s): the clock of the budget.
double processCpuSeconds();

// Arms the budget: work checked from now on may use `seconds` (> 0) of CPU
// time. Re-arming replaces the deadline.
void armWorkBudget(double seconds);
// No deadline (the default).
void disarmWorkBudget();
// Throws WorkBudgetExceeded naming `stage` when an armed budget has run out.
void checkWorkBudget(const char* stage);

// Arms on construction, disarms on destruction (a frame's scope).
class ScopedWorkBudget {
 public:
  explicit ScopedWorkBudget(double seconds);
  ~ScopedWorkBudget();
  ScopedWorkBudget(const ScopedWorkBudget&) = delete;
  ScopedWorkBudget& operator=(const ScopedWorkBudget&) = delete;
};

}  // namespace crumple
