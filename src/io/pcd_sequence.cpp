#include <obsgroup/io/pcd_sequence.h>

#include <obsgroup/io/errors.h>
#include "pcd_header_check.h"

#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace obsgroup::io {

std::string toString(PointKind kind) {
  switch (kind) {
    case PointKind::XYZ: return "PointXYZ";
    case PointKind::XYZI: return "PointXYZI";
    case PointKind::XYZRGB: return "PointXYZRGB";
  }
  return "?";
}

namespace {

/// Runs a PCL reader call: its error status and whatever it throws on a
/// malformed file (std::out_of_range from readHeader, for one) become an
/// InputError naming the file.
template <typename Call>
void pclCall(const std::string& file, Call&& call, const std::string& message) {
  int status = -1;
  try {
    status = call();
  } catch (const std::exception& e) {
    throw InputError(file + ": " + message + " (PCL: " + e.what() + ")");
  }
  if (status < 0) throw InputError(file + ": " + message);
}

/// x, y and z must be single 4-byte floats: PCL silently skips a field of
/// another type (doubles would load as points all at 0, a wrong map).
void checkCoordinateFields(const pcl::PCLPointCloud2& header, const std::string& file) {
  for (const char* name : {"x", "y", "z"}) {
    const auto field = std::find_if(header.fields.begin(), header.fields.end(),
                                    [name](const pcl::PCLPointField& f) { return f.name == name; });
    if (field == header.fields.end()) throw InputError(file + ": field '" + name + "' is missing from FIELDS");
    if (field->datatype != pcl::PCLPointField::FLOAT32 || field->count != 1)
      throw InputError(file + ": field '" + name + "' is not one 4-byte float (TYPE F, SIZE 4, COUNT 1); " +
                       "obsgroup reads x y z as PCL's PointXYZ does");
  }
}

/// What PCL read must hold the points its header declares, each field inside
/// a point: pcl::fromPCLPointCloud2 trusts both and copies out of bounds
/// otherwise. The header check should make this unreachable; it is the
/// last guard should PCL parse a file differently from it.
void checkBlobSize(const pcl::PCLPointCloud2& blob, const std::string& file) {
  const std::size_t points = std::size_t(blob.width) * blob.height;
  if (blob.point_step == 0 ? points > 0 : blob.data.size() / blob.point_step < points)
    throw InputError(file + ": PCL read " + std::to_string(blob.data.size()) + " bytes for " + std::to_string(points) +
                     " points of " + std::to_string(blob.point_step) + " bytes: malformed or truncated");
  for (const auto& field : blob.fields)
    if (std::size_t(field.offset) + std::size_t(pcl::getFieldSize(field.datatype)) * field.count > blob.point_step)
      throw InputError(file + ": field '" + field.name + "' lies outside the point's " +
                       std::to_string(blob.point_step) + " bytes: malformed header");
}

bool isIdentity(const Eigen::Isometry3d& pose) {
  return (pose.matrix() - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff() < 1e-9;
}

}  // namespace

bool naturalLess(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t ei = i, ej = j;
      while (ei < a.size() && std::isdigit(static_cast<unsigned char>(a[ei]))) ++ei;
      while (ej < b.size() && std::isdigit(static_cast<unsigned char>(b[ej]))) ++ej;
      const std::string da = a.substr(i, ei - i), db = b.substr(j, ej - j);
      const std::string ta = da.substr(std::min(da.find_first_not_of('0'), da.size()));
      const std::string tb = db.substr(std::min(db.find_first_not_of('0'), db.size()));
      if (ta.size() != tb.size()) return ta.size() < tb.size();
      if (ta != tb) return ta < tb;
      i = ei;
      j = ej;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j || (a.size() - i == b.size() - j && a < b);
}

std::vector<std::string> filesWithExtension(const std::string& folder, const std::string& extension) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext == extension && entry.is_regular_file()) names.push_back(entry.path().filename().string());
  }
  if (ec) throw InputError(folder + ": cannot list the folder: " + ec.message());
  std::sort(names.begin(), names.end(), naturalLess);
  std::vector<std::string> files;
  for (const auto& name : names) files.push_back((fs::path(folder) / name).string());
  return files;
}

std::vector<std::string> listPcdFiles(const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw InputError(folder + ": not a folder");
  std::vector<std::string> files = filesWithExtension(folder, ".pcd");
  if (files.empty()) {
    const fs::path inner = fs::path(folder) / "pcd";
    throw InputError(folder + ": the folder holds no .pcd file" +
                     (fs::is_directory(inner, ec) ? " (did you mean " + inner.string() + "?)" : std::string()));
  }
  return files;
}

PointKind detectPointKind(const std::string& file) {
  checkPcdFile(file);
  pcl::PCDReader reader;
  pcl::PCLPointCloud2 header;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0, type = 0;
  unsigned int offset = 0;
  pclCall(file, [&] { return reader.readHeader(file, header, origin, orientation, version, type, offset); },
          "cannot parse the PCD header");
  checkCoordinateFields(header, file);
  return pointKindOfFields(header.fields);
}

