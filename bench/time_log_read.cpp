// Seconds to read a CARMEN log with readCarmenLog, the best of REPEATS runs:
//   time_log_read LOG [REPEATS=3] [THREADS=0]
// Compare a log with its gzipped copy: gzip -k LOG && time_log_read LOG.gz
#include <obsgroup/io/carmen_reader.h>
#include <obsgroup/io/errors.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: time_log_read LOG [REPEATS=3] [THREADS=0]\n");
    return 2;
  }
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  obsgroup::io::CarmenOptions options;
  options.threads = argc > 3 ? std::atoi(argv[3]) : 0;
  double best = std::numeric_limits<double>::infinity();
  std::size_t scans = 0;
  try {
    for (int k = 0; k < repeats; ++k) {
      const auto start = std::chrono::steady_clock::now();
      scans = obsgroup::io::readCarmenLog(argv[1], options).scans.size();
      best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
  } catch (const obsgroup::io::InputError& e) {
    std::fprintf(stderr, "time_log_read: %s\n", e.what());
    return 3;
  }
  std::printf("%s: %zu scans, best of %d: %.3f s\n", argv[1], scans, repeats, best);
  return 0;
}
