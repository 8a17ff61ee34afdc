// libFuzzer target: the CARMEN log reader on arbitrary bytes, with every
// laser choice and with and without the geometry options.
#include <obsgroup/io/carmen_reader.h>
#include <obsgroup/io/errors.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

using namespace obsgroup::io;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  // The first byte picks the options, the rest is the log.
  const std::uint8_t choice = data[0];
  const std::string_view content(reinterpret_cast<const char*>(data + 1), size - 1);
  CarmenOptions options;
  options.laser = static_cast<LaserSource>(choice % 4);
  if (choice & 0x10) options.field_of_view_deg = 270.0;
  if (choice & 0x20) options.max_range = 4.0;
  try {
    const CarmenLog log = parseCarmenLog(content, "fuzz.clf", options);
    if (log.scans.empty()) std::abort();  // a log without scans must be an error
    for (const LaserScan& scan : log.scans) {
      if (!scan.laser_pose.matrix().allFinite()) std::abort();
      const auto cloud = scanToCloud(scan);
      for (const auto& p : cloud->points)
        if (!std::isfinite(p.x) || !std::isfinite(p.y)) std::abort();  // no return must give no point
    }
  } catch (const InputError&) {
    // the expected outcome of a malformed log
  }
  return 0;
}
