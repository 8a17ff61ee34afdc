#include <obsgroup/io/depth_sequence.h>

#include <obsgroup/io/errors.h>
#include <obsgroup/io/input_file.h>
#include <obsgroup/io/pcd_sequence.h>
#include "text_fields.h"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace obsgroup::io {

namespace fs = std::filesystem;

double defaultDepthScale(DepthLayout layout) { return layout == DepthLayout::TumRgbd ? 5000.0 : 1000.0; }

PinholeIntrinsics parseIntrinsics(const std::string& text) {
  std::vector<double> v;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string field = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const std::optional<double> value = toDouble(field);
    if (!value || !std::isfinite(*value))
      throw UsageError("--intrinsics: '" + field + "' is not a finite number (expected fx,fy,cx,cy)");
    v.push_back(*value);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (v.size() != 4) throw UsageError("--intrinsics: " + std::to_string(v.size()) + " values, expected 4: fx,fy,cx,cy");
  if (!(v[0] > 0 && v[1] > 0)) throw UsageError("--intrinsics: fx and fy must be > 0 (got " + text + ")");
  return {v[0], v[1], v[2], v[3]};
}

// ---------------------------------------------------------------------------
// PNG through libpng. Its errors longjmp: the decoding function holds no C++
// object whose destructor a jump would skip (the image is the caller's).

namespace {

struct PngSource {
  const unsigned char* data;
  std::size_t size;
  std::size_t position;
  char error[256];
};

extern "C" void pngRead(png_structp png, png_bytep out, png_size_t length) {
  auto* source = static_cast<PngSource*>(png_get_io_ptr(png));
  if (length > source->size - source->position) png_error(png, "the data end before the image does (truncated)");
  std::memcpy(out, source->data + source->position, length);
  source->position += length;
}

extern "C" void pngError(png_structp png, png_const_charp message) {
  auto* source = static_cast<PngSource*>(png_get_error_ptr(png));
  std::snprintf(source->error, sizeof source->error, "%s", message);
  png_longjmp(png, 1);
}

extern "C" void pngWarning(png_structp, png_const_charp) {}

constexpr png_uint_32 kMaxSide = 1u << 14;          // 16384 pixels
constexpr std::size_t kMaxPixels = std::size_t(1) << 26;  // 64 Mpixel

/// 0 when decoded; else the error is in source.error. `depth` and `colour`
/// receive the header's, for the caller's message.
int decodeInto(PngSource& source, DepthImage& image, int& depth, int& colour) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &source, pngError, pngWarning);
  if (!png) {
    std::snprintf(source.error, sizeof source.error, "libpng could not start");
    return 1;
  }
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    std::snprintf(source.error, sizeof source.error, "libpng could not start");
    return 1;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return 1;
  }
  png_set_user_limits(png, kMaxSide, kMaxSide);
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
  png_set_crc_action(png, PNG_CRC_QUIET_USE, PNG_CRC_QUIET_USE);  // let the fuzzer past the checksums
#endif
  png_set_read_fn(png, &source, pngRead);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info), height = png_get_image_height(png, info);
  depth = png_get_bit_depth(png, info);
  colour = png_get_color_type(png, info);
  if (depth != 16 || colour != PNG_COLOR_TYPE_GRAY) {
    std::snprintf(source.error, sizeof source.error, "not a 16-bit grey image");
    png_destroy_read_struct(&png, &info, nullptr);
    return 2;
  }
  // Deflate packs at most about 1032 bytes into one: more pixels than the
  // data can hold is a corrupt header, refused before allocating them.
  if (std::size_t(width) * height > kMaxPixels || std::size_t(width) * height * 2 > source.size * 1100 + 4096) {
    std::snprintf(source.error, sizeof source.error, "%ux%u pixels: more than obsgroup reads or than the file can hold", unsigned(width),
                  unsigned(height));
    png_destroy_read_struct(&png, &info, nullptr);
    return 1;
  }
  const std::uint16_t one = 1;
  unsigned char first_byte;
  std::memcpy(&first_byte, &one, 1);
  if (first_byte == 1) png_set_swap(png);  // PNG stores 16-bit samples big-endian
  const int passes = png_set_interlace_handling(png);
  png_read_update_info(png, info);
  image.width = int(width);
  image.height = int(height);
  image.values.assign(std::size_t(width) * height, 0);
  for (int pass = 0; pass < passes; ++pass)
    for (png_uint_32 y = 0; y < height; ++y)
      png_read_row(png, reinterpret_cast<png_bytep>(image.values.data() + std::size_t(y) * width), nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return 0;
}

