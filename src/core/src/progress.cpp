#include "crumple/core/progress.hpp"

#include <unistd.h>

#include <algorithm>

namespace crumple {

Progress::Progress(std::string label, long total, std::FILE* out, int interactive)
    : label_(std::move(label)),
      total_(std::max(1L, total)),
      out_(out),
      interactive_(out != nullptr &&
                   (interactive < 0 ? ::isatty(::fileno(out)) != 0 : interactive != 0)),
      start_(std::chrono::steady_clock::now()) {}

void Progress::update(long done) {
  if (out_ == nullptr) return;
  done = std::clamp(done, 0L, total_);
  const int percent = static_cast<int>(100 * done / total_);
  if (!interactive_) {
    // One line per step, even when the integer percentage repeats, so a farm
    // manager sees the job is alive.
    std::fprintf(out_, "PROGRESS %d\n", percent);
    std::fflush(out_);
    return;
  }
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double eta = done > 0 ? elapsed * static_cast<double>(total_ - done) / done : 0.0;
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(kWidth * done / total_);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kWidth, '.');
  std::fprintf(out_, "\r%s [%s] %3d%% %ld/%ld  elapsed %.1fs  ETA %.1fs ", label_.c_str(),
               bar.c_str(), percent, done, total_, elapsed, eta);
  std::fflush(out_);
  lastPercent_ = percent;
}

void Progress::finish() {
  if (interactive_ && lastPercent_ >= 0) {
    std::fputc('\n', out_);
    std::fflush(out_);
  }
}

}  // namespace crumple
