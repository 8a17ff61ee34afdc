#pragma once
/// \file
/// Keyframes of a dense sequence: a depth camera at 30 Hz takes many frames
/// of the same view, and grouping only the frames that moved gives the same
/// places for a fraction of the work. Every other frame takes the place of
/// its keyframe, so each frame still has one.

#include "obsgroup/partition/recursive_partitioner.h"

#include <Eigen/Geometry>

#include <vector>

namespace obsgroup {

struct KeyframeOptions {
  double distance = 0.0;   ///< metres moved since the last keyframe that make a new one
  double angle_deg = 0.0;  ///< degrees turned since the last keyframe that make a new one
};

/// Frame 0 is a keyframe, then every frame whose pose is at least
/// `options.distance` from the last keyframe's, or turned at least
/// `options.angle_deg` from it (the angle of the relative rotation). Returns
/// each frame's keyframe: its own index for a keyframe, the last keyframe
/// before it otherwise. Throws std::invalid_argument for a negative or
/// non-finite option.
std::vector<int> selectKeyframes(const std::vector<Eigen::Isometry3d>& poses, const KeyframeOptions& options);

/// The keyframes (ascending) of a selectKeyframes() result.
std::vector<int> keyframesOf(const std::vector<int>& keyframe_of);

/// A partition of the keyframes (observation k of it is frame keyframes[k])
/// as a partition of every frame: each frame joins its keyframe's group, and
/// each split node holds the frames of its keyframes. The eigenvectors, over
/// the keyframes, are dropped.
Partition expandKeyframePartition(const Partition& of_keyframes, const std::vector<int>& keyframe_of);

}  // namespace obsgroup
