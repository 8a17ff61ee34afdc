#include "pictures.h"

#include <cairo-svg.h>
#include <cairo.h>
#include <pcl/point_types.h>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>

namespace obsgroup::io {

namespace {

struct Rgb {
  double r, g, b;
};

/// Well separated colours for the first groups, then golden-angle hues.
Rgb groupColour(int group) {
  static const Rgb kPalette[] = {{0.12, 0.47, 0.71}, {1.00, 0.50, 0.05}, {0.17, 0.63, 0.17}, {0.84, 0.15, 0.16},
                                 {0.58, 0.40, 0.74}, {0.55, 0.34, 0.29}, {0.89, 0.47, 0.76}, {0.50, 0.50, 0.50},
                                 {0.74, 0.74, 0.13}, {0.09, 0.75, 0.81}};
  if (group < 10) return kPalette[group];
  const double h = std::fmod(group * 0.618033988749895, 1.0) * 6.0;
  const double x = 1.0 - std::abs(std::fmod(h, 2.0) - 1.0);
  const double c = 0.8, m = 0.1;
  const int sector = static_cast<int>(h);
  const double rgb[6][3] = {{c, x, 0}, {x, c, 0}, {0, c, x}, {0, x, c}, {x, 0, c}, {c, 0, x}};
  return {rgb[sector][0] * c + m, rgb[sector][1] * c + m, rgb[sector][2] * c + m};
}

using Surface = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using Context = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;

Surface imageSurface(int width, int height) {
  return Surface(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height), cairo_surface_destroy);
}

void writePng(const OutputFolder& out, const std::string& name, cairo_surface_t* surface) {
  out.write(name, [surface](const std::string& temporary) {
    if (cairo_surface_write_to_png(surface, temporary.c_str()) != CAIRO_STATUS_SUCCESS)
      throw std::runtime_error(temporary + ": cairo cannot write the PNG");
  });
}

void text(cairo_t* cr, double x, double y, const std::string& s, double size = 14) {
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, s.c_str());
}

/// World (re-centred) metres to picture pixels, y up.
struct View {
  double scale = 1.0, min_x = 0.0, max_y = 0.0, margin = 40.0;
  int width = 0, height = 0;
  double px(double x) const { return margin + (x - min_x) * scale; }
  double py(double y) const { return margin + (max_y - y) * scale; }
};

/// A view of `box` (at least 1 m a side) whose longer side is `longest`
/// pixels, within the margin, with 20 px more below for a caption. A picture
/// narrower than `min_width` is widened about the box.
View fitView(Eigen::AlignedBox2d box, double longest, int min_width = 0) {
  if (box.isEmpty()) box.extend(Eigen::Vector2d::Zero());
  const Eigen::Vector2d size = box.sizes().cwiseMax(1.0);
  View v;
  v.scale = longest / size.maxCoeff();
  v.min_x = box.min().x();
  v.max_y = box.max().y();
  v.width = static_cast<int>(std::ceil(size.x() * v.scale + 2 * v.margin));
  v.height = static_cast<int>(std::ceil(size.y() * v.scale + 2 * v.margin + 20));
  if (v.width < min_width) {
    v.min_x -= (min_width - v.width) / 2.0 / v.scale;
    v.width = min_width;
  }
  return v;
}

Eigen::AlignedBox2d boxOf(const Eigen::Vector3f* begin, const Eigen::Vector3f* end,
                          const std::vector<Eigen::Vector2d>& positions) {
  Eigen::AlignedBox2d box;
  for (const Eigen::Vector3f* p = begin; p != end; ++p) box.extend(p->head<2>().cast<double>());
  for (const auto& p : positions) box.extend(p);
  return box;
}

std::uint32_t argbOf(const Rgb& c) {
  return 0xff000000u | (std::uint32_t(c.r * 255) << 16) | (std::uint32_t(c.g * 255) << 8) | std::uint32_t(c.b * 255);
}

