// The cells a visibility view depends on (ViewWidths::read_lo, read_hi):
// online grouping recomputes a view when another observation flips a cell
// of the shared occupancy in that box, and only then. A cell flipped
// outside it must leave the view as it was, doors included.
#include "region_cells.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace obsgroup::region_cells {
namespace {

struct View {
  std::vector<std::uint64_t> cells;
  Cell<2> read_lo{}, read_hi{};
  bool read_occupancy = false;
};

View viewOf(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3d& origin, const RegionParameters& params,
            const CellGrid& grid, const OccupancyGrid& occupancy) {
  OccupancyGrid::Reader reader(occupancy);
  RegionMarker<2> own, marker;
  ViewWidths widths;
  View view;
  visibilityOf({points.data(), points.data() + points.size()}, origin, params, grid, true, reader, own, marker, widths,
               view.cells);
  view.read_lo = widths.read_lo, view.read_hi = widths.read_hi;
  view.read_occupancy = widths.read_occupancy;
  return view;
}

bool inBox(const Cell<2>& c, const View& v) {
  return c[0] >= v.read_lo[0] && c[0] <= v.read_hi[0] && c[1] >= v.read_lo[1] && c[1] <= v.read_hi[1];
}

TEST(ViewDependency, CellsFlippedOutsideTheReadBoxLeaveTheViewAsItWas) {
  // A forward laser (a quarter turn of beams) in a cluttered room: its rays
  // behind it read the shared occupancy, and doors (narrow openings between
  // clutter) stop them. Random cells outside the read box flip, many at a
  // time: the view must not change. Cells inside it flip too: the box is
  // not the whole range, and what it holds does change views.
  RegionParameters params;
  const CellGrid grid(params.cell_size);
  const Eigen::Vector3d origin(0.05, -0.03, 0.0);
  const auto centre = grid.inCells<2>(origin);
  const auto [lo, hi] = boxAround<2>(centre, params.max_range / grid.size);
  int smaller_than_range = 0, changed_from_inside = 0;
  for (unsigned seed = 0; seed < 40; ++seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    // Walls of clutter: each cell occupied with a probability that varies by seed.
    const double density = 0.02 + 0.06 * unit(random);
    std::vector<std::uint64_t> occupied;
    for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
      for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
        if (std::hypot(double(x) + 0.5 - centre[0], double(y) + 0.5 - centre[1]) > 2.0 && unit(random) < density)
          occupied.push_back(keyOf<2>(Cell<2>{x, y}));
    // The laser's own points: a wall ahead, 2-4 m away, within 45 degrees of +x.
    std::vector<Eigen::Vector3f> points;
    const double ahead = 2.0 + 2.0 * unit(random);
    for (int b = -45; b <= 45; ++b) {
      const double a = b * 3.14159265358979323846 / 180.0;
      points.emplace_back(float(origin.x() + ahead * std::cos(a)), float(origin.y() + ahead * std::sin(a)), 0.0f);
    }
    const OccupancyGrid base(occupied);
    const View before = viewOf(points, origin, params, grid, base);
    ASSERT_TRUE(before.read_occupancy) << seed;
    ASSERT_LE(before.read_lo[0], before.read_hi[0]) << seed;
    const bool smaller = before.read_lo[0] > lo[0] || before.read_lo[1] > lo[1] || before.read_hi[0] < hi[0] ||
                         before.read_hi[1] < hi[1];
    smaller_than_range += smaller;

    for (const bool inside : {false, true}) {
      OccupancyGrid flipped(occupied);
      std::vector<char> is_occupied;
      for (std::int64_t x = lo[0] - 2; x <= hi[0] + 2; ++x)
        for (std::int64_t y = lo[1] - 2; y <= hi[1] + 2; ++y) {
          const Cell<2> c{x, y};
          if (inBox(c, before) != inside || unit(random) > 0.3) continue;
          const std::uint64_t key = keyOf<2>(c);
          const bool was = std::binary_search(occupied.begin(), occupied.end(), key);
          flipped.set(key, !was);
        }
      const View after = viewOf(points, origin, params, grid, flipped);
      if (!inside) {
        EXPECT_EQ(after.cells, before.cells) << "seed " << seed;
      } else {
        changed_from_inside += after.cells != before.cells;
      }
    }
  }
  EXPECT_GT(smaller_than_range, 20);
  EXPECT_GT(changed_from_inside, 20);
}

}  // namespace
}  // namespace obsgroup::region_cells
