#include "obsgroup/io/frame_reading.h"

#include "obsgroup/io/errors.h"

#include <pcl/common/common.h>
#include <pcl/common/io.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <exception>
#include <cstdint>
#include <limits>
#include <vector>

namespace obsgroup::io {

namespace {

/// The voxels VoxelGrid would index for points within [lo, hi], leaf `leaf`.
double voxelCount(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, double leaf) {
  double count = 1.0;
  for (int a = 0; a < 3; ++a) count *= std::floor(double(hi[a]) / leaf) - std::floor(double(lo[a]) / leaf) + 1.0;
  return count;
}

/// Appends the voxel centroids of `points` to `out`. VoxelGrid's voxels sit on
/// multiples of the leaf in the cloud's frame, whatever the cloud's extent, so
/// the halves of a cloud cut on a voxel boundary give the voxels of the whole.
template <typename PointT>
void filterInParts(const pcl::PointCloud<PointT>& points, double leaf, pcl::PointCloud<PointT>& out) {
  if (points.empty()) return;
  Eigen::Vector4f lo, hi;
  pcl::getMinMax3D(points, lo, hi);
  if (voxelCount(lo.head<3>(), hi.head<3>(), leaf) < double(std::numeric_limits<std::int32_t>::max())) {
    pcl::VoxelGrid<PointT> grid;
    grid.setLeafSize(float(leaf), float(leaf), float(leaf));
    grid.setInputCloud(typename pcl::PointCloud<PointT>::ConstPtr(&points, [](const pcl::PointCloud<PointT>*) {}));
    pcl::PointCloud<PointT> part;
    grid.filter(part);
    out.insert(out.end(), part.begin(), part.end());
    return;
  }
  Eigen::Index axis = 0;
  (hi - lo).head<3>().maxCoeff(&axis);
  // The voxel index VoxelGrid gives a coordinate is floor(c / leaf): cut between two of them.
  const double first = std::floor(double(lo[axis]) / leaf), last = std::floor(double(hi[axis]) / leaf);
  const double cut = std::floor((first + last) / 2.0);
  pcl::PointCloud<PointT> below, above;
  for (const PointT& p : points) (std::floor(double(p.data[axis]) / leaf) <= cut ? below : above).push_back(p);
  filterInParts(below, leaf, out);
  filterInParts(above, leaf, out);
}

/// The byte offset of FLOAT32 field `name`, or -1.
long floatField(const pcl::PCLPointCloud2& cloud, const char* name) {
  for (const auto& field : cloud.fields)
    if (field.name == name && field.datatype == pcl::PCLPointField::FLOAT32 && field.count >= 1 &&
        std::size_t(field.offset) + sizeof(float) <= cloud.point_step)
      return long(field.offset);
  return -1;
}

/// filterInParts for a message's points `indices`, x, y, z at `offsets`.
void filterInParts(const pcl::PCLPointCloud2& cloud, const pcl::Indices& indices, const long offsets[3], double leaf,
                   pcl::PCLPointCloud2& out) {
  if (indices.empty()) return;
  const auto coordinate = [&](int index, int axis) {
    float value;
    std::memcpy(&value, &cloud.data[std::size_t(index) * cloud.point_step + std::size_t(offsets[axis])], sizeof value);
    return value;
  };
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (int index : indices)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], coordinate(index, a));
      hi[a] = std::max(hi[a], coordinate(index, a));
    }
  if (voxelCount(lo, hi, leaf) < double(std::numeric_limits<std::int32_t>::max())) {
    pcl::PCLPointCloud2::Ptr part(new pcl::PCLPointCloud2);
    pcl::copyPointCloud(cloud, indices, *part);
    pcl::VoxelGrid<pcl::PCLPointCloud2> grid;
    grid.setLeafSize(float(leaf), float(leaf), float(leaf));
    grid.setInputCloud(part);
    pcl::PCLPointCloud2 reduced;
    grid.filter(reduced);
    if (out.data.empty() && out.fields.empty()) {
      out = std::move(reduced);
    } else {
      out.data.insert(out.data.end(), reduced.data.begin(), reduced.data.end());
      out.width += reduced.width * reduced.height;
    }
    return;
  }
  Eigen::Index axis = 0;
  (hi - lo).maxCoeff(&axis);
  const double cut = std::floor((std::floor(double(lo[axis]) / leaf) + std::floor(double(hi[axis]) / leaf)) / 2.0);
  pcl::Indices below, above;
  for (int index : indices) (std::floor(double(coordinate(index, int(axis))) / leaf) <= cut ? below : above).push_back(index);
  filterInParts(cloud, below, offsets, leaf, out);
  filterInParts(cloud, above, offsets, leaf, out);
}

}  // namespace

