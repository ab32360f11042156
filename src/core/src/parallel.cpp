#include "crumple/core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>
#include <vector>

namespace crumple {
namespace {
std::atomic<int> gThreads{1};
}

void setThreadCount(int threads) { gThreads.store(std::max(1, threads)); }
int threadCount() { return gThreads.load(); }

void parallelFor(std::size_t n, const std::function<void(std::size_t, std::size_t)>& body,
                 std::size_t minChunk) {
  const std::size_t threads = static_cast<std::size_t>(threadCount());
  if (threads <= 1 || n < 2 * std::max<std::size_t>(1, minChunk)) {
    if (n > 0) body(0, n);
    return;
  }
  const std::size_t parts = std::min(threads, n / std::max<std::size_t>(1, minChunk));
  std::vector<std::exception_ptr> errors(parts);
  std::vector<std::thread> workers;
  workers.reserve(parts - 1);
  auto run = [&](std::size_t p) {
    const std::size_t begin = n * p / parts;
    const std::size_t end = n * (p + 1) / parts;
    try {
      body(begin, end);
    } catch (...) {
      errors[p] = std::current_exception();
    }
  };
  for (std::size_t p = 1; p < parts; ++p) workers.emplace_back(run, p);
  run(0);
  for (auto& w : workers) w.join();
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace crumple
