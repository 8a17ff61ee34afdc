#pragma once
/// \file
/// Handing freed memory back to the system. The per-observation lists of a
/// large run (points, ranges, region cells: a few kilobytes each) are too
/// small for malloc to return by itself once freed; kept, they count in
/// every later stage's resident memory.

#include <cstddef>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace obsgroup {

/// Trimming walks the heap: only worth it past this many freed bytes.
inline constexpr std::size_t kTrimBytes = std::size_t(64) << 20;

/// Returns the pages of `bytes` of small blocks just freed to the system
/// (glibc's malloc_trim; elsewhere nothing).
inline void returnFreedMemory(std::size_t bytes) {
#if defined(__GLIBC__)
  if (bytes >= kTrimBytes) malloc_trim(0);
#else
  (void)bytes;
#endif
}

}  // namespace obsgroup
