// libFuzzer target: the PCD-folder loader, PCL's own PCD reader included,
// on arbitrary file contents. The bytes are written to a one-file folder,
// as the command would find them.
#include <obsgroup/io/errors.h>
#include <obsgroup/io/pcd_sequence.h>

#include <pcl/point_types.h>

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>

using namespace obsgroup::io;
namespace fs = std::filesystem;

namespace {

const fs::path& folder() {
  static const fs::path path = [] {
    const fs::path p = fs::temp_directory_path() / ("obsgroup_fuzz_pcd_" + std::to_string(::getpid()));
    fs::create_directories(p);
    std::atexit([] { std::error_code ec; fs::remove_all(folder(), ec); });
    return p;
  }();
  return path;
}

template <typename PointT>
void load(const std::vector<std::string>& files) {
  const auto sequence = loadPcdSequence<PointT>(files, std::nullopt);
  if (sequence.observations.size() != files.size()) std::abort();
  for (const auto& o : sequence.observations)
    if (!o.cloud || !o.pose.matrix().allFinite()) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  {
    std::ofstream out(folder() / "000000.pcd", std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const auto files = listPcdFiles(folder().string());
    switch (detectPointKind(files.front())) {
      case PointKind::XYZ: load<pcl::PointXYZ>(files); break;
      case PointKind::XYZI: load<pcl::PointXYZI>(files); break;
      case PointKind::XYZRGB: load<pcl::PointXYZRGB>(files); break;
    }
  } catch (const InputError&) {
  }
  return 0;
}
