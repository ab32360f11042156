#pragma once
// Deterministic data parallelism: work is split into fixed contiguous chunks
// and each index is processed exactly once, so any per-index result is the
// same whatever the thread count. Reductions must be done by the caller in
// index order after the parallel loop (never with atomics on doubles).
#include <cstddef>
#include <functional>

namespace crumple {

// Process-wide worker count used by parallelFor (>= 1). Set once from --threads.
void setThreadCount(int threads);
int threadCount();

// Calls body(begin, end) on disjoint ranges covering [0, n). Runs inline when
// one thread is configured or n is below minChunk. Exceptions are rethrown
// (the one from the lowest range first).
void parallelFor(std::size_t n, const std::function<void(std::size_t, std::size_t)>& body,
                 std::size_t minChunk = 64);

}  // namespace crumple