/// Each region cell in a pale shade of the group most of whose observations
/// hold it (ties: the lower group). Cells of 3D regions are seen from above.
void tintRegions(const ObservationRegions& regions, const Partition& partition, const View& v, unsigned char* data,
                 int stride) {
  std::vector<std::pair<std::uint64_t, int>> cells;  // (plane cell, group)
  cells.reserve(regions.cells.size());
  for (int i = 0; i < regions.size(); ++i)
    for (std::size_t k = regions.offsets[i]; k < regions.offsets[i + 1]; ++k) {
      const Eigen::Vector3d c = regions.cellCentre(regions.cells[k]);
      const std::uint64_t px = std::uint64_t(std::uint32_t(std::lround(v.px(c.x()))));
      const std::uint64_t py = std::uint64_t(std::uint32_t(std::lround(v.py(c.y()))));
      cells.emplace_back((px << 32) | py, partition.group_of[i]);
    }
  std::sort(cells.begin(), cells.end());
  const int half = std::max(1, int(std::ceil(regions.cell_size * v.scale / 2)));
  for (std::size_t a = 0; a < cells.size();) {
    int best = -1, best_count = 0;
    std::size_t b = a;
    while (b < cells.size() && cells[b].first == cells[a].first) {
      std::size_t e = b;
      while (e < cells.size() && cells[e] == cells[b]) ++e;
      if (int(e - b) > best_count) best = cells[b].second, best_count = int(e - b);
      b = e;
    }
    const Rgb g = groupColour(best);
    const std::uint32_t pale = argbOf({0.72 + 0.28 * g.r, 0.72 + 0.28 * g.g, 0.72 + 0.28 * g.b});
    const int cx = int(std::int32_t(cells[a].first >> 32)), cy = int(std::int32_t(cells[a].first & 0xffffffffu));
    for (int y = std::max(0, cy - half); y < std::min(v.height, cy + half); ++y)
      for (int x = std::max(0, cx - half); x < std::min(v.width, cx + half); ++x)
        reinterpret_cast<std::uint32_t*>(data + y * stride)[x] = pale;
    a = b;
  }
}

/// One pixel per point, or a 2x2 block when they are few (fewer than 300000).
int dotSize(std::size_t points) { return points < 300000 ? 2 : 1; }

/// Points [begin, end) seen from above, `dot` pixels square each, into an
/// image surface's pixels.
void plotPoints(const View& v, const Eigen::Vector3f* begin, const Eigen::Vector3f* end, std::uint32_t argb, int dot,
                unsigned char* data, int stride) {
  for (const Eigen::Vector3f* p = begin; p != end; ++p) {
    const int x = static_cast<int>(v.px(p->x())), y = static_cast<int>(v.py(p->y()));
    for (int dy = 0; dy < dot; ++dy)
      for (int dx = 0; dx < dot; ++dx)
        if (x + dx >= 0 && x + dx < v.width && y + dy >= 0 && y + dy < v.height)
          reinterpret_cast<std::uint32_t*>(data + (y + dy) * stride)[x + dx] = argb;
  }
}

/// The points coloured by group over the tinted regions when there are some.
Surface rasterPoints(const WorldPoints& world, const Partition& partition, const View& v,
                     const ObservationRegions* regions) {
  Surface surface = imageSurface(v.width, v.height);
  cairo_surface_flush(surface.get());
  unsigned char* data = cairo_image_surface_get_data(surface.get());
  const int stride = cairo_image_surface_get_stride(surface.get());
  if (regions) tintRegions(*regions, partition, v, data, stride);
  const int dot = dotSize(world.points.size());
  for (int i = 0; i < world.size(); ++i)
    plotPoints(v, world.begin(i), world.end(i), argbOf(groupColour(partition.group_of[i])), dot, data, stride);
  cairo_surface_mark_dirty(surface.get());
  return surface;
}

