#include "place_outputs.h"

#include <obsgroup/io/errors.h>

#include <nlohmann/json.hpp>
#include "png_rows.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <optional>
#include <cstdlib>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace obsgroup::io {

namespace {

nlohmann::json xy(const Eigen::Vector2d& p) { return nlohmann::json::array({p.x(), p.y()}); }

nlohmann::json ringJson(const std::vector<Eigen::Vector2d>& ring, bool closed) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& p : ring) out.push_back(xy(p));
  if (closed && !ring.empty()) out.push_back(xy(ring.front()));  // GeoJSON repeats the first position
  return out;
}

nlohmann::json bboxJson(const Eigen::AlignedBox2d& box) {
  if (box.isEmpty()) return nullptr;
  return {box.min().x(), box.min().y(), box.max().x(), box.max().y()};
}

nlohmann::json gridJson(const PlaceMap& map) {
  return {{"resolution", map.grid.resolution},
          {"origin", xy(map.grid.origin)},
          {"width", map.grid.width},
          {"height", map.grid.height},
          {"labels", "places.png"},
          {"occupancy", "occupancy.pgm"}};
}

/// One line per place and per door, like partition.json's groups.
std::string linesOf(const char* key, const std::vector<nlohmann::json>& items, bool last) {
  std::string out = std::string("  \"") + key + "\": [";
  for (std::size_t k = 0; k < items.size(); ++k) out += (k ? ",\n    " : "\n    ") + items[k].dump();
  out += items.empty() ? "]" : "\n  ]";
  return out + (last ? "\n" : ",\n");
}

nlohmann::json placeJson(const Place& p, bool with_members) {
  nlohmann::json outline = nlohmann::json::array();
  for (const auto& ring : p.outline) outline.push_back(ringJson(ring, false));
  nlohmann::json place = {{"id", p.id},
                          {"area_m2", p.area_m2},
                          {"centroid", p.area_m2 > 0 ? xy(p.centroid) : nlohmann::json()},
                          {"label_point", p.area_m2 > 0 ? xy(p.label_point) : nlohmann::json()},
                          {"bbox", bboxJson(p.bbox)},
                          {"neighbours", p.neighbours},
                          {"outline", std::move(outline)}};
  if (with_members) place["members"] = p.members;
  return place;
}

nlohmann::json doorJson(const Door& d) {
  return {{"places", {d.place_a, d.place_b}},
          {"midpoint", xy(d.midpoint)},
          {"width_m", d.width_m},
          {"segment", {xy(d.end_a), xy(d.end_b)}}};
}

}  // namespace

std::string placesJson(const PlaceMap& map) {
  std::vector<nlohmann::json> places, doors;
  for (const Place& p : map.places) places.push_back(placeJson(p, true));
  for (const Door& d : map.doors) doors.push_back(doorJson(d));
  return "{\n" + linesOf("places", places, false) + linesOf("doors", doors, false) +
         "  \"grid\": " + gridJson(map).dump() + "\n}\n";
}

nlohmann::json placeOutlinesJson(const PlaceMap& map) {
  nlohmann::json places = nlohmann::json::array(), doors = nlohmann::json::array();
  for (const Place& p : map.places) places.push_back(placeJson(p, false));
  for (const Door& d : map.doors) doors.push_back(doorJson(d));
  return {{"places", std::move(places)}, {"doors", std::move(doors)}};
}

std::string placesGeoJson(const PlaceMap& map) {
  std::vector<nlohmann::json> features;
  for (const Place& p : map.places) {
    nlohmann::json polygons = nlohmann::json::array();
    for (const auto& rings : polygonsOf(p.outline)) {
      nlohmann::json polygon = nlohmann::json::array();
      for (std::size_t r : rings) polygon.push_back(ringJson(p.outline[r], true));
      polygons.push_back(polygon);
    }
    features.push_back({{"type", "Feature"},
                        {"id", p.id},
                        {"properties",
                         {{"kind", "place"},
                          {"id", p.id},
                          {"area_m2", p.area_m2},
                          {"observations", p.members.size()},
                          {"neighbours", p.neighbours}}},
                        {"geometry", {{"type", "MultiPolygon"}, {"coordinates", polygons}}}});
  }
  for (const Door& d : map.doors)
    features.push_back({{"type", "Feature"},
                        {"properties", {{"kind", "door"}, {"places", {d.place_a, d.place_b}}, {"width_m", d.width_m}}},
                        {"geometry", {{"type", "LineString"}, {"coordinates", {xy(d.end_a), xy(d.end_b)}}}}});
  std::string out = "{\"type\": \"FeatureCollection\",\n \"features\": [";
  for (std::size_t k = 0; k < features.size(); ++k) out += (k ? ",\n  " : "\n  ") + features[k].dump();
  return out + (features.empty() ? "]}\n" : "\n ]}\n");
}

