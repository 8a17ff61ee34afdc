// The label map and its YAML as the command writes and `locate` reads them.
#include "place_outputs.h"
#include "temp_folder.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

namespace obsgroup::io {
namespace {

class PlaceOutputs : public test::TempFolderTest {};

// A long route's label map is wider than libpng's default limit of a
// million pixels: it is written and read back whole, every label in place.
TEST_F(PlaceOutputs, ALabelMapWiderThanAMillionPixelsRoundTrips) {
  PlaceMap map;
  map.grid.resolution = 0.2;
  map.grid.origin = Eigen::Vector2d(-3.0, 4.5);
  map.grid.width = 1'200'000;
  map.grid.height = 2;
  map.labels.assign(std::size_t(map.grid.width) * map.grid.height, -1);
  for (int i = 0; i < map.grid.width; i += 1000) map.labels[map.grid.index(i, i % 2)] = i % 300;  // 16-bit ids too
  writePlaceLabels((dir_ / "places.png").string(), map);
  std::ofstream(dir_ / "places.yaml") << mapYaml(map, "places.png", "raw");
  const PlaceMap back = readPlaceLabels(dir_.string());
  EXPECT_EQ(back.grid.width, map.grid.width);
  EXPECT_EQ(back.grid.height, map.grid.height);
  EXPECT_DOUBLE_EQ(back.grid.resolution, map.grid.resolution);
  EXPECT_TRUE(back.grid.origin.isApprox(map.grid.origin));
  EXPECT_EQ(back.labels, map.labels);
}

}  // namespace
}  // namespace obsgroup::io