/// An arrow from (x, y), in pixels, `length` long towards `heading` (radians
/// from the x axis, counter-clockwise as seen from above); stroke it after.
void arrowPath(cairo_t* cr, double x, double y, double heading, double length) {
  const double dx = std::cos(heading) * length, dy = -std::sin(heading) * length;
  cairo_move_to(cr, x, y);
  cairo_line_to(cr, x + dx, y + dy);
  cairo_line_to(cr, x + 0.7 * dx - 0.25 * dy, y + 0.7 * dy + 0.25 * dx);
  cairo_move_to(cr, x + dx, y + dy);
  cairo_line_to(cr, x + 0.7 * dx + 0.25 * dy, y + 0.7 * dy - 0.25 * dx);
}

/// Position on the plane and heading (the x axis projected on it) of a pose.
void planarPose(const Eigen::Isometry3d& pose, const Eigen::Vector3d& origin, Eigen::Vector2d& position,
                double& heading) {
  position = (pose.translation() - origin).head<2>();
  const Eigen::Vector3d ahead = pose.linear().col(0);
  heading = std::atan2(ahead.y(), ahead.x());
}

/// A bar of a round length (1, 2 or 5 times a power of ten metres) at most a
/// fifth of the drawing wide, labelled, in the top right margin.
void drawScaleBar(cairo_t* cr, const View& v) {
  const double most = (v.width - 2 * v.margin) / 5.0 / v.scale;
  double length = std::pow(10.0, std::floor(std::log10(most)));
  if (5 * length <= most) length *= 5;
  else if (2 * length <= most) length *= 2;
  const double pixels = length * v.scale, x1 = v.width - v.margin, x0 = x1 - pixels, y = v.margin / 2;
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 2);
  cairo_new_path(cr);
  cairo_move_to(cr, x0, y - 4);
  cairo_line_to(cr, x0, y);
  cairo_line_to(cr, x1, y);
  cairo_line_to(cr, x1, y - 4);
  cairo_stroke(cr);
  char label[32];
  std::snprintf(label, sizeof label, "%g m", length);
  cairo_text_extents_t extents;
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 12);
  cairo_text_extents(cr, label, &extents);
  text(cr, x0 - extents.x_advance - 6, y + 4, label, 12);
}

void drawMap(cairo_t* cr, cairo_surface_t* points, const View& v, const std::vector<Eigen::Vector2d>& positions,
             const std::vector<double>& headings, const Partition& partition, const TopologicalMap& topology) {
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_set_source_surface(cr, points, 0, 0);
  cairo_paint(cr);
  // Arcs of the topological map between the groups' mean positions.
  std::vector<Eigen::Vector2d> centre(partition.groups.size(), Eigen::Vector2d::Zero());
  for (std::size_t g = 0; g < partition.groups.size(); ++g) {
    for (int i : partition.groups[g]) centre[g] += positions[i];
    centre[g] /= double(partition.groups[g].size());
  }
  // Stronger arcs (larger cut weight) are drawn thicker and darker. Arcs of
  // consecutive observations only weigh 0: when no arc overlaps, all are thin.
  double strongest = 0.0;
  for (const auto& arc : topology.arcs) strongest = std::max(strongest, arc.weight);
  const double dash[] = {6.0, 4.0};
  cairo_set_dash(cr, dash, 2, 0);
  for (const auto& arc : topology.arcs) {
    const double strength = strongest > 0.0 ? arc.weight / strongest : 0.0;
    cairo_set_source_rgba(cr, 0.2, 0.2, 0.2, 0.15 + 0.6 * strength);
    cairo_set_line_width(cr, 0.5 + 2.5 * strength);
    cairo_move_to(cr, v.px(centre[arc.from].x()), v.py(centre[arc.from].y()));
    cairo_line_to(cr, v.px(centre[arc.to].x()), v.py(centre[arc.to].y()));
    cairo_stroke(cr);
  }
  cairo_set_dash(cr, nullptr, 0, 0);
  // Poses as arrows.
  const double length = std::max(10.0, 0.5 * v.scale);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const Rgb c = groupColour(partition.group_of[i]);
    cairo_set_source_rgb(cr, c.r * 0.6, c.g * 0.6, c.b * 0.6);
    cairo_set_line_width(cr, 1.5);
    arrowPath(cr, v.px(positions[i].x()), v.py(positions[i].y()), headings[i], length);
    cairo_stroke(cr);
  }
  // Group labels at their centres.
  for (std::size_t g = 0; g < centre.size(); ++g) {
    const double x = v.px(centre[g].x()), y = v.py(centre[g].y());
    cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
    cairo_new_path(cr);  // the previous label's text leaves a current point
    cairo_arc(cr, x, y, 11, 0, 2 * M_PI);
    cairo_fill_preserve(cr);
    const Rgb c = groupColour(static_cast<int>(g));
    cairo_set_source_rgb(cr, c.r, c.g, c.b);
    cairo_set_line_width(cr, 2);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    text(cr, x - (g < 10 ? 4 : 8), y + 5, std::to_string(g), 13);
  }
  cairo_set_source_rgb(cr, 0, 0, 0);
  char caption[160];
  std::snprintf(caption, sizeof caption, "%zu observations, %zu groups, %zu arcs; 1 m = %.1f px",
                positions.size(), partition.groups.size(), topology.arcs.size(), v.scale);
  text(cr, v.margin, v.height - 12, caption);
}

