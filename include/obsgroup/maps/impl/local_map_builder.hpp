#pragma once

#include "obsgroup/maps/local_map_builder.h"
#include "obsgroup/maps/alignment_pairs.h"

#include "obsgroup/cloud/finite_points.h"
#include "obsgroup/common/parallel_for.h"

#include <mutex>
#include <pcl/common/common.h>
#include <pcl/common/transforms.h>
#include <pcl/filters/voxel_grid.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

namespace obsgroup {
namespace detail {

/// The finite points of a cloud, moved by `pose` (composed in double).
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr movedCloud(const pcl::PointCloud<PointT>& in, const Eigen::Isometry3d& pose) {
  typename pcl::PointCloud<PointT>::Ptr out(new pcl::PointCloud<PointT>);
  pcl::transformPointCloud<PointT, double>(finitePoints(in), *out, Eigen::Affine3d(pose.matrix()));
  return out;
}

/// True when every point of every member lies in the plane z = const: 2D
/// scans, aligned in x, y and yaw only.
template <typename PointT>
bool planar(const std::vector<Observation<PointT>>& observations, const pcl::Indices& group) {
  bool first = true;
  float z = 0.0f;
  for (int i : group)
    for (const PointT& p : observations[i].cloud->points) {
      if (!std::isfinite(p.z)) continue;
      if (first) z = p.z;
      if (p.z != z) return false;
      first = false;
    }
  return true;
}

template <typename PointT>
std::vector<Eigen::Isometry3d> posesOf(const std::vector<Observation<PointT>>& observations) {
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(observations.size());
  for (const auto& o : observations) poses.push_back(o.pose);
  return poses;
}

}  // namespace detail

template <typename PointT>
void LocalMapBuilder<PointT>::refine(const std::vector<Observation<PointT>>& observations, const WeightMatrix& W,
                                     LocalMap<PointT>& map) const {
  LocalMapFrame& frame = map.frame;
  const auto& members = frame.members;
  std::vector<MemberPoints> points(members.size());
  for (std::size_t k = 0; k < members.size(); ++k)
    for (const PointT& p : finitePoints(*observations[members[k]].cloud).points) points[k].emplace_back(p.x, p.y, p.z);
  // The spanning tree's pairs first (each member with the one it overlaps
  // most on the way from the reference); Lum adds every member's strongest
  // other overlaps, so that a pose graph with loops spreads the error.
  std::vector<std::pair<int, int>> pairs;
  std::set<std::pair<int, int>> taken;
  for (const auto& [child, parent] : detail::maximumSpanningTree(frame, W))
    if (parent >= 0) {
      pairs.emplace_back(parent, child);
      taken.emplace(std::min(parent, child), std::max(parent, child));
    }
  const bool planar = detail::planar(observations, members);
  if (refinement_ == Refinement::Lum) {
    detail::addStrongestPartners(members, W, parameters_.neighbours, taken, pairs);
    if (planar && parameters_.point_neighbours > 0)
      detail::addStrongestPartners(members, detail::pointOverlap(frame, points, parameters_.point_overlap_cell, W.rows()),
                                   parameters_.point_neighbours, taken, pairs);
  }
  map.refinement = refineMemberPoses(refinement_, points, pairs, planar, parameters_, frame);
}

template <typename PointT>
LocalMap<PointT> LocalMapBuilder<PointT>::build(const std::vector<Observation<PointT>>& observations,
                                                const pcl::Indices& group, const WeightMatrix& W) const {
  return buildGroup(observations, group, W, detail::posesOf(observations));
}

template <typename PointT>
LocalMap<PointT> LocalMapBuilder<PointT>::buildGroup(const std::vector<Observation<PointT>>& observations,
                                                     const pcl::Indices& group, const WeightMatrix& W,
                                                     const std::vector<Eigen::Isometry3d>& poses) const {
  const std::string who = "LocalMapBuilder::build";
  checkWeightMatrixSize(who, W, Eigen::Index(observations.size()));
  checkMembers(who, group, Eigen::Index(observations.size()));
  for (int i : group)
    if (!observations[i].cloud)
      throw std::invalid_argument(who + ": observation " + std::to_string(i) + " has no cloud (null pointer)");
  LocalMap<PointT> map;
  map.frame = initialFrame(group, W, poses);
  map.refinement.members = static_cast<int>(group.size()) - 1;
  if (refinement_ != Refinement::None) refine(observations, W, map);

  map.cloud.reset(new PointCloud);
  for (std::size_t k = 0; k < group.size(); ++k)
    *map.cloud += *detail::movedCloud(*observations[group[k]].cloud, map.frame.member_poses[k]);
  if (voxel_leaf_ > 0.0 && !map.cloud->empty()) {
    Eigen::Vector4f lo, hi;
    pcl::getMinMax3D(*map.cloud, lo, hi);
    const Eigen::Array3d cells = ((hi - lo).template head<3>().template cast<double>() / voxel_leaf_).array().floor() + 1.0;
    // pcl::VoxelGrid silently returns its input past 2^31 voxels: say so instead.
    map.filtered = cells.prod() <= double(std::numeric_limits<std::int32_t>::max());
    if (map.filtered) {
      pcl::VoxelGrid<PointT> voxel;
      voxel.setLeafSize(float(voxel_leaf_), float(voxel_leaf_), float(voxel_leaf_));
      voxel.setInputCloud(map.cloud);
      typename PointCloud::Ptr filtered(new PointCloud);
      voxel.filter(*filtered);
      map.cloud = filtered;
    }
  }
  const Eigen::Isometry3d& reference = map.frame.pose;
  map.cloud->sensor_origin_ << reference.translation().template cast<float>(), 0.0f;
  map.cloud->sensor_orientation_ = Eigen::Quaternionf(reference.linear().template cast<float>());
  return map;
}

template <typename PointT>
std::vector<LocalMap<PointT>> LocalMapBuilder<PointT>::build(const std::vector<Observation<PointT>>& observations,
                                                             const Partition& partition, const WeightMatrix& W) const {
  checkWeightMatrixSize("LocalMapBuilder::build", W, Eigen::Index(observations.size()));
  std::vector<LocalMap<PointT>> maps(partition.groups.size());
  const std::vector<Eigen::Isometry3d> poses = detail::posesOf(observations);  // once, not per group
  std::mutex reporting;
  std::size_t done = 0;
  parallelFor(partition.groups.size(), threads_, [&](std::size_t g) {
    if (interruptRequested(interrupt_)) return;
    const std::string name = "local map " + std::to_string(g) + ": ";
    try {
      maps[g] = buildGroup(observations, partition.groups[g], W, poses);
    } catch (const Interrupted&) {
      throw;
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(name + e.what());
    } catch (const std::exception& e) {
      throw std::runtime_error(name + e.what());
    }
    if (progress_) {
      const std::lock_guard<std::mutex> lock(reporting);
      progress_(++done, partition.groups.size());
    }
  });
  throwIfInterrupted(interrupt_);
  return maps;
}

}  // namespace obsgroup

#define PCL_INSTANTIATE_LocalMapBuilder(T) template class obsgroup::LocalMapBuilder<T>;