std::string colourName(int colour) {
  switch (colour) {
    case PNG_COLOR_TYPE_GRAY: return "grey";
    case PNG_COLOR_TYPE_GRAY_ALPHA: return "grey + alpha";
    case PNG_COLOR_TYPE_RGB: return "RGB";
    case PNG_COLOR_TYPE_RGB_ALPHA: return "RGBA";
    case PNG_COLOR_TYPE_PALETTE: return "palette";
  }
  return "colour type " + std::to_string(colour);
}

}  // namespace

DepthImage decodeDepthPng(std::string_view bytes, const std::string& name) {
  if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0)
    throw InputError(name + ": not a PNG file (no PNG signature)");
  PngSource source{reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), 0, {}};
  DepthImage image;
  int depth = 0, colour = 0;
  const int status = decodeInto(source, image, depth, colour);
  if (status == 2)
    throw InputError(name + ": field 'IHDR': a " + std::to_string(depth) + "-bit " + colourName(colour) +
                     " PNG; a depth image is 16-bit grey (one channel, 16 bits)");
  if (status != 0) throw InputError(name + ": cannot decode the PNG: " + source.error);
  return image;
}

DepthImage readDepthPng(const std::string& path) { return decodeDepthPng(readInputBytes(path, "depth image"), path); }

pcl::PointCloud<pcl::PointXYZ>::Ptr backProject(const DepthImage& image, const PinholeIntrinsics& k,
                                                double depth_scale, std::optional<double> max_depth, int stride) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  const int step = std::max(stride, 1);
  for (int v = 0; v < image.height; v += step)
    for (int u = 0; u < image.width; u += step) {
      const std::uint16_t raw = image.values[std::size_t(v) * image.width + u];
      if (raw == 0) continue;  // no return
      const double d = raw / depth_scale;
      if (max_depth && d > *max_depth) continue;
      cloud->push_back(pcl::PointXYZ(float((u - k.cx) * d / k.fx), float((v - k.cy) * d / k.fy), float(d)));
    }
  return cloud;
}

std::optional<DepthLayout> detectDepthLayout(const std::string& folder) {
  std::error_code ec;
  const fs::path dir(folder);
  if (!fs::is_directory(dir / "depth", ec)) return std::nullopt;
  if (fs::is_regular_file(dir / "depth.txt", ec)) return DepthLayout::TumRgbd;
  if (fs::is_regular_file(dir / "trajectory.log", ec)) return DepthLayout::Redwood;
  return std::nullopt;
}

std::vector<Eigen::Isometry3d> parseTrajectoryLog(std::string_view content, const std::string& path) {
  if (isGzip(content)) return parseTrajectoryLog(gunzip(content, path), path);
  content = withoutByteOrderMark(content);
  // The non-empty lines with their numbers.
  std::vector<std::pair<std::size_t, std::vector<std::string_view>>> lines;
  for (TextLines text(content); text.nextData();) lines.emplace_back(text.number(), text.fields());
  std::vector<Eigen::Isometry3d> poses;
  for (std::size_t k = 0; k < lines.size(); k += 5) {
    const std::size_t frame = k / 5;
    const auto& [header_line, header] = lines[k];
    if (header.size() != 3)
      throw inputError(path, header_line,
                       "frame " + std::to_string(frame) + ": a block starts with a line of 3 numbers (i i i+1), got " +
                           std::to_string(header.size()) + " values");
    for (std::size_t f = 0; f < 3; ++f)
      parseCount(header[f], {path, header_line}, f == 2 ? "frames" : "frame", 1L << 40);
    if (k + 5 > lines.size())
      throw inputError(path, header_line,
                       "frame " + std::to_string(frame) + ": the block has " + std::to_string(lines.size() - k - 1) +
                           " matrix rows, expected 4 (truncated?)");
    Eigen::Matrix4d m;
    for (int r = 0; r < 4; ++r) {
      const auto& [row_line, row] = lines[k + 1 + r];
      const LineRef where{path, row_line};
      if (row.size() != 4)
        throw inputError(path, row_line,
                         "frame " + std::to_string(frame) + ": matrix row " + std::to_string(r + 1) + " has " +
                             std::to_string(row.size()) + " values, expected 4");
      for (int c = 0; c < 4; ++c) m(r, c) = parseFinite(row[c], where, "m" + std::to_string(r + 1) + std::to_string(c + 1));
    }
    const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
    if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-6)
      throw inputError(path, lines[k + 4].first,
                       "frame " + std::to_string(frame) + ": the last matrix row is not 0 0 0 1");
    if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-2 || R.determinant() < 0)
      throw inputError(path, lines[k + 1].first,
                       "frame " + std::to_string(frame) + ": the 3x3 part is not a rotation matrix");
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
    pose.translation() = m.topRightCorner<3, 1>();
    poses.push_back(pose);
  }
  if (poses.empty()) throw InputError(path + ": the trajectory holds no pose");
  return poses;
}