/// The points of `world`, at the input `poses`, moved to the `drawn` poses:
/// observation i's by drawn_i poses_i^-1, in double about the origin. A
/// move within rounding of the identity (an unrefined member) keeps them.
/// The boxes are not updated.
WorldPoints atDrawnPoses(const WorldPoints& world, const std::vector<Eigen::Isometry3d>& poses,
                         const std::vector<Eigen::Isometry3d>& drawn) {
  WorldPoints moved = world;
  const int n = world.size();
#pragma omp parallel for schedule(dynamic, 16)
  for (int i = 0; i < n; ++i) {
    const Eigen::Isometry3d move = drawn[i] * poses[i].inverse();
    const Eigen::Matrix3d R = move.linear();
    const Eigen::Vector3d t = R * world.origin + move.translation() - world.origin;
    if ((R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-12 && t.cwiseAbs().maxCoeff() < 1e-9) continue;
    for (std::size_t k = world.offsets[i]; k < world.offsets[i + 1]; ++k)
      moved.points[k] = (R * world.points[k].cast<double>() + t).cast<float>();
  }
  return moved;
}

/// One local map from above in its own frame: its points (already in
/// `surface`), its members' poses, the reference's black in a ring.
void drawLocalMap(cairo_t* cr, const View& v, int group, const LocalMapFrame& frame, std::size_t points) {
  const Rgb c = groupColour(group);
  const double length = std::clamp(0.5 * v.scale, 10.0, 30.0);
  std::size_t reference = 0;
  for (std::size_t k = 0; k < frame.members.size(); ++k) {
    if (frame.members[k] == frame.reference) {
      reference = k;
      continue;
    }
    Eigen::Vector2d position;
    double heading;
    planarPose(frame.member_poses[k], Eigen::Vector3d::Zero(), position, heading);
    cairo_set_source_rgb(cr, c.r * 0.6, c.g * 0.6, c.b * 0.6);
    cairo_set_line_width(cr, 1.5);
    arrowPath(cr, v.px(position.x()), v.py(position.y()), heading, length);
    cairo_stroke(cr);
  }
  if (!frame.members.empty()) {
    Eigen::Vector2d position;
    double heading;
    planarPose(frame.member_poses[reference], Eigen::Vector3d::Zero(), position, heading);
    const double x = v.px(position.x()), y = v.py(position.y());
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 2.5);
    arrowPath(cr, x, y, heading, 1.3 * length);
    cairo_stroke(cr);
    cairo_new_path(cr);
    cairo_arc(cr, x, y, 6, 0, 2 * M_PI);
    cairo_set_line_width(cr, 2);
    cairo_stroke(cr);
  }
  drawScaleBar(cr, v);
  cairo_set_source_rgb(cr, 0, 0, 0);
  char caption[200];
  std::snprintf(caption, sizeof caption, "local map %d: %zu observations, %zu points; reference %d (black)", group,
                frame.members.size(), points, frame.reference);
  text(cr, v.margin, v.height - 12, caption, 12);
}