std::string mapYaml(const PlaceMap& map, const std::string& image, const std::string& mode) {
  std::ostringstream out;
  out.precision(17);
  out << "image: " << image << "\n"
      << "mode: " << mode << "\n"
      << "resolution: " << map.grid.resolution << "\n"
      << "origin: [" << map.grid.origin.x() << ", " << map.grid.origin.y() << ", 0.0]\n"
      << "negate: 0\n"
      << "occupied_thresh: 0.65\n"
      << "free_thresh: 0.196\n";
  return out.str();
}

void writePlaceLabels(const std::string& path, const PlaceMap& map) {
  const int width = std::max(1, map.grid.width), height = std::max(1, map.grid.height);
  int largest = -1;
  for (int l : map.labels) largest = std::max(largest, l);
  if (largest + 1 > 65535) throw std::runtime_error(path + ": more than 65534 place ids for a 16-bit label map");
  const int bit_depth = largest + 1 > 255 ? 16 : 8;
  const std::size_t bytes_per_row = std::size_t(width) * (bit_depth == 16 ? 2 : 1);
  std::vector<png_byte> pixels(bytes_per_row * std::size_t(height), 0);
  for (int r = 0; r < height; ++r) {
    const int j = map.grid.height - 1 - r;  // the top row is the grid's highest
    png_byte* row = pixels.data() + std::size_t(r) * bytes_per_row;
    for (int i = 0; j >= 0 && i < map.grid.width; ++i) {
      const int value = map.labels[map.grid.index(i, j)] + 1;
      if (bit_depth == 16) {
        row[2 * i] = png_byte(value >> 8);  // big-endian, as PNG stores it
        row[2 * i + 1] = png_byte(value & 0xff);
      } else {
        row[i] = png_byte(value);
      }
    }
  }
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) throw std::runtime_error(path + ": cannot write");
  const bool written =
      render::writePngRows(file, width, height, bit_depth, render::PngPixels::Grey, pixels.data(), bytes_per_row, false);
  if (std::fclose(file) != 0 || !written) throw std::runtime_error(path + ": cannot write the label map");
}

void writeOccupancyPgm(const std::string& path, const PlaceMap& map) {
  const int width = std::max(1, map.grid.width), height = std::max(1, map.grid.height);
  std::ofstream out(path, std::ios::binary);
  out << "P5\n" << width << " " << height << "\n255\n";
  std::vector<char> row(std::size_t(width), char(205));
  for (int r = 0; r < height; ++r) {
    const int j = map.grid.height - 1 - r;
    for (int i = 0; i < width; ++i) {
      const Occupancy o = j >= 0 && i < map.grid.width ? map.occupancy[map.grid.index(i, j)] : Occupancy::Unknown;
      row[i] = char(o == Occupancy::Occupied ? 0 : o == Occupancy::Free ? 254 : 205);
    }
    out.write(row.data(), std::streamsize(row.size()));
  }
  if (!out.flush()) throw std::runtime_error(path + ": cannot write");
}

