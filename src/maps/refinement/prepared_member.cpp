#include "prepared_member.h"

#include <pcl/filters/voxel_grid.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <limits>

namespace obsgroup::refinement {

std::unique_ptr<PreparedMember> prepare(const MemberPoints& points, double voxel, bool planar) {
  auto member = std::make_unique<PreparedMember>();
  pcl::PointCloud<pcl::PointXYZ>::Ptr raw(new pcl::PointCloud<pcl::PointXYZ>);
  raw->reserve(points.size());
  for (const auto& p : points) raw->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  member->cloud.reset(new pcl::PointCloud<pcl::PointXYZ>);
  if (voxel > 0 && !raw->empty()) {
    pcl::VoxelGrid<pcl::PointXYZ> grid;
    grid.setLeafSize(float(voxel), float(voxel), float(voxel));
    grid.setInputCloud(raw);
    grid.filter(*member->cloud);
  } else {
    member->cloud = raw;
  }
  auto& cloud = *member->cloud;
  member->normals.assign(cloud.size(), Eigen::Vector3d::Zero());
  if (cloud.size() < 3) return member;
  const flann::Matrix<float> data(&cloud.points[0].x, cloud.size(), 3, sizeof(pcl::PointXYZ));
  member->index = std::make_unique<PreparedMember::Index>(data, flann::KDTreeSingleIndexParams(10));
  member->index->buildIndex();
  // A line (2D) or plane (3D) fitted to the nearest points; a corner or a
  // scatter gives no normal, and the point then matches nothing.
  const std::size_t k = std::min<std::size_t>(planar ? 6 : 10, cloud.size());
  const double max_spread = std::max(0.5, 8 * voxel);
  flann::KNNSimpleResultSet<float> result(k);
  std::vector<std::size_t> neighbours(k);
  std::vector<float> distances(k);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    member->nearest(cloud[i].getVector3fMap(), result);
    result.copy(neighbours.data(), distances.data(), k);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    int used = 0;
    for (std::size_t j = 0; j < k; ++j)
      if (distances[j] <= max_spread * max_spread) {
        mean += cloud[neighbours[j]].getVector3fMap().cast<double>();
        ++used;
      }
    if (used < 3) continue;
    mean /= used;
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (std::size_t j = 0; j < k; ++j)
      if (distances[j] <= max_spread * max_spread) {
        const Eigen::Vector3d d = cloud[neighbours[j]].getVector3fMap().cast<double>() - mean;
        covariance += d * d.transpose();
      }
    Eigen::Vector3d& normal = member->normals[i];
    if (planar) {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(covariance.topLeftCorner<2, 2>());
      if (eigen.eigenvalues()[0] < 0.1 * eigen.eigenvalues()[1]) normal << eigen.eigenvectors().col(0), 0;
    } else {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
      if (eigen.eigenvalues()[0] < 0.1 * eigen.eigenvalues()[1]) normal = eigen.eigenvectors().col(0);
    }
    // Towards the sensor (the frame's origin), as pcl::flipNormalTowardsViewpoint:
    // the two faces of a thin wall then point apart and do not match.
    if (normal.dot(cloud[i].getVector3fMap().cast<double>()) > 0) normal = -normal;
  }
  return member;
}

bool residual(const PreparedMember& target, const Eigen::Vector3d& x, const Eigen::Vector3d& source_normal,
              double gate, double& r, Eigen::Vector3d& normal, flann::KNNSimpleResultSet<float>& nearest) {
  if (!target.index) return false;
  target.nearest(x.cast<float>(), nearest);
  std::size_t index = 0;
  float distance = std::numeric_limits<float>::infinity();
  nearest.copy(&index, &distance, 1);
  if (!(distance <= gate * gate)) return false;
  normal = target.normals[index];
  if (normal.isZero() || (!source_normal.isZero() && normal.dot(source_normal) < 0.8)) return false;
  r = normal.dot(x - target.cloud->points[index].getVector3fMap().cast<double>());
  return true;
}


}  // namespace obsgroup::refinement