/// local_maps/group_NNN.png of one local map, whose points (in its frame)
/// are given without the non-finite ones.
void writeLocalMapPicture(const OutputFolder& out, int group, const LocalMapFrame& frame,
                          const std::vector<Eigen::Vector3f>& points) {
  std::vector<Eigen::Vector2d> positions(frame.member_poses.size());
  for (std::size_t k = 0; k < positions.size(); ++k) positions[k] = frame.member_poses[k].translation().head<2>();
  const View v = fitView(boxOf(points.data(), points.data() + points.size(), positions), 700.0, 480);
  Surface surface = imageSurface(v.width, v.height);
  Context cr(cairo_create(surface.get()), cairo_destroy);
  cairo_set_source_rgb(cr.get(), 1, 1, 1);
  cairo_paint(cr.get());
  cairo_surface_flush(surface.get());
  plotPoints(v, points.data(), points.data() + points.size(), argbOf(groupColour(group)), dotSize(points.size()),
             cairo_image_surface_get_data(surface.get()), cairo_image_surface_get_stride(surface.get()));
  cairo_surface_mark_dirty(surface.get());
  drawLocalMap(cr.get(), v, group, frame, points.size());
  char name[64];
  std::snprintf(name, sizeof name, "local_maps/group_%03d.png", group);
  writePng(out, name, surface.get());
}

}  // namespace

std::vector<Eigen::Isometry3d> refinedPoses(const TopologicalMap& topology, std::size_t observations) {
  std::vector<Eigen::Isometry3d> poses(observations, Eigen::Isometry3d::Identity());
  for (const LocalMapFrame& node : topology.nodes)
    for (std::size_t k = 0; k < node.members.size(); ++k) poses.at(node.members[k]) = node.pose * node.member_poses[k];
  return poses;
}

template <typename PointT>
void writeLocalMapPictures(const OutputFolder& out, const std::vector<LocalMap<PointT>>& maps, int threads) {
  const int n = static_cast<int>(maps.size());
  std::vector<std::exception_ptr> failures(maps.size());
#pragma omp parallel for num_threads(threads > 0 ? threads : omp_get_max_threads()) schedule(dynamic, 1)
  for (int g = 0; g < n; ++g) {
    try {
      std::vector<Eigen::Vector3f> points;
      if (maps[g].cloud) {
        points.reserve(maps[g].cloud->size());
        for (const PointT& p : maps[g].cloud->points)
          if (std::isfinite(p.x) && std::isfinite(p.y)) points.emplace_back(p.x, p.y, p.z);
      }
      writeLocalMapPicture(out, g, maps[g].frame, points);
    } catch (...) {
      failures[g] = std::current_exception();
    }
  }
  for (const auto& failure : failures)
    if (failure) std::rethrow_exception(failure);
}

template void writeLocalMapPictures(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZ>>&, int);
template void writeLocalMapPictures(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZI>>&, int);
template void writeLocalMapPictures(const OutputFolder&, const std::vector<LocalMap<pcl::PointXYZRGB>>&, int);

