#pragma once
/// \file
/// Cooperative interruption of long computations: a flag the caller sets
/// (from a signal handler, a GUI button, another thread) and the library
/// polls between units of work. Stopping this way unwinds cleanly, so a
/// caller can remove half-made outputs instead of being killed mid-write.

#include <atomic>
#include <stdexcept>

namespace obsgroup {

/// Set to true to ask a running computation to stop. A lock-free atomic, so
/// a signal handler may set it.
using InterruptFlag = std::atomic<bool>;

/// Thrown by a computation that saw its InterruptFlag set.
class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

/// True when `flag` is given and set.
inline bool interruptRequested(const InterruptFlag* flag) {
  return flag != nullptr && flag->load(std::memory_order_relaxed);
}

inline void throwIfInterrupted(const InterruptFlag* flag) {
  if (interruptRequested(flag)) throw Interrupted();
}

}  // namespace obsgroup