namespace {

/// A frame of depth.txt: its timestamp, the PNG and the line naming it.
struct DepthFrame {
  double stamp;
  std::string file;
  std::size_t line;
};

std::vector<DepthFrame> readDepthList(const fs::path& folder) {
  const std::string list = (folder / "depth.txt").string();
  const std::string bytes = readInputBytes(list, "depth list");
  const std::string_view content = withoutByteOrderMark(bytes);
  std::vector<DepthFrame> frames;
  for (TextLines lines(content); lines.nextData();) {
    const auto& fields = lines.fields();
    const std::size_t number = lines.number();
    if (fields.size() != 2)
      throw inputError(list, number,
                       "a line has " + std::to_string(fields.size()) + " values, expected 2 (timestamp filename)");
    const double stamp = parseFinite(fields[0], {list, number}, "timestamp");
    const fs::path file = folder / std::string(fields[1]);
    std::error_code ec;
    if (!fs::is_regular_file(file, ec))
      throw inputError(list, number, "field 'filename': " + file.string() + ": no such file");
    frames.push_back({stamp, file.string(), number});
  }
  if (frames.empty()) throw InputError(list + ": lists no depth image");
  return frames;
}

std::vector<std::string> listPngFiles(const fs::path& folder) {
  std::vector<std::string> files = filesWithExtension(folder.string(), ".png");
  if (files.empty()) throw InputError(folder.string() + ": the folder holds no .png file");
  return files;
}

/// Turns the world so that `up` is z, and says so when that is not the identity.
void putUpOnZ(std::vector<Eigen::Isometry3d>& optical_poses, UpAxis up, bool chosen, const std::string& trajectory,
              DepthSequence& out) {
  out.up = up;
  if (up == UpAxis::PlusZ) return;
  const Eigen::Matrix3d turn = upToZ(up);
  for (auto& pose : optical_poses) pose.prerotate(turn);
  out.warnings.push_back(trajectory + ": its world has " + toString(up) + " up (" +
                         (chosen ? std::string("--up") : "from the cameras' image axes; --up z keeps it as it is") +
                         "): turned to put it on z, as obsgroup's height band and pictures from above assume");
}

/// One frame in the camera's body frame, reduced as `options` say; `warning`
/// says when it has no point.
Observation<pcl::PointXYZ> readFrame(const std::string& file, const Eigen::Isometry3d& optical_pose,
                                     const DepthOptions& options, double depth_scale, bool& reduced,
                                     std::string& warning) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud;
  std::size_t pixels = 0;
  {
    const DepthImage image = readDepthPng(file);  // freed before the next frame is read
    const std::size_t stride = std::size_t(std::max(1, options.stride));
    pixels = ((std::size_t(image.width) + stride - 1) / stride) * ((std::size_t(image.height) + stride - 1) / stride);
    cloud = backProject(image, options.intrinsics, depth_scale, options.max_depth, options.stride);
  }
  if (cloud->empty()) warning = file + ": the depth image has no valid pixel; kept as an observation (a group of its own)";
  // Into the camera's body frame, where the local maps are drawn from above
  // and the pose arrows point where the camera looks; the world points stay.
  const Eigen::Matrix3f to_body = kOpticalInBody.cast<float>();
  for (auto& p : cloud->points) p.getVector3fMap() = to_body * p.getVector3fMap();
  reduced = reduceFrame(*cloud, pixels, options.reduction);
  Eigen::Isometry3d pose = optical_pose;
  pose.linear() = optical_pose.linear() * kOpticalInBody.transpose();
  cloud->sensor_origin_ << pose.translation().cast<float>(), 0.0f;
  cloud->sensor_orientation_ = Eigen::Quaternionf(pose.linear().cast<float>());
  return {cloud, pose};
}

/// Every frame, in parallel; the first error (in frame order) is thrown.
void readFrames(const std::vector<std::string>& files, const std::vector<Eigen::Isometry3d>& optical_poses,
                const DepthOptions& options, DepthSequence& out) {
  std::vector<Observation<pcl::PointXYZ>> observations(files.size());
  std::vector<std::string> warnings(files.size());
  std::vector<char> reduced(files.size(), 0);
  const std::vector<SkippedFrame> skipped = readFramesInParallel(
      files.size(),
      [&](std::size_t k) {
        bool frame_reduced = false;
        observations[k] = readFrame(files[k], optical_poses[k], options, out.depth_scale, frame_reduced, warnings[k]);
        reduced[k] = frame_reduced;
      },
      options.reduction);
  const std::string skipped_warning = skippedWarning(skipped, files.size());
  if (!skipped_warning.empty()) out.warnings.push_back(skipped_warning);
  for (std::size_t k = 0, next = 0; k < files.size(); ++k) {
    if (next < skipped.size() && skipped[next].index == k) {
      ++next;
      continue;
    }
    out.observations.push_back(std::move(observations[k]));
    out.labels.push_back(files[k]);
    if (!warnings[k].empty()) out.warnings.push_back(std::move(warnings[k]));
    out.reduced += reduced[k];
  }
}

}  // namespace