void writeMapPictures(const OutputFolder& out, const WorldPoints& input_world,
                      const std::vector<Eigen::Isometry3d>& poses, const std::vector<Eigen::Isometry3d>& drawn,
                      const Partition& partition, const TopologicalMap& topology, const ObservationRegions* regions) {
  const WorldPoints world = atDrawnPoses(input_world, poses, drawn);
  std::vector<Eigen::Vector2d> positions(drawn.size());
  std::vector<double> headings(drawn.size());
  for (std::size_t i = 0; i < drawn.size(); ++i) planarPose(drawn[i], world.origin, positions[i], headings[i]);
  const View v = fitView(boxOf(world.points.data(), world.points.data() + world.points.size(), positions), 1600.0);
  // The regions describe the input poses (they gave W) and stay there.
  const Surface points = rasterPoints(world, partition, v, regions);

  Surface png = imageSurface(v.width, v.height);
  {
    Context cr(cairo_create(png.get()), cairo_destroy);
    drawMap(cr.get(), points.get(), v, positions, headings, partition, topology);
  }
  writePng(out, "map.png", png.get());

  out.write("map.svg", [&](const std::string& temporary) {
    Surface svg(cairo_svg_surface_create(temporary.c_str(), v.width, v.height), cairo_surface_destroy);
    {
      Context cr(cairo_create(svg.get()), cairo_destroy);
      drawMap(cr.get(), points.get(), v, positions, headings, partition, topology);
    }
    cairo_surface_finish(svg.get());
    if (cairo_surface_status(svg.get()) != CAIRO_STATUS_SUCCESS)
      throw std::runtime_error(temporary + ": cairo cannot write the SVG");
  });
}

void writeWeightsPicture(const OutputFolder& out, const WeightMatrix& W, const Partition& partition) {
  const int n = static_cast<int>(W.rows());
  if (n == 0) return;
  // Position of each observation once ordered by group.
  std::vector<int> position(n);
  std::vector<int> group_start;
  int next = 0;
  for (const auto& group : partition.groups) {
    group_start.push_back(next);
    for (int i : group) position[i] = next++;
  }
  group_start.push_back(n);
  const int side = n <= 800 ? n * std::max(1, 800 / n) : 800;
  const double cell = double(side) / n;
  const int margin = 30;
  std::vector<float> darkness(std::size_t(side) * side, 0.0f);
  for (int col = 0; col < W.outerSize(); ++col)
    for (WeightMatrix::InnerIterator it(W, col); it; ++it) {
      const int x0 = int(position[col] * cell), y0 = int(position[it.row()] * cell);
      const int x1 = std::max(x0 + 1, int((position[col] + 1) * cell));
      const int y1 = std::max(y0 + 1, int((position[it.row()] + 1) * cell));
      for (int y = y0; y < std::min(y1, side); ++y)
        for (int x = x0; x < std::min(x1, side); ++x) {
          float& d = darkness[std::size_t(y) * side + x];
          d = std::max(d, static_cast<float>(std::min(1.0, it.value())));
        }
    }
  Surface surface = imageSurface(side + 2 * margin, side + 2 * margin);
  Context cr(cairo_create(surface.get()), cairo_destroy);
  cairo_set_source_rgb(cr.get(), 1, 1, 1);
  cairo_paint(cr.get());
  cairo_surface_flush(surface.get());
  unsigned char* data = cairo_image_surface_get_data(surface.get());
  const int stride = cairo_image_surface_get_stride(surface.get());
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const auto level = static_cast<std::uint32_t>(255.0f * (1.0f - darkness[std::size_t(y) * side + x]));
      reinterpret_cast<std::uint32_t*>(data + (y + margin) * stride)[x + margin] =
          0xff000000u | (level << 16) | (level << 8) | level;
    }
  cairo_surface_mark_dirty(surface.get());
  cairo_set_source_rgb(cr.get(), 0.85, 0.1, 0.1);
  cairo_set_line_width(cr.get(), 1.5);
  const double dash[] = {4.0, 3.0};
  cairo_set_dash(cr.get(), dash, 2, 0);
  for (std::size_t g = 0; g + 1 < group_start.size(); ++g) {
    const double a = margin + group_start[g] * cell, b = margin + group_start[g + 1] * cell;
    cairo_rectangle(cr.get(), a, a, b - a, b - a);
    cairo_stroke(cr.get());
  }
  cairo_set_dash(cr.get(), nullptr, 0, 0);
  cairo_set_source_rgb(cr.get(), 0, 0, 0);
  text(cr.get(), margin, 20,
       "W (" + std::to_string(n) + " x " + std::to_string(n) + "), ordered by group; darker = larger overlap");
  writePng(out, "weights.png", surface.get());
}

