#include "obsgroup/partition/keyframes.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace obsgroup {

std::vector<int> selectKeyframes(const std::vector<Eigen::Isometry3d>& poses, const KeyframeOptions& options) {
  if (!(std::isfinite(options.distance) && options.distance >= 0.0))
    throw std::invalid_argument("keyframe distance must be finite and >= 0 (got " + std::to_string(options.distance) + ")");
  if (!(std::isfinite(options.angle_deg) && options.angle_deg >= 0.0))
    throw std::invalid_argument("keyframe angle must be finite and >= 0 (got " + std::to_string(options.angle_deg) + ")");
  const double angle = options.angle_deg * 3.14159265358979323846 / 180.0;
  std::vector<int> keyframe_of(poses.size());
  int last = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Isometry3d moved = poses[std::size_t(last)].inverse() * poses[i];
    const bool far = moved.translation().norm() >= options.distance;
    const bool turned = Eigen::AngleAxisd(moved.linear()).angle() >= angle;
    if (i == 0 || far || turned) last = static_cast<int>(i);
    keyframe_of[i] = last;
  }
  return keyframe_of;
}

std::vector<int> keyframesOf(const std::vector<int>& keyframe_of) {
  std::vector<int> keyframes;
  for (std::size_t i = 0; i < keyframe_of.size(); ++i)
    if (keyframe_of[i] == static_cast<int>(i)) keyframes.push_back(keyframe_of[i]);
  return keyframes;
}

Partition expandKeyframePartition(const Partition& of_keyframes, const std::vector<int>& keyframe_of) {
  const std::vector<int> keyframes = keyframesOf(keyframe_of);
  // The frames each keyframe stands for, itself first; frames follow their
  // keyframe, so each list is ascending.
  std::vector<std::vector<int>> frames_of(keyframes.size());
  std::vector<int> position(keyframe_of.size(), -1);
  for (std::size_t k = 0; k < keyframes.size(); ++k) position[std::size_t(keyframes[k])] = static_cast<int>(k);
  for (std::size_t i = 0; i < keyframe_of.size(); ++i)
    frames_of[std::size_t(position[std::size_t(keyframe_of[i])])].push_back(static_cast<int>(i));
  const auto expand = [&](const std::vector<int>& members) {
    std::vector<int> frames;
    for (int k : members) frames.insert(frames.end(), frames_of.at(std::size_t(k)).begin(), frames_of[std::size_t(k)].end());
    std::sort(frames.begin(), frames.end());
    return frames;
  };
  Partition out;
  out.warnings = of_keyframes.warnings;
  out.group_of.assign(keyframe_of.size(), -1);
  for (const auto& group : of_keyframes.groups) {
    out.groups.push_back(expand(group));
    for (int i : out.groups.back()) out.group_of[std::size_t(i)] = static_cast<int>(out.groups.size() - 1);
  }
  out.splits = of_keyframes.splits;
  for (SplitNode& node : out.splits) {
    node.members = expand(node.members);
    node.eigenvector.resize(0);
  }
  return out;
}

}  // namespace obsgroup
