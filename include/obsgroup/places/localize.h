#pragma once
/// \file
/// "Which place am I in, and where exactly": a scan located in the places
/// of a run (PlaceMap::locate) and aligned to that place's local map with
/// PCL's ICP. Header-only: a program that includes it links PCL's
/// registration library (pcl_registration), which obsgroup itself does not.

#include "obsgroup/maps/local_map_builder.h"
#include "obsgroup/places/place_map.h"

#include <pcl/filters/filter.h>
#include <pcl/registration/icp.h>

#include <cmath>
#include <limits>
#include <optional>
#include <utility>

namespace obsgroup {

struct LocalizeOptions {
  /// A pose on no place takes the nearest place within this, metres (PlaceMap::locate).
  double tolerance = 1.0;
  /// ICP's correspondence gate, metres: about the largest pose error it corrects.
  double max_correspondence_distance = 0.5;
  int max_iterations = 50;
};

/// What localize() found.
struct Localization {
  /// The place holding the aligned pose (the initial pose's when ICP did not
  /// converge); empty when none is within the tolerance.
  std::optional<int> place;
  /// The place the initial pose is in: the local map the scan was aligned to.
  std::optional<int> initial_place;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< aligned (else the initial pose), world frame
  bool converged = false;
  /// Mean squared distance of the matched points after alignment, m^2 (NaN
  /// when not converged).
  double fitness_m2 = std::numeric_limits<double>::quiet_NaN();
};

/// Locates `cloud` (sensor frame) at `initial_pose` (world frame) in
/// `places`, then aligns it to that place's local map. `map_of(id)` gives
/// the local map of a place id and its reference's world pose (the map's
/// frame), as a pair (cloud pointer, pose); a null cloud leaves the scan
/// unaligned.
template <typename PointT, typename MapOf>
Localization localize(const PlaceMap& places, MapOf&& map_of, const pcl::PointCloud<PointT>& cloud,
                      const Eigen::Isometry3d& initial_pose, const LocalizeOptions& options = {}) {
  Localization out;
  out.pose = initial_pose;
  out.initial_place = places.locate(initial_pose.translation().template head<2>(), options.tolerance).place;
  out.place = out.initial_place;
  if (!out.initial_place) return out;
  const auto [map, map_pose] = map_of(*out.initial_place);
  if (!map || map->size() < 3) return out;
  typename pcl::PointCloud<PointT>::Ptr source(new pcl::PointCloud<PointT>);
  std::vector<int> kept;
  source->is_dense = false;
  pcl::removeNaNFromPointCloud(cloud, *source, kept);
  if (source->empty()) return out;
  pcl::IterativeClosestPoint<PointT, PointT> icp;
  icp.setInputSource(source);
  icp.setInputTarget(map);
  icp.setMaxCorrespondenceDistance(options.max_correspondence_distance);
  icp.setMaximumIterations(options.max_iterations);
  icp.setTransformationEpsilon(1e-8);
  pcl::PointCloud<PointT> moved;
  const Eigen::Isometry3d guess = map_pose.inverse() * initial_pose;  // the scan in the map's frame
  icp.align(moved, guess.matrix().cast<float>());
  if (!icp.hasConverged()) return out;
  Eigen::Isometry3d found(icp.getFinalTransformation().template cast<double>());
  found.linear() = Eigen::Quaterniond(found.rotation()).normalized().toRotationMatrix();  // ICP works in float
  out.pose = map_pose * found;
  out.converged = true;
  out.fitness_m2 = icp.getFitnessScore(options.max_correspondence_distance);
  out.place = places.locate(out.pose.translation().template head<2>(), options.tolerance).place;
  return out;
}

/// The same with the local maps of a run (LocalMapBuilder::build), map k
/// being place place_ids[k] (buildPlaceMap's ids).
template <typename PointT>
Localization localize(const PlaceMap& places, const std::vector<LocalMap<PointT>>& maps,
                      const std::vector<int>& place_ids, const pcl::PointCloud<PointT>& cloud,
                      const Eigen::Isometry3d& initial_pose, const LocalizeOptions& options = {}) {
  const auto map_of = [&](int id) -> std::pair<typename pcl::PointCloud<PointT>::ConstPtr, Eigen::Isometry3d> {
    for (std::size_t k = 0; k < place_ids.size() && k < maps.size(); ++k)
      if (place_ids[k] == id) return {maps[k].cloud, maps[k].frame.pose};
    return {nullptr, Eigen::Isometry3d::Identity()};
  };
  return localize(places, map_of, cloud, initial_pose, options);
}

}  // namespace obsgroup
