// The pictures' drawn content, read back with cairo: arcs between group
// centres, the legend, distinct colours of neighbouring groups, a crop that a
// far return does not shrink, the local maps' scale bar.
#include "pictures.h"
#include "png_rows.h"

#include <cairo.h>
#include <pcl/point_types.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>

namespace fs = std::filesystem;
using namespace obsgroup;
using render::MapLayout;
using render::mapLayout;

namespace {

/// A PNG read back: pixel colours as 0..255 channels.
class Png {
 public:
  explicit Png(const fs::path& path)
      : s_(cairo_image_surface_create_from_png(path.string().c_str()), cairo_surface_destroy) {}
  bool ok() const { return cairo_surface_status(s_.get()) == CAIRO_STATUS_SUCCESS; }
  int width() const { return cairo_image_surface_get_width(s_.get()); }
  int height() const { return cairo_image_surface_get_height(s_.get()); }
  std::uint32_t rgb(int x, int y) const {
    const unsigned char* row = cairo_image_surface_get_data(s_.get()) + y * cairo_image_surface_get_stride(s_.get());
    return reinterpret_cast<const std::uint32_t*>(row)[x] & 0xffffffu;
  }
  bool white(int x, int y) const { return rgb(x, y) == 0xffffffu; }
  /// Grey, not white: an arc (or text), not a group's colour.
  bool darkGrey(int x, int y) const {
    const std::uint32_t c = rgb(x, y);
    const int r = c >> 16, g = (c >> 8) & 255, b = c & 255;
    return r < 215 && std::abs(r - g) < 12 && std::abs(g - b) < 12;
  }

 private:
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> s_;
};

/// Four rooms of 10 m at the corners of a 20 m square, one group each, three
/// observations per room 2 m apart; one far return 1 km away in the first.
struct Scene {
  WorldPoints world;
  std::vector<Eigen::Isometry3d> poses;
  Partition partition;
  TopologicalMap topology;

  explicit Scene(bool far_return = true) {
    const Eigen::Vector2d rooms[] = {{0, 0}, {20, 0}, {0, 20}, {20, 20}};
    std::vector<std::vector<Eigen::Vector3f>> points;
    partition.groups.resize(4);
    for (int g = 0; g < 4; ++g) {
      LocalMapFrame node;
      node.pose.translation() << rooms[g].x() - 2, rooms[g].y(), 0;
      for (int k = 0; k < 3; ++k) {
        const int i = int(poses.size());
        Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
        pose.translation() << rooms[g].x() - 2 + 2 * k, rooms[g].y(), 0;
        poses.push_back(pose);
        partition.groups[g].push_back(i);
        partition.group_of.push_back(g);
        node.members.push_back(i);
        node.member_poses.push_back(node.pose.inverse() * pose);
        std::vector<Eigen::Vector3f> wall;
        for (double t = -5; t <= 5; t += 0.1)
          for (const Eigen::Vector2d& p : {Eigen::Vector2d(t, -5), Eigen::Vector2d(t, 5), Eigen::Vector2d(-5, t),
                                           Eigen::Vector2d(5, t)})
            wall.emplace_back(float(rooms[g].x() + p.x()), float(rooms[g].y() + p.y()), 0.f);
        if (far_return && i == 0) wall.emplace_back(1000.f, 1000.f, 0.f);
        points.push_back(wall);
      }
      node.reference = node.members.front();
      topology.nodes.push_back(node);
    }
    world.appendAll(points, 1);
  }

  void arc(int from, int to, double weight) {
    TopologicalArc a;
    a.from = from, a.to = to, a.weight = weight, a.overlapping_pairs = weight > 0, a.sequence_pairs = 1;
    topology.arcs.push_back(a);
  }

  MapLayout layout() const { return mapLayout(world, poses, poses, partition, topology); }
};

class Pictures : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("obsgroup_test_pictures_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!std::getenv("OBSGROUP_KEEP_PICTURES")) fs::remove_all(dir_);
  }

  fs::path writeMap(const Scene& scene) {
    const fs::path out = dir_ / ("out" + std::to_string(runs_++));
    render::writeMapPictures(render::folderWriter(out.string()), scene.world, scene.poses, scene.poses,
                             scene.partition, scene.topology);
    return out / "map.png";
  }

