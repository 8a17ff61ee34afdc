#pragma once
// A progress bar on stderr, shown only when stderr is a terminal: one line,
// updated in place, that each stage of a run takes in turn.

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <functional>
#include <string>

namespace obsgroup::cli {

/// Told every step of every stage ("read", "overlap", ...), whether or not a
/// bar is drawn: how a program running the command follows it.
using ProgressObserver = std::function<void(const std::string& stage, std::size_t done, std::size_t total)>;

class ProgressBar {
 public:
  ProgressBar(std::string label, bool enabled, ProgressObserver observer = {})
      : label_(std::move(label)), enabled_(enabled && ::isatty(2)), observer_(std::move(observer)) {}
  ~ProgressBar() { finish(); }

  void operator()(std::size_t done, std::size_t total) {
    if (observer_) observer_(label_, done, total);
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (done < total && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const int width = 30;
    const int filled = total ? static_cast<int>(width * done / total) : width;
    std::fprintf(stderr, "\r%s [%s%s] %3d%% %zu/%zu", label_.c_str(), std::string(filled, '#').c_str(),
                 std::string(width - filled, '.').c_str(), total ? static_cast<int>(100 * done / total) : 100,
                 done, total);
    std::fflush(stderr);
    shown_ = true;
  }

  /// Clears the line: every stage's bar takes the same line in turn, and
  /// what follows (a warning, the summary) starts on a clean one.
  void finish() {
    if (shown_) std::fprintf(stderr, "\r\033[K");
    shown_ = false;
  }

 private:
  std::string label_;
  bool enabled_;
  ProgressObserver observer_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point last_{};
};

}  // namespace obsgroup::cli
