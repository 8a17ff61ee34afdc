#pragma once
// A folder of PCD files as a sequence of observations, each posed by its
// VIEWPOINT or by a trajectory file.

#include "obsgroup/io/frame_reading.h"
#include "obsgroup/io/pose_file.h"

#include <obsgroup/cloud/observation.h>

#include <pcl/PCLPointField.h>

#include <optional>
#include <string>
#include <vector>

namespace obsgroup::io {

/// The point type a sequence is read as, chosen from its PCD fields.
enum class PointKind { XYZ, XYZI, XYZRGB };

std::string toString(PointKind kind);

/// The point type a cloud's fields map onto: XYZRGB with an `rgb` or `rgba`
/// field (FLOAT32 or UINT32), else XYZI with a FLOAT32 `intensity`, else XYZ.
/// Only fields PCL can map onto the point type count.
PointKind pointKindOfFields(const std::vector<pcl::PCLPointField>& fields);

/// Natural order of file names: runs of digits compare as numbers.
bool naturalLess(const std::string& a, const std::string& b);

/// The paths of the regular files of `folder` whose extension is
/// `extension` (".pcd", any case), in natural name order; empty when there
/// is none. Throws InputError when the folder cannot be listed.
std::vector<std::string> filesWithExtension(const std::string& folder, const std::string& extension);

/// The .pcd files of a folder in natural name order (2.pcd before 10.pcd).
/// Throws InputError if the folder does not exist or holds no PCD file.
std::vector<std::string> listPcdFiles(const std::string& folder);

/// XYZRGB when the first file has rgb/rgba, XYZI when it has intensity,
/// else XYZ. Throws InputError when its header cannot be read.
PointKind detectPointKind(const std::string& file);

template <typename PointT>
struct PcdSequence {
  std::vector<Observation<PointT>> observations;
  std::vector<std::string> labels;  ///< the file of each observation
  std::vector<std::string> warnings;
  std::size_t reduced = 0;  ///< clouds voxel-filtered as they were read
};

/// Loads every file. Poses come from `poses` when given (one per file, in
/// order), else from each file's VIEWPOINT. Throws InputError naming the PCD
/// file that cannot be parsed or is truncated, or a poses count that does
/// not match; warns about empty clouds and about VIEWPOINTs that are all the
/// identity. Files are read on every thread, each cloud reduced as
/// `reduction` says (its sensor points: width x height of the file) before
/// the next is read.
template <typename PointT>
PcdSequence<PointT> loadPcdSequence(const std::vector<std::string>& files,
                                    const std::optional<std::vector<Eigen::Isometry3d>>& poses,
                                    const std::string& poses_file = "", const FrameReading& reduction = {});

}  // namespace obsgroup::io