  /// Of the pixels along the middle half of the segment between the centres
  /// of `a` and `b`, the share drawn dark grey (an arc).
  static double arcShare(const Png& png, const MapLayout& layout, int a, int b) {
    int dark = 0, all = 0;
    for (double t = 0.3; t <= 0.7; t += 0.01, ++all) {
      const Eigen::Vector2d p = layout.centres[a] + t * (layout.centres[b] - layout.centres[a]);
      const int x = int(std::lround(p.x())), y = int(std::lround(p.y()));
      bool any = false;  // the line is antialiased: look beside it too
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) any = any || png.darkGrey(x + dx, y + dy);
      dark += any;
    }
    return double(dark) / all;
  }

  fs::path dir_;
  int runs_ = 0;
};

TEST_F(Pictures, ArcsAreDrawnBetweenGroupCentres) {
  Scene scene;
  scene.arc(0, 1, 5.0);
  scene.arc(0, 2, 1.0);
  const Png png(writeMap(scene));
  ASSERT_TRUE(png.ok());
  const MapLayout layout = scene.layout();
  ASSERT_EQ(png.width(), layout.view.width);
  EXPECT_GT(arcShare(png, layout, 0, 1), 0.9);
  EXPECT_GT(arcShare(png, layout, 0, 2), 0.9);
  EXPECT_LT(arcShare(png, layout, 1, 2), 0.1);  // no arc there
  EXPECT_LT(arcShare(png, layout, 2, 3), 0.1);
}

TEST_F(Pictures, ArcsOfNoOverlapAreDrawnToo) {  // all weights 0 once gave NaN widths
  Scene scene;
  scene.arc(0, 1, 0.0);
  scene.arc(2, 3, 0.0);
  const Png png(writeMap(scene));
  const MapLayout layout = scene.layout();
  EXPECT_GT(arcShare(png, layout, 0, 1), 0.9);
  EXPECT_GT(arcShare(png, layout, 2, 3), 0.9);
}

TEST_F(Pictures, TheLegendHasContent) {
  Scene scene;
  scene.arc(0, 1, 1.0);
  const Png png(writeMap(scene));
  const MapLayout layout = scene.layout();
  ASSERT_GT(layout.legend_top, png.height() / 2);
  ASSERT_LT(layout.legend_top, png.height() - 40);
  int dark = 0, coloured = 0;
  for (int y = layout.legend_top; y < png.height(); ++y)
    for (int x = 0; x < png.width(); ++x) {
      dark += png.darkGrey(x, y);
      const std::uint32_t c = png.rgb(x, y);
      coloured += (c >> 16) != (c & 255) && ((c >> 8) & 255) != (c & 255);
    }
  EXPECT_GT(dark, 1500);     // text, the arc and the scale bar
  EXPECT_GT(coloured, 30);   // the sample group and arrow
}

TEST_F(Pictures, AFarReturnDoesNotShrinkTheBuilding) {
  Scene scene;
  const Png png(writeMap(scene));
  const MapLayout layout = scene.layout();
  EXPECT_EQ(layout.points_outside, 1u);
  int x0 = png.width(), x1 = -1, y0 = png.height(), y1 = -1;
  for (int y = 0; y < layout.legend_top; ++y)
    for (int x = 0; x < png.width(); ++x)
      if (!png.white(x, y)) x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  // The rooms span 30 m; the picture is wider than tall (room for the legend).
  EXPECT_GT(y1 - y0, 0.8 * layout.legend_top);
  EXPECT_GT(x1 - x0, 0.5 * png.width());
  // Without the far return the picture is the same size.
  const MapLayout clean = Scene(false).layout();
  EXPECT_EQ(clean.view.width, layout.view.width);
  EXPECT_EQ(clean.view.height, layout.view.height);
}

TEST_F(Pictures, NeighbouringGroupsHaveDifferentColours) {
  Scene scene;
  scene.arc(0, 1, 1.0);
  scene.arc(0, 3, 1.0);
  scene.arc(1, 2, 1.0);
  const Png png(writeMap(scene));
  const MapLayout layout = scene.layout();
  // A room's outer corner is a point of that group's colour only.
  const Eigen::Vector2d corners[] = {{-5, -5}, {25, -5}, {-5, 25}, {25, 25}};
  std::uint32_t colour[4];
  for (int g = 0; g < 4; ++g) {
    colour[g] = png.rgb(int(layout.view.px(corners[g].x())), int(layout.view.py(corners[g].y())));
    EXPECT_FALSE(png.white(int(layout.view.px(corners[g].x())), int(layout.view.py(corners[g].y()))));
  }
  for (const TopologicalArc& arc : scene.topology.arcs) EXPECT_NE(colour[arc.from], colour[arc.to]);
  // Every group has its two nearest as neighbours here: all four differ.
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) EXPECT_NE(colour[a], colour[b]) << a << " " << b;
}

