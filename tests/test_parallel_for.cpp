// The parallel loops every stage runs on: each index once, the exception of
// the smallest failing index, and loops too small to share run on the
// calling thread, without an OpenMP team.
#include <obsgroup/common/parallel_for.h>

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace obsgroup;

namespace {

/// Inside a parallel region, even a team of one thread (which omp_in_parallel does not count).
bool inTeam() {
#ifdef _OPENMP
  return omp_get_level() > 0;
#else
  return false;
#endif
}

TEST(ParallelFor, RunsEveryIndexOnceWhateverTheSizeChunkAndThreads) {
  for (std::size_t n : {0u, 1u, 3u, 4u, 5u, 1000u})
    for (int threads : {1, 2, 0})
      for (int chunk : {1, 4, 64}) {
        std::vector<std::atomic<int>> runs(n);
        parallelFor(n, threads, chunk, [&](std::size_t i) { ++runs[i]; });
        for (std::size_t i = 0; i < n; ++i)
          ASSERT_EQ(runs[i].load(), 1) << "n " << n << ", threads " << threads << ", chunk " << chunk << ", i " << i;
      }
}

TEST(ParallelFor, RethrowsTheExceptionOfTheSmallestFailingIndex) {
  for (std::size_t n : {3u, 200u})
    for (int threads : {1, 2}) {
      try {
        parallelFor(n, threads, 4, [](std::size_t i) {
          if (i % 2 == 1) throw std::runtime_error(std::to_string(i));
        });
        FAIL() << "nothing thrown";
      } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "1") << "n " << n << ", threads " << threads;
      }
    }
}

TEST(ParallelFor, RethrowsAScratchThatCannotBeMade) {
  for (std::size_t n : {2u, 200u}) {
    int calls = 0;
    EXPECT_THROW(parallelForWithScratch(
                     n, 2, 4, []() -> int { throw std::invalid_argument("no scratch"); },
                     [&calls](std::size_t, int&) { ++calls; }),
                 std::invalid_argument);
    EXPECT_EQ(calls, 0) << "n " << n;
  }
}

TEST(ParallelFor, ALoopOfOneChunkRunsOnTheCallingThreadWithOneScratch) {
  int scratches = 0;
  std::vector<int> order;
  parallelForWithScratch(
      4, 2, 4, [&scratches] { return ++scratches; },
      [&order](std::size_t i, int&) {
        EXPECT_FALSE(inTeam());
        order.push_back(int(i));
      });
  EXPECT_EQ(scratches, 1);
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3}));
  // One thread asked: the same, whatever the size.
  parallelFor(1000, 1, 4, [](std::size_t) { EXPECT_FALSE(inTeam()); });
}

TEST(ParallelFor, ALargerLoopIsSharedByTheThreadsAsked) {
#ifdef _OPENMP
  std::atomic<int> in_team{0};
  std::mutex seen_mutex;
  std::vector<int> threads_seen;
  parallelFor(1000, 2, 4, [&](std::size_t) {
    if (inTeam()) ++in_team;
    std::lock_guard<std::mutex> lock(seen_mutex);
    threads_seen.push_back(omp_get_num_threads());
  });
  EXPECT_EQ(in_team.load(), 1000);
  for (int t : threads_seen) ASSERT_EQ(t, 2);
#else
  GTEST_SKIP() << "built without OpenMP";
#endif
}

}  // namespace
