// libFuzzer target: the small files of the KITTI and Redwood layouts (a
// velodyne .bin, calib.txt's Tr line, trajectory.log) on arbitrary bytes.
// The first byte chooses the reader; the rest is the file.
#include <obsgroup/io/depth_sequence.h>
#include <obsgroup/io/errors.h>
#include <obsgroup/io/kitti_sequence.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

using namespace obsgroup::io;

namespace {

bool isRigid(const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d R = pose.linear();
  return pose.matrix().allFinite() && (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view file(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] % 3) {
      case 0: {
        const auto cloud = decodeKittiScan(file, "fuzz.bin");
        if (cloud->size() != file.size() / 16) std::abort();
        break;
      }
      case 1:
        if (!isRigid(parseKittiCalibration(file, "calib.txt"))) std::abort();
        break;
      default:
        for (const Eigen::Isometry3d& pose : parseTrajectoryLog(file, "trajectory.log"))
          if (!isRigid(pose)) std::abort();
    }
  } catch (const InputError&) {
  }
  return 0;
}
