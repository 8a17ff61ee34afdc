// `stream --realtime`'s schedule, on a fake clock: what is waited for and
// when, with no test waiting on the wall clock.
#include "replay_clock.h"

#include <gtest/gtest.h>

#include <chrono>
#include <vector>

using namespace obsgroup;
using namespace std::chrono_literals;
using cli::ReplayClock;
using cli::ReplayTimer;

namespace {

/// A clock that moves only when napped on or told to.
struct FakeTime {
  ReplayTimer::Clock::time_point now{1000s};
  std::vector<ReplayTimer::Clock::duration> naps;
  ReplayTimer timer() {
    return {[this] { return now; }, [this](ReplayTimer::Clock::duration d) {
              naps.push_back(d);
              now += d;
            }};
  }
  ReplayTimer::Clock::duration napped() const {
    ReplayTimer::Clock::duration total{};
    for (auto d : naps) total += d;
    return total;
  }
};

}  // namespace

TEST(ReplayClock, WaitsUntilEachStampIsDueOnAnAbsoluteSchedule) {
  const std::vector<double> stamps{100.0, 100.25, 100.125, 100.5, 100.75, 100.75};  // exact in binary
  FakeTime time;
  ReplayClock clock(&stamps, nullptr, time.timer());
  const auto start = time.now;
  // Each observation takes 50 ms to insert; observation k is then due at
  // start + stamp_k - stamp_0, so the waits are 200, 0 (its stamp went
  // back), 150, 200 and 0 (due with the one before) ms.
  const std::vector<std::chrono::milliseconds> expected_wait{0ms, 200ms, 0ms, 150ms, 200ms, 0ms};
  for (std::size_t k = 0; k < stamps.size(); ++k) {
    const auto napped_before = time.napped();
    clock.waitFor(k);
    EXPECT_EQ(std::chrono::duration_cast<std::chrono::milliseconds>(time.napped() - napped_before), expected_wait[k])
        << "observation " << k;
    if (k > 0 && expected_wait[k] > 0ms) {
      EXPECT_EQ(time.now, start + std::chrono::duration_cast<ReplayTimer::Clock::duration>(
                                      std::chrono::duration<double>(stamps[k] - stamps[0])))
          << "observation " << k;
    }
    time.now += 50ms;  // the insert and update
  }
  EXPECT_NEAR(clock.waitedSeconds(), 0.55, 1e-9);
  for (auto nap : time.naps) EXPECT_LE(nap, ReplayClock::kLongestNap);
}

TEST(ReplayClock, ASlowUpdateIsCaughtUpOnNotAddedTo) {
  const std::vector<double> stamps{0.0, 0.125, 0.25, 0.375};
  FakeTime time;
  ReplayClock clock(&stamps, nullptr, time.timer());
  clock.waitFor(0);
  time.now += 300ms;  // an update slower than the stamps
  clock.waitFor(1);
  clock.waitFor(2);
  EXPECT_TRUE(time.naps.empty());
  clock.waitFor(3);
  EXPECT_EQ(std::chrono::duration_cast<std::chrono::milliseconds>(time.napped()), 75ms);
}

TEST(ReplayClock, CtrlCWhileWaitingStopsWithinOneNap) {
  const std::vector<double> stamps{0.0, 60.0};
  InterruptFlag interrupt{false};
  FakeTime time;
  ReplayTimer timer = time.timer();
  const auto nap = timer.sleep;
  timer.sleep = [&](ReplayTimer::Clock::duration d) {
    nap(d);
    if (time.naps.size() == 3) interrupt = true;  // Ctrl-C during the third nap
  };
  ReplayClock clock(&stamps, &interrupt, timer);
  clock.waitFor(0);
  EXPECT_THROW(clock.waitFor(1), Interrupted);
  EXPECT_EQ(time.naps.size(), 3u);
}

TEST(ReplayClock, WithoutStampsNothingIsWaitedFor) {
  FakeTime time;
  ReplayClock clock(nullptr, nullptr, time.timer());
  for (std::size_t k = 0; k < 3; ++k) clock.waitFor(k);
  EXPECT_TRUE(time.naps.empty());
  EXPECT_EQ(clock.waitedSeconds(), 0.0);
}
