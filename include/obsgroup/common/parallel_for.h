#pragma once
/// \file
/// Parallel loops whose body may throw. An exception must not leave an
/// OpenMP region (the process would end in std::terminate), so each is
/// caught, the one of the smallest index is kept (the same whatever the
/// thread count) and rethrown unchanged after the loop. Every parallel loop
/// of obsgroup that can throw goes through these two functions.

#include <atomic>
#include <cstddef>
#include <algorithm>
#include <exception>
#include <optional>
#include <utility>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace obsgroup {

/// The thread count a loop runs on: `threads`, or all cores when it is 0 or less.
inline int threadCount(int threads) {
#ifdef _OPENMP
  return threads > 0 ? threads : omp_get_max_threads();
#else
  (void)threads;
  return 1;
#endif
}

/// Runs body(i, scratch) for i in [0, n) on threadCount(threads) threads,
/// dynamically scheduled `chunk` indices at a time. Each thread gets its own
/// scratch from make_scratch() (buffers reused across its indices); a loop of
/// one chunk or less, or on one thread, runs in order on the calling thread
/// with one scratch. Rethrows the exception of the smallest failing index.
template <typename MakeScratch, typename Body>
void parallelForWithScratch(std::size_t n, int threads, int chunk, MakeScratch&& make_scratch, Body&& body) {
  // A loop of one chunk or less runs here, without an OpenMP team: the
  // online grouping runs thousands of such loops (a level of the split tree
  // with one node, a few regions to recompute), and each team's start and
  // end hands work between threads that then spin or sleep in between
  // (docs/performance.md, "Beside other work").
  if (n <= std::size_t(std::max(chunk, 1)) || threadCount(threads) == 1) {
    if (n == 0) return;
    auto scratch = make_scratch();
    for (std::size_t i = 0; i < n; ++i) body(i, scratch);  // the first failure is the smallest index
    return;
  }
  std::exception_ptr first, scratch_failed;
  // Indices after a failed one are skipped: they cannot change which
  // exception is rethrown, and a failing callback should not be called on.
  std::atomic<std::size_t> first_index{n};
  std::atomic<bool> no_scratch{false};  // a thread could not make its scratch: nothing more runs
  const long long count = static_cast<long long>(n);
#pragma omp parallel num_threads(threadCount(threads))
  {
    // Every thread must reach the loop (a worksharing construct), so a
    // scratch that cannot be made is remembered, not thrown here.
    std::optional<decltype(make_scratch())> scratch;
    try {
      scratch.emplace(make_scratch());
    } catch (...) {
#pragma omp critical(obsgroup_parallel_for)
      if (!scratch_failed) scratch_failed = std::current_exception();
      no_scratch = true;
    }
#pragma omp for schedule(dynamic, chunk)
    for (long long i = 0; i < count; ++i) {
      if (!scratch || no_scratch.load(std::memory_order_relaxed) ||
          static_cast<std::size_t>(i) > first_index.load(std::memory_order_relaxed))
        continue;
      try {
        body(static_cast<std::size_t>(i), *scratch);
      } catch (...) {
#pragma omp critical(obsgroup_parallel_for)
        if (static_cast<std::size_t>(i) < first_index || !first) {
          first_index = std::min<std::size_t>(first_index, static_cast<std::size_t>(i));
          first = std::current_exception();
        }
      }
    }
  }
  if (scratch_failed) std::rethrow_exception(scratch_failed);
  if (first) std::rethrow_exception(first);
}

/// Runs body(i) for i in [0, n) on threadCount(threads) threads, `chunk`
/// indices at a time; rethrows the exception of the smallest failing index.
template <typename Body>
void parallelFor(std::size_t n, int threads, int chunk, Body&& body) {
  struct NoScratch {};
  parallelForWithScratch(
      n, threads, chunk, [] { return NoScratch{}; }, [&body](std::size_t i, NoScratch&) { body(i); });
}

/// parallelFor one index at a time: for loops of few, long iterations.
template <typename Body>
void parallelFor(std::size_t n, int threads, Body&& body) {
  parallelFor(n, threads, 1, std::forward<Body>(body));
}

}  // namespace obsgroup
