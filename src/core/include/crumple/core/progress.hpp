#pragma once
// Progress on long work (docs/ARCHITECTURE.md "The command line"): a redrawn bar with ETA
// on a terminal, one machine-readable "PROGRESS <percent>" line per step
// otherwise (farm managers parse these).
#include <chrono>
#include <cstdio>
#include <string>

namespace crumple {

class Progress {
 public:
  // total: number of steps; label: what is being done; out: where to write
  // (nullptr: nowhere, a quiet run). interactive: -1 = detect with isatty on out.
  Progress(std::string label, long total, std::FILE* out = stderr, int interactive = -1);
  // Mark `done` steps complete (monotonic) and report.
  void update(long done);
  // Finish the line on a terminal.
  void finish();
  bool interactive() const { return interactive_; }

 private:
  std::string label_;
  long total_;
  std::FILE* out_;
  bool interactive_;
  std::chrono::steady_clock::time_point start_;
  int lastPercent_ = -1;
};

}  // namespace crumple