/// `n` nodes scattered over 100 m x 7 m, and `arcs` between them: random
/// ones, or (`random` false) each node's to the next three.
TopologicalMap randomTopology(int n, int arcs, bool random) {
  std::mt19937 generator(7);
  TopologicalMap topology;
  for (int g = 0; g < n; ++g) {
    LocalMapFrame node;
    node.pose.translation() << std::uniform_real_distribution<double>(0, 100)(generator), g % 7, 0;
    node.member_poses.push_back(Eigen::Isometry3d::Identity());
    topology.nodes.push_back(node);
  }
  for (int k = 0; k < arcs; ++k) {
    TopologicalArc arc;
    arc.from = random ? int(generator() % n) : k / 3;
    arc.to = random ? int(generator() % n) : k / 3 + 1 + k % 3;
    arc.weight = double(generator() % 1000);
    if (arc.from > arc.to) std::swap(arc.from, arc.to);
    if (arc.from != arc.to && arc.to < n) topology.arcs.push_back(arc);
  }
  return topology;
}

TEST(GroupColours, NoArcJoinsTwoGroupsOfOneColour) {
  const TopologicalMap topology = randomTopology(300, 900, false);
  const std::vector<int> colours = render::groupColours(topology);
  ASSERT_EQ(colours.size(), 300u);
  for (const TopologicalArc& arc : topology.arcs) EXPECT_NE(colours[arc.from], colours[arc.to]);
  EXPECT_LT(*std::max_element(colours.begin(), colours.end()), 12);
}

TEST(GroupColours, ADenseTopologyKeepsTheShownArcsApart) {
  const TopologicalMap topology = randomTopology(300, 6000, true);  // 40 arcs a node
  const std::vector<int> colours = render::groupColours(topology);
  ASSERT_EQ(colours.size(), 300u);
  for (std::size_t a : render::shownArcs(topology, 3))
    EXPECT_NE(colours[topology.arcs[a].from], colours[topology.arcs[a].to]);
  EXPECT_LT(*std::max_element(colours.begin(), colours.end()), 12);  // all well separated
}

/// The two nearest centres of every group, as comparing all pairs would
/// give them, ties to the lower index: on a lattice (four neighbours at one
/// distance, and stacked duplicates) far from the origin, as UTM maps are.
TEST(GroupColours, NeighboursAreTheTwoNearestCentresWithTiesToTheLowerIndex) {
  TopologicalMap topology;
  for (int g = 0; g < 150; ++g) {
    LocalMapFrame node;
    node.pose.translation() << 500000.0 + 2.0 * (g % 10), 5400000.0 + 2.0 * ((g / 10) % 10), 0.0;  // rows 0-4 twice
    node.member_poses.push_back(Eigen::Isometry3d::Identity());
    topology.nodes.push_back(node);
  }
  const auto neighbours = render::groupNeighbours(topology, {});
  ASSERT_EQ(neighbours.size(), topology.nodes.size());
  std::vector<std::set<int>> expected(topology.nodes.size());
  for (int g = 0; g < 150; ++g) {
    std::vector<std::pair<double, int>> by_distance;
    for (int h = 0; h < 150; ++h)
      if (h != g)
        by_distance.emplace_back((topology.nodes[g].pose.translation() - topology.nodes[h].pose.translation()).squaredNorm(), h);
    std::sort(by_distance.begin(), by_distance.end());
    for (int j = 0; j < 2; ++j) expected[g].insert(by_distance[j].second), expected[by_distance[j].second].insert(g);
  }
  for (int g = 0; g < 150; ++g)
    EXPECT_EQ(std::set<int>(neighbours[g].begin(), neighbours[g].end()), expected[g]) << "group " << g;
  const std::vector<int> colours = render::groupColours(topology);
  for (int g = 0; g < 150; ++g)
    for (int h : expected[g]) EXPECT_NE(colours[g], colours[h]);
}

