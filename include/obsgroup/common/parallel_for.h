#pragma once
/// \file
/// A parallel loop whose body may throw: an exception must not leave an
/// OpenMP region (the process would end in std::terminate), so each is
/// caught, the one of the smallest index is kept (the same whatever the
/// thread count) and rethrown unchanged after the loop.

#include <cstddef>
#include <exception>

namespace obsgroup {

/// Runs body(i) for i in [0, n) on `threads` threads, dynamically scheduled
/// one index at a time; rethrows the exception of the smallest failing index.
template <typename Body>
void parallelFor(std::size_t n, int threads, Body&& body) {
  std::exception_ptr first;
  std::size_t first_index = n;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (long long i = 0; i < static_cast<long long>(n); ++i) {
    try {
      body(static_cast<std::size_t>(i));
    } catch (...) {
#pragma omp critical(obsgroup_parallel_for)
      if (static_cast<std::size_t>(i) < first_index) {
        first_index = static_cast<std::size_t>(i);
        first = std::current_exception();
      }
    }
  }
  if (first) std::rethrow_exception(first);
}

}  // namespace obsgroup