DepthSequence loadDepthSequence(const std::string& folder, DepthLayout layout, const DepthOptions& options) {
  const fs::path dir(folder);
  DepthSequence out;
  out.layout = layout;
  out.depth_scale = options.depth_scale.value_or(defaultDepthScale(layout));
  if (layout == DepthLayout::TumRgbd) {
    const std::vector<DepthFrame> frames = readDepthList(dir);
    const std::string truth = options.poses.value_or((dir / "groundtruth.txt").string());
    const StampedPoseIndex poses(readStampedPoses(truth), options.max_time_difference);
    std::vector<std::string> files;
    std::vector<Eigen::Isometry3d> matched;
    for (const DepthFrame& frame : frames) {
      const auto pose = poses.at(frame.stamp);
      if (!pose) {
        ++out.skipped;
        continue;
      }
      files.push_back(frame.file);
      matched.push_back(*pose);
    }
    const UpAxis up = options.up.value_or(UpAxis::PlusZ);
    putUpOnZ(matched, up == UpAxis::Auto ? camerasUpAxis(matched) : up, options.up.has_value(), truth, out);
    readFrames(files, matched, options, out);
    if (out.observations.empty())
      throw InputError(truth + ": no pose within " + std::to_string(options.max_time_difference) +
                       " s of any of the " + std::to_string(frames.size()) +
                       " depth frames (--max-time-difference widens the tolerance)");
    if (out.skipped > 0)
      out.warnings.push_back(std::to_string(out.skipped) + " of " + std::to_string(frames.size()) +
                             " depth frames have no pose in " + truth + " within " +
                             std::to_string(options.max_time_difference) + " s: skipped");
    return out;
  }
  const std::vector<std::string> files = listPngFiles(dir / "depth");
  const std::string log = options.poses.value_or((dir / "trajectory.log").string());
  std::vector<Eigen::Isometry3d> poses = parseTrajectoryLog(readInputBytes(log, "trajectory"), inputName(log));
  if (poses.size() < files.size())
    throw InputError(log + ": " + std::to_string(poses.size()) + " trajectory entries for " +
                     std::to_string(files.size()) + " depth images (one 5-line block per image, in name order)");
  if (poses.size() > files.size())
    out.warnings.push_back(log + ": " + std::to_string(poses.size()) + " trajectory entries for " +
                           std::to_string(files.size()) + " depth images; the last " +
                           std::to_string(poses.size() - files.size()) + " are not used");
  poses.resize(std::min(poses.size(), files.size()));
  const UpAxis up = options.up.value_or(UpAxis::Auto);
  putUpOnZ(poses, up == UpAxis::Auto ? camerasUpAxis(poses) : up, options.up.has_value(), log, out);
  readFrames(files, poses, options, out);
  return out;
}

Eigen::Matrix3d upToZ(UpAxis axis) {
  const double quarter = 1.5707963267948966;
  switch (axis) {
    case UpAxis::PlusX: return Eigen::AngleAxisd(-quarter, Eigen::Vector3d::UnitY()).toRotationMatrix();
    case UpAxis::MinusX: return Eigen::AngleAxisd(quarter, Eigen::Vector3d::UnitY()).toRotationMatrix();
    case UpAxis::PlusY: return Eigen::AngleAxisd(quarter, Eigen::Vector3d::UnitX()).toRotationMatrix();
    case UpAxis::MinusY: return Eigen::AngleAxisd(-quarter, Eigen::Vector3d::UnitX()).toRotationMatrix();
    case UpAxis::MinusZ: return Eigen::AngleAxisd(2 * quarter, Eigen::Vector3d::UnitX()).toRotationMatrix();
    case UpAxis::PlusZ:
    case UpAxis::Auto: break;
  }
  return Eigen::Matrix3d::Identity();
}

UpAxis camerasUpAxis(const std::vector<Eigen::Isometry3d>& optical_poses) {
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (const auto& pose : optical_poses) up -= pose.linear().col(1);  // the image's y axis points down
  if (up.isZero()) return UpAxis::PlusZ;
  Eigen::Index axis = 0;
  up.cwiseAbs().maxCoeff(&axis);
  static const UpAxis plus[] = {UpAxis::PlusX, UpAxis::PlusY, UpAxis::PlusZ};
  static const UpAxis minus[] = {UpAxis::MinusX, UpAxis::MinusY, UpAxis::MinusZ};
  return up[axis] > 0 ? plus[axis] : minus[axis];
}

}  // namespace obsgroup::io