TEST(ShownArcs, EachNodeKeepsItsStrongest) {
  TopologicalMap topology;
  topology.nodes.resize(6);
  for (int a = 0; a < 6; ++a)
    for (int b = a + 1; b < 6; ++b) {
      TopologicalArc arc;
      arc.from = a, arc.to = b, arc.weight = a * 10 + b;
      topology.arcs.push_back(arc);
    }
  const std::vector<std::size_t> shown = render::shownArcs(topology, 1);
  // Node 5's strongest is (4, 5) for 4 and 5; (3, 5) for 3, (2, 5), (1, 5), (0, 5).
  ASSERT_EQ(shown.size(), 5u);
  for (std::size_t a : shown) EXPECT_EQ(topology.arcs[a].to, 5);
  EXPECT_EQ(render::shownArcs(topology, 5).size(), topology.arcs.size());
}

TEST_F(Pictures, AThousandGroupsKeepTheirMarksApart) {
  // 1,000 one-observation groups on a 40 x 25 grid 3 m apart, each joined to
  // its grid neighbours and to the groups two rows on.
  Scene scene;  // its four rooms replaced
  scene.poses.clear();
  scene.partition = Partition();
  scene.topology = TopologicalMap();
  std::vector<std::vector<Eigen::Vector3f>> points;
  for (int g = 0; g < 1000; ++g) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() << 3.0 * (g % 40), 3.0 * (g / 40), 0;
    scene.poses.push_back(pose);
    scene.partition.groups.push_back({g});
    scene.partition.group_of.push_back(g);
    LocalMapFrame node;
    node.members = {g}, node.reference = g, node.pose = pose, node.member_poses = {Eigen::Isometry3d::Identity()};
    scene.topology.nodes.push_back(node);
    std::vector<Eigen::Vector3f> wall;
    for (double t = -1.4; t <= 1.4; t += 0.1) wall.emplace_back(float(pose.translation().x() + t),
                                                                float(pose.translation().y() + 1.4), 0.f);
    points.push_back(wall);
  }
  scene.world = WorldPoints();
  scene.world.appendAll(points, 1);
  for (int g = 0; g < 1000; ++g)
    for (int h : {g + 1, g + 40, g + 80})
      if (h < 1000 && (h != g + 1 || h % 40 != 0)) scene.arc(g, h, 1.0 + (g * 7 + h) % 5);
  const MapLayout layout = scene.layout();
  EXPECT_LE(layout.view.width, 2800 + 100);
  EXPECT_LE(layout.shown_arcs.size(), 3000u);
  EXPECT_LT(layout.shown_arcs.size(), scene.topology.arcs.size());
  std::size_t numbered = 0;
  for (int g = 0; g < 1000; ++g) {
    EXPECT_GT(layout.centres[g].x(), 0);
    EXPECT_LT(layout.centres[g].x(), layout.view.width);
    EXPECT_GT(layout.centres[g].y(), 0);
    EXPECT_LT(layout.centres[g].y(), layout.legend_top);
    if (!layout.numbered[g]) continue;
    ++numbered;
    for (int h = 0; h < g; ++h)
      if (layout.numbered[h]) {
        EXPECT_GE((layout.centres[g] - layout.centres[h]).norm(), 2 * layout.label_radius);
      }
  }
  EXPECT_GT(numbered, 50u);
  for (std::size_t a : layout.shown_arcs)
    EXPECT_NE(layout.colours[scene.topology.arcs[a].from], layout.colours[scene.topology.arcs[a].to]);
  const Png png(writeMap(scene));
  ASSERT_TRUE(png.ok());
  EXPECT_EQ(png.width(), layout.view.width);
}

