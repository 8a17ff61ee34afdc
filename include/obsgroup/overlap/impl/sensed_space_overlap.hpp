#pragma once

#include "obsgroup/overlap/sensed_space_overlap.h"
#include "obsgroup/overlap/shared_grid_matcher.h"
#include "obsgroup/common/parallel_for.h"

#include "obsgroup/cloud/finite_points.h"

#include <pcl/common/common.h>
#include <pcl/common/transforms.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/search/kdtree.h>

#include <omp.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>

namespace obsgroup {

template <typename PointT>
std::vector<Eigen::Vector3f> SensedSpaceOverlap<PointT>::observationToWorld(
    const Observation<PointT>& observation, const Eigen::Vector3d& origin) const {
  if (!observation.cloud) throw std::invalid_argument("observation has no cloud (null pointer)");
  if (!observation.pose.matrix().allFinite()) throw std::invalid_argument("observation pose is not finite");

  const PointCloud finite = finitePoints(*observation.cloud);

  PointCloud filtered;
  const PointCloud* used = &finite;
  if (voxel_leaf_ > 0.0 && !finite.empty()) {
    // pcl::VoxelGrid silently returns its input when the voxel count would
    // overflow its 32-bit indices; refuse instead of matching unfiltered data.
    Eigen::Vector4f min_pt, max_pt;
    pcl::getMinMax3D(finite, min_pt, max_pt);
    const Eigen::Array3d cells =
        ((max_pt - min_pt).head<3>().cast<double>() / voxel_leaf_).array().floor() + 1.0;
    if (cells.prod() > double(std::numeric_limits<std::int32_t>::max()))
      throw std::invalid_argument("voxel leaf " + std::to_string(voxel_leaf_) +
                                  " m is too small for a cloud of extent " +
                                  std::to_string((max_pt - min_pt).head<3>().maxCoeff()) + " m");
    pcl::VoxelGrid<PointT> voxel;
    voxel.setLeafSize(float(voxel_leaf_), float(voxel_leaf_), float(voxel_leaf_));
    voxel.setInputCloud(typename PointCloud::ConstPtr(&finite, [](const PointCloud*) {}));
    voxel.filter(filtered);
    used = &filtered;
  }

  // The pose is applied in double and the result re-centred before rounding
  // to float (see WorldPoints).
  Eigen::Affine3d to_world(observation.pose.matrix());
  to_world.translation() -= origin;
  PointCloud moved;
  pcl::transformPointCloud<PointT, double>(*used, moved, to_world, false);
  std::vector<Eigen::Vector3f> out;
  out.reserve(moved.size());
  for (const PointT& p : moved.points) out.emplace_back(p.x, p.y, p.z);
  return out;
}

template <typename PointT>
WorldPoints SensedSpaceOverlap<PointT>::toWorld(const std::vector<Observation<PointT>>& observations) const {
  if (!(voxel_leaf_ >= 0.0) || !std::isfinite(voxel_leaf_))
    throw std::invalid_argument("voxel leaf size must be finite and >= 0");
  const int n = static_cast<int>(observations.size());
  WorldPoints world;
  world.origin = worldOrigin(observations);

  // Block by block, so that the points are never held twice (every
  // observation's own list, then the whole). Without a voxel filter only
  // non-finite points drop out: the clouds' sizes bound the total, reserved
  // at once (pages never written are never resident), so the list does not
  // move as it grows.
  if (voxel_leaf_ == 0.0) {
    std::size_t bound = 0;
    for (const auto& o : observations) bound += o.cloud ? o.cloud->size() : 0;
    world.points.reserve(bound);
  }
  const int threads = threadCount(threads_);
  constexpr int kBlock = 4096;
  std::vector<std::vector<Eigen::Vector3f>> block;
  for (int first = 0; first < n; first += kBlock) {
    block.assign(std::size_t(std::min(kBlock, n - first)), {});
    parallelFor(block.size(), threads, 4, [&](std::size_t k) {
      const int i = first + int(k);
      try {
        block[k] = observationToWorld(observations[i], world.origin);
      } catch (const std::exception& e) {
        throw InvalidObservation(i, e.what());
      }
    });
    world.appendAll(block, threads);
  }
  return world;
}

namespace detail {

/// Column j of the PCL-search back-end: for each candidate i, the number of
/// i's points with a point of j within delta. The search runs in float, so it
/// is asked a slightly larger radius and the match decided by the predicate
/// shared with the grid back-end.
template <typename PointT>
std::vector<MatchCount> countColumnPclSearch(pcl::search::Search<PointT>& search, const WorldPoints& world, int j,
                                             const std::vector<int>& candidates, double delta,
                                             std::uint64_t& tests) {
  typename pcl::PointCloud<PointT>::Ptr target(new pcl::PointCloud<PointT>);
  target->resize(world.count(j));
  for (std::size_t k = 0; k < world.count(j); ++k) {
    const Eigen::Vector3f& q = world.begin(j)[k];
    (*target)[k].x = q.x();
    (*target)[k].y = q.y();
    (*target)[k].z = q.z();
  }
  search.setInputCloud(target);
  const MatchDistance within(delta);
  const double radius = delta * (1.0 + 1e-5);
  pcl::Indices indices;
  std::vector<float> sq_distances;
  std::vector<MatchCount> column;  // (i, count): MatchCount::j holds i here
  for (int i : candidates) {
    std::uint32_t count = 0;
    PointT query;
    for (const Eigen::Vector3f* p = world.begin(i); p != world.end(i); ++p) {
      ++tests;
      query.x = p->x();
      query.y = p->y();
      query.z = p->z();
      // The nearest neighbour decides, unless float rounding put it just
      // outside delta: then every neighbour in the radius is checked.
      if (search.radiusSearch(query, radius, indices, sq_distances, 1) == 0) continue;
      bool match = within(*p, world.begin(j)[indices[0]]);
      if (!match) {
        search.radiusSearch(query, radius, indices, sq_distances, 0);
        for (const auto k : indices) match = match || within(*p, world.begin(j)[k]);
      }
      count += match;
    }
    if (count > 0) column.push_back({i, count});
  }
  return column;
}

}  // namespace detail

template <typename PointT>
MatchCounts SensedSpaceOverlap<PointT>::countMatchesPclSearch(const WorldPoints& world) const {
  const int n = world.size();
  const auto candidates = overlappingBoxes(world, delta_);
  std::vector<std::vector<MatchCount>> columns(n);
  std::vector<std::uint64_t> column_tests(n, 0);
  std::atomic<std::size_t> done{0};
  // A user's search object is shared, so it runs on one thread; otherwise
  // each thread owns a kd-tree. The search object and the progress callback
  // are the user's code: parallelFor hands their exceptions to the caller.
  const int threads = search_ ? 1 : threadCount(threads_);
  const std::thread::id caller = std::this_thread::get_id();  // progress on the calling thread
  parallelForWithScratch(
      std::size_t(n), threads, 4,
      [this] { return search_ ? search_ : SearchMethodPtr(new pcl::search::KdTree<PointT>(false)); },
      [&](std::size_t j, SearchMethodPtr& search) {
        throwIfInterrupted(interrupt_);
        if (!candidates[j].empty())
          columns[j] = detail::countColumnPclSearch(*search, world, int(j), candidates[j], delta_, column_tests[j]);
        const std::size_t now = ++done;
        if (progress_ && std::this_thread::get_id() == caller) progress_(now, n);
      });
  std::uint64_t pairs = 0, tests = 0;
  for (int j = 0; j < n; ++j) {
    pairs += candidates[j].size();
    tests += column_tests[j];
  }
  throwIfInterrupted(interrupt_);
  if (progress_) progress_(n, n);

  MatchCounts out;
  out.rows.resize(n);
  for (int j = 0; j < n; ++j)
    for (const MatchCount& m : columns[j]) out.rows[m.j].push_back({j, m.count});
  out.pairs_evaluated = pairs;
  out.point_tests = tests;
  return out;
}

template <typename PointT>
ObservationRegions SensedSpaceOverlap<PointT>::computeRegions(const std::vector<Observation<PointT>>& observations,
                                                              const WorldPoints& world) const {
  // The beams start at each observation's pose, re-centred like its points.
  std::vector<Eigen::Vector3d> origins(observations.size());
  for (std::size_t i = 0; i < observations.size(); ++i) origins[i] = observations[i].pose.translation() - world.origin;
  return obsgroup::computeRegions(model_, world, origins, region_, threads_, interrupt_);
}

template <typename PointT>
OverlapResult SensedSpaceOverlap<PointT>::compute(const std::vector<Observation<PointT>>& observations) const {
  if (!(delta_ > 0.0) || !std::isfinite(delta_))
    throw std::invalid_argument("match distance delta must be finite and > 0");
  return compute(observations, toWorld(observations));
}

template <typename PointT>
OverlapResult SensedSpaceOverlap<PointT>::compute(const std::vector<Observation<PointT>>& observations,
                                                  const WorldPoints& world, ObservationRegions* regions) const {
  if (!(delta_ > 0.0) || !std::isfinite(delta_))
    throw std::invalid_argument("match distance delta must be finite and > 0");
  if (world.size() != static_cast<int>(observations.size()))
    throw std::invalid_argument("world points of " + std::to_string(world.size()) + " observations for " +
                                std::to_string(observations.size()));
  if (model_ != SensedSpaceModel::Points) {
    if (progress_) progress_(0, observations.size());
    std::vector<Eigen::Vector3d> origins(observations.size());
    for (std::size_t i = 0; i < observations.size(); ++i) origins[i] = observations[i].pose.translation() - world.origin;
    OverlapResult result;
    if (regions) {
      *regions = obsgroup::computeRegions(model_, world, origins, region_, threads_, interrupt_);
      result = regionOverlap(*regions, threads_, interrupt_);
    } else {
      result = computeRegionOverlap(model_, world, origins, region_, threads_, interrupt_);
    }
    result.region_cells = std::move(result.points_per_observation);
    result.points_per_observation.resize(observations.size());
    for (int i = 0; i < world.size(); ++i) result.points_per_observation[i] = world.count(i);
    if (progress_) progress_(observations.size(), observations.size());
    return result;
  }
  if (regions) *regions = ObservationRegions{};  // the points model has none
  const MatchCounts counts = neighbour_search_ == NeighbourSearch::SharedGrid
                                 ? countMatchesSharedGrid(world, delta_, threads_, progress_, interrupt_)
                                 : countMatchesPclSearch(world);
  return assembleOverlap(counts, world);
}

}  // namespace obsgroup

#define PCL_INSTANTIATE_SensedSpaceOverlap(T) template class obsgroup::SensedSpaceOverlap<T>;
