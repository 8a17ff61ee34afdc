#pragma once

#include "obsgroup/maps/local_map_builder.h"

#include <pcl/common/common.h>
#include <pcl/common/transforms.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/registration/correspondence_estimation.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/lum.h>
#include <pcl/registration/transformation_estimation_2D.h>

#include <omp.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <stdexcept>
#include <tuple>

namespace obsgroup {
namespace detail {

/// The finite points of a cloud, moved by `pose` (composed in double).
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr movedCloud(const pcl::PointCloud<PointT>& in, const Eigen::Isometry3d& pose) {
  typename pcl::PointCloud<PointT>::Ptr out(new pcl::PointCloud<PointT>);
  out->reserve(in.size());
  for (PointT p : in.points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const Eigen::Vector3f q = (pose * Eigen::Vector3d(p.x, p.y, p.z)).template cast<float>();
    p.x = q.x();
    p.y = q.y();
    p.z = q.z();
    out->push_back(p);
  }
  return out;
}

/// True when every point of every member lies in the plane z = const: 2D
/// scans, aligned in x, y and yaw only.
template <typename PointT>
bool planar(const std::vector<Observation<PointT>>& observations, const std::vector<int>& group) {
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

/// Members of `frame` in the order of a maximum spanning tree of W grown from
/// the reference (Prim), each with its parent's index in `members` (-1 for
/// the reference and for members W does not connect).
inline std::vector<std::pair<int, int>> maximumSpanningTree(const LocalMapFrame& frame, const WeightMatrix& W) {
  const auto& members = frame.members;
  const auto local = [&members](int i) {
    const auto it = std::lower_bound(members.begin(), members.end(), i);
    return it != members.end() && *it == i ? static_cast<int>(it - members.begin()) : -1;
  };
  std::vector<bool> done(members.size(), false);
  std::vector<std::pair<int, int>> order;  // (member, parent)
  // (weight, -child, parent): the heaviest edge first, ties to the smaller child.
  std::priority_queue<std::tuple<double, int, int>> edges;
  const int root = local(frame.reference);
  edges.emplace(std::numeric_limits<double>::infinity(), -root, -1);
  while (!edges.empty()) {
    const auto [w, negative_child, parent] = edges.top();
    edges.pop();
    const int child = -negative_child;
    if (done[child]) continue;
    done[child] = true;
    order.emplace_back(child, parent);
    for (WeightMatrix::InnerIterator it(W, members[child]); it; ++it) {
      const int next = local(static_cast<int>(it.row()));
      if (next >= 0 && !done[next] && it.value() > 0.0) edges.emplace(it.value(), -next, child);
    }
  }
  for (std::size_t k = 0; k < members.size(); ++k)
    if (!done[k]) order.emplace_back(static_cast<int>(k), -1);
  return order;
}

template <typename PointT>
std::vector<Eigen::Isometry3d> posesOf(const std::vector<Observation<PointT>>& observations) {
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(observations.size());
  for (const auto& o : observations) poses.push_back(o.pose);
  return poses;
}

inline Eigen::Vector6f toPose6(const Eigen::Isometry3d& pose) {
  Eigen::Vector6f v;
  const Eigen::Affine3f a(pose.matrix().cast<float>());
  pcl::getTranslationAndEulerAngles(a, v[0], v[1], v[2], v[3], v[4], v[5]);
  return v;
}

inline Eigen::Isometry3d fromAffine(const Eigen::Affine3f& a) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const Eigen::Matrix3d R = a.linear().cast<double>();
  pose.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();  // re-orthonormalised after float
  pose.translation() = a.translation().cast<double>();
  return pose;
}

}  // namespace detail

template <typename PointT>
void LocalMapBuilder<PointT>::refineIcp(const std::vector<Observation<PointT>>& observations, const WeightMatrix& W,
                                        LocalMapFrame& frame) const {
  pcl::IterativeClosestPoint<PointT, PointT> icp;
  icp.setMaxCorrespondenceDistance(max_correspondence_distance_);
  icp.setMaximumIterations(max_iterations_);
  icp.setTransformationEpsilon(1e-10);
  icp.setEuclideanFitnessEpsilon(1e-12);
  if (detail::planar(observations, frame.members))
    icp.setTransformationEstimation(
        typename pcl::registration::TransformationEstimation2D<PointT, PointT>::Ptr(
            new pcl::registration::TransformationEstimation2D<PointT, PointT>));
  pcl::PointCloud<PointT> aligned;
  for (const auto& [child, parent] : detail::maximumSpanningTree(frame, W)) {
    if (parent < 0) continue;  // the reference, or a member W does not reach: input pose kept
    const int c = frame.members[child], p = frame.members[parent];
    // The input relative pose, hung on the parent's refined pose.
    const Eigen::Isometry3d guess =
        frame.member_poses[parent] * (observations[p].pose.inverse() * observations[c].pose);
    frame.member_poses[child] = guess;
    const auto target = detail::movedCloud(*observations[p].cloud, frame.member_poses[parent]);
    const auto source = detail::movedCloud(*observations[c].cloud, Eigen::Isometry3d::Identity());
    if (target->size() < 3 || source->size() < 3) continue;
    icp.setInputTarget(target);
    icp.setInputSource(source);
    icp.align(aligned, guess.matrix().cast<float>());
    if (icp.hasConverged()) frame.member_poses[child] = detail::fromAffine(Eigen::Affine3f(icp.getFinalTransformation()));
  }
}

template <typename PointT>
bool LocalMapBuilder<PointT>::refineLum(const std::vector<Observation<PointT>>& observations, const WeightMatrix& W,
                                        LocalMapFrame& frame) const {
  const auto& members = frame.members;
  const std::size_t m = members.size();
  if (m < 2) return true;
  // LUM keeps its first vertex fixed: the reference goes first.
  std::vector<std::size_t> order{static_cast<std::size_t>(
      std::lower_bound(members.begin(), members.end(), frame.reference) - members.begin())};
  for (std::size_t k = 0; k < m; ++k)
    if (k != order[0]) order.push_back(k);
  pcl::registration::LUM<PointT> lum;
  std::vector<int> vertex(m);
  for (std::size_t v = 0; v < m; ++v) {
    const std::size_t k = order[v];
    const auto cloud = detail::movedCloud(*observations[members[k]].cloud, Eigen::Isometry3d::Identity());
    vertex[k] = static_cast<int>(lum.addPointCloud(cloud, v == 0 ? Eigen::Vector6f::Zero().eval()
                                                                 : detail::toPose6(frame.member_poses[k])));
  }
  // Edges: the pairs of the group that overlap (W > 0).
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t a = 0; a < m; ++a)
    for (WeightMatrix::InnerIterator it(W, members[a]); it; ++it) {
      const auto b = std::lower_bound(members.begin(), members.end(), static_cast<int>(it.row()));
      if (b != members.end() && *b == it.row() && static_cast<std::size_t>(b - members.begin()) > a && it.value() > 0)
        pairs.emplace_back(a, b - members.begin());
    }
  if (pairs.empty()) return true;
  // Correspondences are re-estimated a few times only: run longer on
  // nearest-neighbour correspondences, PCL's LUM was seen to drift away by
  // metres on scans of a room that were perfectly aligned to begin with.
  constexpr int kRounds = 3;
  lum.setMaxIterations(std::max(1, max_iterations_ / kRounds));
  for (int round = 0; round < kRounds; ++round) {
    for (const auto& [a, b] : pairs) {
      pcl::registration::CorrespondenceEstimation<PointT, PointT> estimation;
      estimation.setInputSource(lum.getTransformedCloud(vertex[b]));
      estimation.setInputTarget(lum.getTransformedCloud(vertex[a]));
      pcl::CorrespondencesPtr correspondences(new pcl::Correspondences);
      estimation.determineReciprocalCorrespondences(*correspondences, max_correspondence_distance_);
      if (correspondences->size() > 3) lum.setCorrespondences(vertex[b], vertex[a], correspondences);
    }
    lum.compute();
  }
  // Accept the result only if no pose moved further than alignment can tell.
  std::vector<Eigen::Isometry3d> refined(m);
  for (std::size_t k = 0; k < m; ++k) {
    refined[k] = members[k] == frame.reference ? Eigen::Isometry3d::Identity()
                                               : detail::fromAffine(lum.getTransformation(vertex[k]));
    const Eigen::Isometry3d change = frame.member_poses[k].inverse() * refined[k];
    if (!refined[k].matrix().allFinite() || change.translation().norm() > 2 * max_correspondence_distance_ ||
        Eigen::AngleAxisd(change.linear()).angle() > 0.2)
      return false;
  }
  frame.member_poses = refined;
  return true;
}