PointKind pointKindOfFields(const std::vector<pcl::PCLPointField>& fields) {
  bool intensity = false, rgb = false;
  for (const auto& field : fields) {
    // Only fields PCL can map onto the point type: anything else is left out.
    intensity = intensity || (field.name == "intensity" && field.datatype == pcl::PCLPointField::FLOAT32 &&
                              field.count == 1);
    rgb = rgb || ((field.name == "rgb" || field.name == "rgba") && field.count == 1 &&
                  (field.datatype == pcl::PCLPointField::FLOAT32 || field.datatype == pcl::PCLPointField::UINT32));
  }
  return rgb ? PointKind::XYZRGB : (intensity ? PointKind::XYZI : PointKind::XYZ);
}

template <typename PointT>
PcdSequence<PointT> loadPcdSequence(const std::vector<std::string>& files,
                                    const std::optional<std::vector<Eigen::Isometry3d>>& poses,
                                    const std::string& poses_file, const FrameReading& reduction) {
  if (poses && poses->size() != files.size())
    throw InputError(poses_file + ": " + std::to_string(poses->size()) + " poses for " +
                     std::to_string(files.size()) + " PCD files (one pose per file, in name order)");
  PcdSequence<PointT> out;
  out.observations.resize(files.size());
  std::vector<std::string> warnings(files.size());
  std::vector<char> reduced(files.size(), 0), identity(files.size(), 0);
  const auto read = [&](std::size_t k) {
    pcl::PCDReader reader;
    typename pcl::PointCloud<PointT>::Ptr cloud(new pcl::PointCloud<PointT>);
    checkPcdFile(files[k]);
    std::size_t sensor_points = 0;
    {
      pcl::PCLPointCloud2 blob;  // the file's bytes, freed before the next file
      int version = 0;
      pclCall(files[k], [&] { return reader.read(files[k], blob, cloud->sensor_origin_, cloud->sensor_orientation_, version); },
              "cannot parse this PCD file (malformed header or truncated data)");
      checkCoordinateFields(blob, files[k]);  // every file, not only the first
      checkBlobSize(blob, files[k]);
      sensor_points = std::size_t(blob.width) * blob.height;
      // pcl::fromPCLPointCloud2 indexes point 0 of an empty cloud (PCL 1.13):
      // what pcl::PCDReader::read<PointT> does, minus that.
      if (sensor_points > 0) {
        const Eigen::Vector4f origin = cloud->sensor_origin_;
        const Eigen::Quaternionf orientation = cloud->sensor_orientation_;
        pcl::fromPCLPointCloud2(blob, *cloud);
        cloud->sensor_origin_ = origin;
        cloud->sensor_orientation_ = orientation;
      }
    }
    if (cloud->empty()) warnings[k] = files[k] + ": the cloud has no point; kept as an observation (a group of its own)";
    reduced[k] = reduceFrame(*cloud, sensor_points, reduction);
    const Eigen::Isometry3d viewpoint = poseFromSensorOrigin(*cloud);
    identity[k] = isIdentity(viewpoint);
    out.observations[k] = {cloud, poses ? (*poses)[k] : viewpoint};
  };
  const std::vector<SkippedFrame> skipped = readFramesInParallel(files.size(), read, reduction);
  const std::string skipped_warning = skippedWarning(skipped, files.size());
  if (!skipped_warning.empty()) out.warnings.push_back(skipped_warning);
  std::size_t identity_viewpoints = 0;
  for (std::size_t k = 0; k < files.size(); ++k) {
    if (!warnings[k].empty()) out.warnings.push_back(std::move(warnings[k]));
    out.reduced += reduced[k];
    identity_viewpoints += identity[k];
  }
  out.labels = files;
  eraseSkipped(out.observations, skipped);
  eraseSkipped(out.labels, skipped);
  if (!poses && out.observations.size() > 1 && identity_viewpoints == out.observations.size())
    out.warnings.push_back("every PCD VIEWPOINT is absent or the identity and no --poses was given: all "
                           "observations are at the origin, which is almost never what was meant");
  return out;
}

template PcdSequence<pcl::PointXYZ> loadPcdSequence(const std::vector<std::string>&,
                                                    const std::optional<std::vector<Eigen::Isometry3d>>&,
                                                    const std::string&, const FrameReading&);
template PcdSequence<pcl::PointXYZI> loadPcdSequence(const std::vector<std::string>&,
                                                     const std::optional<std::vector<Eigen::Isometry3d>>&,
                                                     const std::string&, const FrameReading&);
template PcdSequence<pcl::PointXYZRGB> loadPcdSequence(const std::vector<std::string>&,
                                                       const std::optional<std::vector<Eigen::Isometry3d>>&,
                                                       const std::string&, const FrameReading&);

}  // namespace obsgroup::io