void writeFiedlerPicture(const OutputFolder& out, const Partition& partition) {
  std::vector<const SplitNode*> shown;
  for (const SplitNode& node : partition.splits)
    if (node.attempted && node.eigenvector.size() > 0 && shown.size() < 4) shown.push_back(&node);
  const int plot_w = 640, plot_h = 300, columns = shown.size() > 1 ? 2 : 1;
  const int rows = std::max<int>(1, (static_cast<int>(shown.size()) + 1) / 2);
  Surface surface = imageSurface(plot_w * columns, plot_h * rows);
  Context cr(cairo_create(surface.get()), cairo_destroy);
  cairo_set_source_rgb(cr.get(), 1, 1, 1);
  cairo_paint(cr.get());
  if (shown.empty()) {
    cairo_set_source_rgb(cr.get(), 0, 0, 0);
    text(cr.get(), 20, 40, "No spectral bisection was computed (too few or no overlapping observations).");
  }
  for (std::size_t k = 0; k < shown.size(); ++k) {
    const SplitNode& node = *shown[k];
    const double ox = (k % 2) * plot_w + 50, oy = (k / 2) * plot_h + 40;
    const double w = plot_w - 80, h = plot_h - 80;
    const Eigen::VectorXd& y = node.eigenvector;
    double lo = std::min(y.minCoeff(), node.threshold), hi = std::max(y.maxCoeff(), node.threshold);
    if (hi - lo < 1e-12) hi = lo + 1.0;
    const auto sx = [&](double i) { return ox + (y.size() > 1 ? i / (y.size() - 1) : 0.5) * w; };
    const auto sy = [&](double value) { return oy + h - (value - lo) / (hi - lo) * h; };
    cairo_set_source_rgb(cr.get(), 0.3, 0.3, 0.3);
    cairo_set_line_width(cr.get(), 1);
    cairo_rectangle(cr.get(), ox, oy, w, h);
    cairo_stroke(cr.get());
    cairo_set_source_rgb(cr.get(), 0.12, 0.47, 0.71);
    cairo_set_line_width(cr.get(), 1.2);
    for (Eigen::Index i = 0; i < y.size(); ++i) (i ? cairo_line_to : cairo_move_to)(cr.get(), sx(i), sy(y[i]));
    cairo_stroke(cr.get());
    for (Eigen::Index i = 0; i < y.size() && y.size() <= 400; ++i) {
      cairo_new_path(cr.get());
      cairo_arc(cr.get(), sx(i), sy(y[i]), 2.5, 0, 2 * M_PI);
      cairo_fill(cr.get());
    }
    cairo_set_source_rgb(cr.get(), 0.85, 0.1, 0.1);
    cairo_move_to(cr.get(), ox, sy(node.threshold));
    cairo_line_to(cr.get(), ox + w, sy(node.threshold));
    cairo_stroke(cr.get());
    cairo_set_source_rgb(cr.get(), 0, 0, 0);
    char title[200];
    std::snprintf(title, sizeof title, "split %d: %zu observations, Ncut %.3f, %s", int(&node - partition.splits.data()),
                  node.members.size(), node.ncut, node.accepted ? "accepted" : "rejected");
    text(cr.get(), ox, oy - 12, title);
    text(cr.get(), ox, oy + h + 20, "observation " + std::to_string(node.members.front()) + " ... " +
                                        std::to_string(node.members.back()) + " (in order); red: threshold", 12);
  }
  writePng(out, "fiedler.png", surface.get());
}

}  // namespace obsgroup::io
