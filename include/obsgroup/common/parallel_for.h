#pragma once
/// \file
/// Parallel loops whose body may throw. An exception must not leave an
/// OpenMP region (the process would end in std::terminate), so each is
/// caught, the one of the smallest index is kept (the same whatever the
/// thread count) and rethrown unchanged after the loop. Every parallel loop
/// of obsgroup that can throw goes through these two functions.

#include <cstddef>
#include <exception>
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
/// scratch from make_scratch() (buffers reused across its indices). Rethrows
/// the exception of the smallest failing index.
template <typename MakeScratch, typename Body>
void parallelForWithScratch(std::size_t n, int threads, int chunk, MakeScratch&& make_scratch, Body&& body) {
  std::exception_ptr first;
  std::size_t first_index = n;
  const long long count = static_cast<long long>(n);
#pragma omp parallel num_threads(threadCount(threads))
  {
    auto scratch = make_scratch();
#pragma omp for schedule(dynamic, chunk)
    for (long long i = 0; i < count; ++i) {
      try {
        body(static_cast<std::size_t>(i), scratch);
      } catch (...) {
#pragma omp critical(obsgroup_parallel_for)
        if (static_cast<std::size_t>(i) < first_index) {
          first_index = static_cast<std::size_t>(i);
          first = std::current_exception();
        }
      }
    }
  }
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
