#pragma once
// `obsgroup stream --realtime`: the pace of a replay at the input's stamps,
// with the clock and the nap injectable, so that tests check the schedule
// without waiting on the wall clock.

#include <obsgroup/common/interrupt.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <thread>
#include <vector>

namespace obsgroup::cli {

/// What a replay reads the time from and naps with: the steady clock and
/// std::this_thread::sleep_for, or a test's fake.
struct ReplayTimer {
  using Clock = std::chrono::steady_clock;
  std::function<Clock::time_point()> now = [] { return Clock::now(); };
  std::function<void(Clock::duration)> sleep = [](Clock::duration d) { std::this_thread::sleep_for(d); };
};

/// Paces a replay at the input's stamps: observation k is due at
/// t0 + (stamp_k - stamp_0) wall time, t0 being when observation 0 came.
/// The schedule is absolute, so a slow update is caught up on, and a stamp
/// that goes backwards is already due: it is not slept on.
class ReplayClock {
 public:
  using Clock = ReplayTimer::Clock;
  /// Naps are at most this long, so that Ctrl-C stops a replay waiting for a late stamp.
  static constexpr std::chrono::milliseconds kLongestNap{50};

  /// `stamps` null: no pacing.
  ReplayClock(const std::vector<double>* stamps, const InterruptFlag* interrupt, ReplayTimer timer = {})
      : stamps_(stamps), interrupt_(interrupt), timer_(std::move(timer)) {}

  /// Returns when observation k is due; throws Interrupted when the flag is
  /// set while waiting.
  void waitFor(std::size_t k) {
    if (!stamps_) return;
    if (k == 0) start_ = timer_.now();
    const auto due = start_ + std::chrono::duration_cast<Clock::duration>(
                                  std::chrono::duration<double>((*stamps_)[k] - (*stamps_)[0]));
    const auto before = timer_.now();
    auto now = before;
    for (; now < due; now = timer_.now()) {
      throwIfInterrupted(interrupt_);
      timer_.sleep(std::min<Clock::duration>(due - now, kLongestNap));
    }
    waited_s_ += std::chrono::duration<double>(now - before).count();
  }
  /// The time spent waiting for stamps, seconds.
  double waitedSeconds() const { return waited_s_; }

 private:
  const std::vector<double>* stamps_;
  const InterruptFlag* interrupt_;
  ReplayTimer timer_;
  Clock::time_point start_;
  double waited_s_ = 0.0;
};

}  // namespace obsgroup::cli
