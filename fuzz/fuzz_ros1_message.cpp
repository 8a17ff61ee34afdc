// libFuzzer target: the ROS 1 message decoder on arbitrary bytes. The first
// byte picks the type (and role); the rest is the serialised message.
#include "bag_messages.h"

#include <obsgroup/io/errors.h>

#include <cstdint>
#include <cstdlib>
#include <string>

using namespace obsgroup::io;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const std::pair<const char*, bag::Role> kinds[] = {{bag::kLaserScanType, bag::Role::Data},
                                                            {bag::kPointCloud2Type, bag::Role::Data},
                                                            {bag::kTfType, bag::Role::Tf},
                                                            {bag::kOdometryType, bag::Role::Pose},
                                                            {bag::kPoseStampedType, bag::Role::Pose}};
  const auto& [type, role] = kinds[data[0] % 5];
  bag::Messages messages;
  try {
    bag::decodeRos1Message(type, role, data + 1, size - 1, "fuzz.bag: message 1", 1, messages);
  } catch (const InputError&) {
    return 0;
  }
  for (const auto& scan : messages.scans)
    if (scan.message.ranges.size() * 4 > size) std::abort();
  for (const auto& cloud : messages.clouds) {
    const auto& c = cloud.message.cloud;
    if (std::uint64_t(c.row_step) * c.height > c.data.size() || std::uint64_t(c.width) * c.point_step > c.row_step)
      std::abort();
  }
  for (const auto& t : messages.tf)
    if (!t.message.transform.matrix().allFinite()) std::abort();
  for (const auto& p : messages.poses)
    if (!p.message.pose.matrix().allFinite()) std::abort();
  return 0;
}