TEST_F(Pictures, GroupsTooCloseForTheirMarksAreDrawnAsADensity) {
  // 6,000 groups of two observations 0.5 m apart along a 3 km route: about a
  // pixel apart on the canvas, each joined to the next.
  Scene scene;
  EXPECT_FALSE(scene.layout().coarse);  // four rooms: a mark each
  {
    Scene still;  // every observation at one spot (a robot standing still): still a mark each
    for (auto& pose : still.poses) pose = still.poses.front();
    EXPECT_FALSE(still.layout().coarse);
  }
  scene.poses.clear();
  scene.partition = Partition();
  scene.topology = TopologicalMap();
  std::vector<std::vector<Eigen::Vector3f>> points;
  const int groups = 6000;
  for (int g = 0; g < groups; ++g) {
    LocalMapFrame node;
    for (int k = 0; k < 2; ++k) {
      const int i = int(scene.poses.size());
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.translation() << 0.5 * g + 0.2 * k, 0, 0;
      scene.poses.push_back(pose);
      scene.partition.groups.resize(std::size_t(g) + 1);
      scene.partition.groups[std::size_t(g)].push_back(i);
      scene.partition.group_of.push_back(g);
      node.members.push_back(i), node.member_poses.push_back(Eigen::Isometry3d::Identity());
      // A wall 60 m to the side: its grey stays out of the poses' blocks.
      points.push_back({Eigen::Vector3f(float(0.5 * g), 60.f, 0.f)});
    }
    node.reference = node.members.front(), node.pose = scene.poses[std::size_t(node.reference)];
    scene.topology.nodes.push_back(node);
  }
  scene.world = WorldPoints();
  scene.world.appendAll(points, 1);
  double total = 0;
  for (int g = 0; g + 1 < groups; ++g) scene.arc(g, g + 1, 1.0 + g % 3), total += 1.0 + g % 3;
  const MapLayout layout = scene.layout();
  ASSERT_TRUE(layout.coarse);
  EXPECT_LT(layout.spacing, 4.0);
  // The arcs summed between blocks: fewer lines, each between two blocks,
  // together no more than every arc.
  ASSERT_FALSE(layout.coarse_arcs.empty());
  EXPECT_LT(layout.coarse_arcs.size(), scene.topology.arcs.size() / 10);
  std::size_t summed = 0;
  double weight = 0;
  for (const auto& line : layout.coarse_arcs) {
    EXPECT_GE(line.arcs, 1u);
    EXPECT_GE((line.to - line.from).norm(), 1.0);
    summed += line.arcs, weight += line.weight;
  }
  EXPECT_GE(summed, layout.coarse_arcs.size());
  EXPECT_LE(summed, scene.topology.arcs.size());
  EXPECT_LE(weight, total);
  std::size_t numbered = std::size_t(std::count(layout.numbered.begin(), layout.numbered.end(), 1));
  EXPECT_GT(numbered, 10u);
  EXPECT_LT(numbered, std::size_t(groups) / 10);

  {
    const Png png(writeMap(scene));
    ASSERT_TRUE(png.ok());
    EXPECT_EQ(png.width(), layout.view.width);
  }

  // Each block holding observations is a shade between white and the colour
  // of the group with most observations there (ties: the lower group); seen
  // without the arcs, which run along the route.
  scene.topology.arcs.clear();
  const MapLayout bare = scene.layout();
  ASSERT_TRUE(bare.coarse);
  const Png png(writeMap(scene));
  ASSERT_TRUE(png.ok());
  const render::PictureView& v = bare.view;
  std::map<std::pair<int, int>, std::map<int, int>> counts;  // block: group: observations
  for (std::size_t i = 0; i < scene.poses.size(); ++i) {
    const int x = int(v.px(scene.poses[i].translation().x())), y = int(v.py(scene.poses[i].translation().y()));
    ++counts[{x / bare.block, y / bare.block}][scene.partition.group_of[i]];
  }
  int checked = 0, shaded = 0;
  for (const auto& [block, of_group] : counts) {
    int best = -1, most = 0;
    for (const auto& [g, n] : of_group)
      if (n > most) best = g, most = n;
    // A pixel of the block away from any number's circle and the arcs' line.
    const int x = block.first * bare.block, y = block.second * bare.block;
    bool clear = true;
    for (std::size_t g = 0; g < bare.centres.size(); ++g)
      if (bare.numbered[g] && (bare.centres[g] - Eigen::Vector2d(x, y)).norm() < bare.label_radius + 6) clear = false;
    if (!clear || y >= bare.legend_top) continue;
    ++checked;
    const std::string hex = render::paletteHex(bare.colours[std::size_t(best)]);
    const int c[3] = {std::stoi(hex.substr(1, 2), nullptr, 16), std::stoi(hex.substr(3, 2), nullptr, 16),
                      std::stoi(hex.substr(5, 2), nullptr, 16)};
    const std::uint32_t rgb = png.rgb(x, y);
    const int p[3] = {int(rgb >> 16), int((rgb >> 8) & 255), int(rgb & 255)};
    // p = 255 - t (255 - c) for one t in [0.3, 1] on every channel
    double t = -1;
    bool fits = true;
    for (int k = 0; k < 3; ++k) {
      if (255 - c[k] < 40) continue;
      const double tk = double(255 - p[k]) / (255 - c[k]);
      if (t < 0) t = tk;
      fits = fits && std::abs(tk - t) < 0.05;
    }
    shaded += fits && t >= 0.29 && t <= 1.01;
  }
  EXPECT_GT(checked, 0);
  EXPECT_EQ(shaded, checked);
}