bool reduceFrame(pcl::PCLPointCloud2& cloud, const FrameReading& reduction) {
  const std::size_t count = std::size_t(cloud.width) * cloud.height;
  if (count == 0 || !reduction.reduces(count)) return false;
  const long offsets[3] = {floatField(cloud, "x"), floatField(cloud, "y"), floatField(cloud, "z")};
  const std::size_t row = std::size_t(cloud.width) * cloud.point_step;
  if (offsets[0] < 0 || offsets[1] < 0 || offsets[2] < 0 || cloud.row_step < row ||
      cloud.data.size() < std::size_t(cloud.height - 1) * cloud.row_step + row)
    return false;
  if (cloud.row_step != row) {  // rows padded (a driver's alignment): packed, as the points are indexed below
    std::vector<std::uint8_t> packed(count * cloud.point_step);
    for (std::size_t r = 0; r < cloud.height; ++r)
      std::memcpy(&packed[r * row], &cloud.data[r * cloud.row_step], row);
    cloud.data.swap(packed);
    cloud.row_step = static_cast<std::uint32_t>(row);
  }
  pcl::Indices finite;
  finite.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    bool ok = true;
    for (int a = 0; a < 3; ++a) {
      float value;
      std::memcpy(&value, &cloud.data[k * cloud.point_step + std::size_t(offsets[a])], sizeof value);
      ok = ok && std::isfinite(value);
    }
    if (ok) finite.push_back(static_cast<int>(k));
  }
  pcl::PCLPointCloud2 reduced;
  filterInParts(cloud, finite, offsets, reduction.voxel_leaf, reduced);
  if (reduced.fields.empty()) {  // no finite point: an empty cloud of the same fields
    reduced.fields = cloud.fields;
    reduced.point_step = cloud.point_step;
    reduced.is_bigendian = cloud.is_bigendian;
  }
  reduced.header = cloud.header;
  reduced.height = 1;
  reduced.row_step = reduced.width * reduced.point_step;
  reduced.is_dense = true;
  cloud = std::move(reduced);
  return true;
}

std::vector<SkippedFrame> readFramesInParallel(std::size_t count, const std::function<void(std::size_t)>& read,
                                               const FrameReading& reading) {
  const std::int64_t n = static_cast<std::int64_t>(count);
  std::vector<std::exception_ptr> errors(count);
  std::vector<std::string> skipped_because(count);
  std::vector<char> skipped(count, 0);
  std::atomic<std::int64_t> first_failed{n};
  std::atomic<std::size_t> done{0};
  std::size_t reported = 0;  // the most frames reported: counts reach the critical section out of order
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t k = 0; k < n; ++k) {
    if (k > first_failed.load()) continue;
    try {
      read(std::size_t(k));
    } catch (const InputError& e) {
      if (reading.skip_bad_files) {
        skipped[std::size_t(k)] = 1;
        skipped_because[std::size_t(k)] = e.what();
      } else {
        errors[std::size_t(k)] = std::current_exception();
      }
    } catch (...) {
      errors[std::size_t(k)] = std::current_exception();
    }
    if (errors[std::size_t(k)])
      for (std::int64_t seen = first_failed.load(); k < seen && !first_failed.compare_exchange_weak(seen, k);) {
      }
    const std::size_t frames = ++done;
    if (reading.progress) {
#pragma omp critical(obsgroup_frame_progress)
      {
        reported = std::max(reported, frames);
        reading.progress(reported, count);
      }
    }
  }
  for (const auto& error : errors)
    if (error) std::rethrow_exception(error);
  std::vector<SkippedFrame> out;
  for (std::size_t k = 0; k < count; ++k)
    if (skipped[k]) out.push_back({k, std::move(skipped_because[k])});
  return out;
}

std::string skippedWarning(const std::vector<SkippedFrame>& skipped, std::size_t count) {
  if (skipped.empty()) return "";
  if (skipped.size() == count)
    throw InputError("every one of the " + std::to_string(count) + " files failed to read; the first: " +
                     skipped.front().message);
  std::string text = "--skip-bad-files: left out " + std::to_string(skipped.size()) + " of " + std::to_string(count) +
                     " files that could not be read: ";
  const std::size_t named = std::min<std::size_t>(skipped.size(), 3);
  for (std::size_t k = 0; k < named; ++k) text += (k ? "; " : "") + skipped[k].message;
  if (skipped.size() > named) text += "; and " + std::to_string(skipped.size() - named) + " more";
  return text;
}

template <typename PointT>
bool reduceFrame(pcl::PointCloud<PointT>& cloud, std::size_t sensor_points, const FrameReading& reduction) {
  if (!reduction.reduces(sensor_points)) return false;
  pcl::PointCloud<PointT> finite;
  finite.reserve(cloud.size());
  for (const PointT& p : cloud)
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) finite.push_back(p);
  pcl::PointCloud<PointT> reduced;
  filterInParts(finite, reduction.voxel_leaf, reduced);
  const Eigen::Vector4f origin = cloud.sensor_origin_;
  const Eigen::Quaternionf orientation = cloud.sensor_orientation_;
  const auto header = cloud.header;
  cloud.swap(reduced);
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
  cloud.sensor_origin_ = origin;
  cloud.sensor_orientation_ = orientation;
  cloud.header = header;
  return true;
}

template bool reduceFrame(pcl::PointCloud<pcl::PointXYZ>&, std::size_t, const FrameReading&);
template bool reduceFrame(pcl::PointCloud<pcl::PointXYZI>&, std::size_t, const FrameReading&);
template bool reduceFrame(pcl::PointCloud<pcl::PointXYZRGB>&, std::size_t, const FrameReading&);

}  // namespace obsgroup::io