template <typename PointT>
LocalMap<PointT> LocalMapBuilder<PointT>::build(const std::vector<Observation<PointT>>& observations,
                                                const std::vector<int>& group, const WeightMatrix& W) const {
  return buildGroup(observations, group, W, detail::posesOf(observations));
}

template <typename PointT>
LocalMap<PointT> LocalMapBuilder<PointT>::buildGroup(const std::vector<Observation<PointT>>& observations,
                                                     const std::vector<int>& group, const WeightMatrix& W,
                                                     const std::vector<Eigen::Isometry3d>& poses) const {
  if (group.empty()) throw std::invalid_argument("LocalMapBuilder: empty group");
  LocalMap<PointT> map;
  map.frame = initialFrame(group, W, poses);
  // LUM starts from the ICP tree: PCL's LUM diverged from the raw input poses
  // on drifted groups (nearest-neighbour correspondences several centimetres
  // off); from aligned poses it spreads the residual over every overlapping pair.
  if (refinement_ != Refinement::None) refineIcp(observations, W, map.frame);
  if (refinement_ == Refinement::Lum) map.fell_back = !refineLum(observations, W, map.frame);

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
  std::vector<LocalMap<PointT>> maps(partition.groups.size());
  const std::vector<Eigen::Isometry3d> poses = detail::posesOf(observations);  // once, not per group
  const int threads = threads_ > 0 ? threads_ : omp_get_max_threads();
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (std::size_t g = 0; g < partition.groups.size(); ++g)
    if (!interruptRequested(interrupt_)) maps[g] = buildGroup(observations, partition.groups[g], W, poses);
  throwIfInterrupted(interrupt_);
  return maps;
}

}  // namespace obsgroup

#define OBSGROUP_INSTANTIATE_LocalMapBuilder(T) template class obsgroup::LocalMapBuilder<T>;
