// libFuzzer target: the TUM and KITTI trajectory readers on arbitrary bytes.
#include <obsgroup/io/errors.h>
#include <obsgroup/io/pose_file.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

using namespace obsgroup::io;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const PoseFormat format = data[0] & 1 ? PoseFormat::Kitti : PoseFormat::Tum;
  const std::string_view content(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    for (const auto& pose : parsePoses(content, "fuzz.txt", format)) {
      if (!pose.matrix().allFinite()) std::abort();
      // Every pose returned is a rigid motion.
      const Eigen::Matrix3d R = pose.linear();
      if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-9) std::abort();
    }
  } catch (const InputError&) {
  }
  return 0;
}