namespace {

struct GreyImage {
  png_uint_32 width = 0, height = 0;
  int bit_depth = 0, colour_type = 0;
  bool interlaced = false;
};

/// Reads a PNG's header and, when it is one grey channel of 8 or 16 bits,
/// its rows into `pixels` (which the caller sized from a first call with
/// pixels == nullptr). libpng reports errors by longjmp: nothing here needs
/// a destructor. Returns false on a decoding error.
bool readGreyPng(std::FILE* file, GreyImage& image, png_byte* pixels, std::size_t bytes_per_row) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_init_io(png, file);
  // The label map of a long route is wider than libpng's default limit of a
  // million pixels; readPlaceLabels bounds the pixels instead.
  png_set_user_limits(png, PNG_UINT_31_MAX, PNG_UINT_31_MAX);
  png_read_info(png, info);
  image.width = png_get_image_width(png, info);
  image.height = png_get_image_height(png, info);
  image.bit_depth = png_get_bit_depth(png, info);
  image.colour_type = png_get_color_type(png, info);
  image.interlaced = png_get_interlace_type(png, info) != PNG_INTERLACE_NONE;
  if (pixels && !image.interlaced && image.colour_type == PNG_COLOR_TYPE_GRAY &&
      (image.bit_depth == 8 || image.bit_depth == 16))
    for (png_uint_32 r = 0; r < image.height; ++r) png_read_row(png, pixels + std::size_t(r) * bytes_per_row, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

}  // namespace

PlaceMap readPlaceLabels(const std::string& folder) {
  namespace fs = std::filesystem;
  const fs::path yaml_path = fs::path(folder) / "places.yaml";
  if (!fs::is_regular_file(yaml_path))
    throw UsageError(folder + " holds no obsgroup places (no places.yaml): give the output folder of "
                              "`obsgroup partition` or `obsgroup stream`");
  const std::string yaml = yaml_path.string();
  std::ifstream in(yaml);
  std::string image;
  std::optional<double> resolution;
  std::optional<Eigen::Vector2d> origin;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::size_t colon = line.find(':');
    if (line.empty() || line[0] == '#' || colon == std::string::npos) continue;
    const std::string key = line.substr(0, colon);
    std::string value = line.substr(colon + 1);
    value.erase(0, value.find_first_not_of(' '));
    const std::string where = yaml + ":" + std::to_string(number) + ": " + key;
    if (key == "image") {
      image = value;
    } else if (key == "resolution") {
      char* end = nullptr;
      errno = 0;
      const double r = std::strtod(value.c_str(), &end);
      if (end == value.c_str() || errno == ERANGE || !(r > 0) || !std::isfinite(r))
        throw InputError(where + ": '" + value + "' is not a resolution > 0");
      resolution = r;
    } else if (key == "origin") {
      double x = 0, y = 0, yaw = 0;
      if (std::sscanf(value.c_str(), "[%lf , %lf , %lf]", &x, &y, &yaw) != 3 || !std::isfinite(x) ||
          !std::isfinite(y))
        throw InputError(where + ": '" + value + "' is not [x, y, yaw]");
      if (yaw != 0) throw InputError(where + ": a rotated map (yaw " + value + ") is not one obsgroup wrote");
      origin = Eigen::Vector2d(x, y);
    }
  }
  if (image.empty() || !resolution || !origin)
    throw InputError(yaml + ": image, resolution and origin are required (map_server's YAML)");
  const std::string png_path = (fs::path(folder) / image).string();
  std::FILE* file = std::fopen(png_path.c_str(), "rb");
  if (!file) throw InputError(png_path + ": cannot open the label map");
  GreyImage header;
  const bool read_header = readGreyPng(file, header, nullptr, 0);
  if (!read_header || header.colour_type != PNG_COLOR_TYPE_GRAY || (header.bit_depth != 8 && header.bit_depth != 16) ||
      header.interlaced || header.width == 0 || header.height == 0 ||
      std::size_t(header.width) * header.height > std::size_t(400000000)) {
    std::fclose(file);
    throw InputError(png_path + ": not a label map obsgroup writes (one channel, 8 or 16 bits, not interlaced, at "
                                "most 400 million pixels)");
  }
  const std::size_t bytes_per_row = std::size_t(header.width) * (header.bit_depth == 16 ? 2 : 1);
  std::vector<png_byte> pixels(bytes_per_row * header.height);
  std::rewind(file);
  GreyImage again;
  const bool read = readGreyPng(file, again, pixels.data(), bytes_per_row);
  std::fclose(file);
  if (!read) throw InputError(png_path + ": the PNG data are damaged");
  PlaceMap map;
  map.grid.resolution = *resolution;
  map.grid.origin = *origin;
  map.grid.width = int(header.width);
  map.grid.height = int(header.height);
  map.labels.assign(std::size_t(header.width) * header.height, -1);
  for (int r = 0; r < map.grid.height; ++r) {
    const png_byte* row = pixels.data() + std::size_t(r) * bytes_per_row;
    const int j = map.grid.height - 1 - r;  // the top row is the grid's highest
    for (int i = 0; i < map.grid.width; ++i) {
      const int value = header.bit_depth == 16 ? (row[2 * i] << 8) | row[2 * i + 1] : row[i];
      map.labels[map.grid.index(i, j)] = value - 1;
    }
  }
  return map;
}

}  // namespace obsgroup::io