TEST_F(Pictures, LocalMapsHaveAScaleBar) {
  Scene scene;
  std::vector<LocalMap<pcl::PointXYZ>> maps(1);
  maps[0].frame = scene.topology.nodes[0];
  maps[0].cloud.reset(new pcl::PointCloud<pcl::PointXYZ>);
  for (int i : scene.partition.groups[0])
    for (auto p = scene.world.begin(i); p != scene.world.end(i); ++p) maps[0].cloud->push_back({p->x() + 2, p->y(), 0});
  const fs::path out = dir_ / "local";
  render::writeLocalMapPictures(render::folderWriter(out.string()), maps, 1);
  const Png png(out / "local_maps" / "group_000.png");
  ASSERT_TRUE(png.ok());
  // The bar: a black line in the top margin, ending 40 px from the right.
  int black = 0;
  for (int x = png.width() - 80; x < png.width() - 42; ++x) black += png.rgb(x, 20) == 0;
  EXPECT_GT(black, 30);
  // The far return is cropped away: the room fills the picture.
  int x0 = png.width(), x1 = -1;
  for (int y = 40; y < png.height() - 40; ++y)
    for (int x = 0; x < png.width(); ++x)
      if (!png.white(x, y) && !png.darkGrey(x, y)) x0 = std::min(x0, x), x1 = std::max(x1, x);
  EXPECT_GT(x1 - x0, png.height() / 2);
}

}  // namespace

TEST(PicturePalette, AFewColoursAreTheirOwnPaletteAndMoreAreDrawnFromTheNearest) {
  const int width = 40, height = 30;
  constexpr std::uint32_t kOpaque = 0xff000000u;
  std::vector<std::uint32_t> bgrx(std::size_t(width) * height, kOpaque | 0xffffffu);  // white, cairo's ARGB32 words
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < 10; ++x) bgrx[std::size_t(y) * width + x] = kOpaque | 0x1f77b4u;  // a band of the first colour
  const auto bytes = reinterpret_cast<const unsigned char*>(bgrx.data());
  auto exact = obsgroup::render::indexColours(bytes, width, height, width * 4, false);
  ASSERT_TRUE(exact);
  ASSERT_EQ(exact->palette.size(), 2u);
  for (std::size_t i = 0; i < bgrx.size(); ++i) {  // every pixel is its colour again
    const png_color c = exact->palette[exact->indices[i]];
    EXPECT_EQ(kOpaque | std::uint32_t(c.red) << 16 | std::uint32_t(c.green) << 8 | c.blue, bgrx[i]) << i;
  }
  // 256 colours of two pixels each, and 40 more of one pixel, each a step off one of them (as an
  // antialiased edge is): the frequent ones are the palette, each rare one drawn as its neighbour.
  std::fill(bgrx.begin(), bgrx.end(), kOpaque | 0xffffffu);
  for (std::uint32_t k = 0; k < 255; ++k) bgrx[2 * k] = bgrx[2 * k + 1] = kOpaque | k << 16 | 0x40u;
  for (std::uint32_t k = 0; k < 40; ++k) bgrx[600 + k] = kOpaque | (k * 6) << 16 | 0x41u;
  EXPECT_FALSE(obsgroup::render::indexColours(bytes, width, height, width * 4, false));  // not exactly
  auto quantized = obsgroup::render::indexColours(bytes, width, height, width * 4, true);
  ASSERT_TRUE(quantized);
  ASSERT_EQ(quantized->palette.size(), 256u);
  for (std::size_t i = 0; i < bgrx.size(); ++i) {
    const png_color c = quantized->palette[quantized->indices[i]];
    EXPECT_EQ(c.red, bgrx[i] >> 16 & 0xff) << i;
    EXPECT_LE(std::abs(int(c.blue) - int(bgrx[i] & 0xff)), 1) << i;
  }
  bgrx[5] = 0x80808080u;  // one translucent pixel: no palette, the picture keeps its alpha
  EXPECT_FALSE(obsgroup::render::indexColours(bytes, width, height, width * 4, true));
}
