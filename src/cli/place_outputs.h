#pragma once
// The places of a run as files a robot's software loads: places.json and
// places.geojson (outlines, doors), places.png + places.yaml (a label map in
// ROS map_server's format) and occupancy.pgm + occupancy.yaml (the
// occupancy map of all observations, on the same grid).

#include <obsgroup/places/place_map.h>

#include <nlohmann/json.hpp>

#include <string>

namespace obsgroup::io {

/// {"places": [{"id", "members", "outline", "area_m2", "centroid", "bbox",
/// "neighbours"}], "doors": [{"places", "midpoint", "width_m", "segment"}],
/// "grid": {...}}: coordinates in the map's frame, metres.
std::string placesJson(const PlaceMap& map);
/// What report.html shows of the places: {"places": [...], "doors": [...]},
/// each place as in placesJson without its members (the groups hold them).
nlohmann::json placeOutlinesJson(const PlaceMap& map);
/// The same outlines (MultiPolygon) and doors (LineString) as a GeoJSON
/// FeatureCollection, the ids as properties; x, y in the map's frame, metres.
std::string placesGeoJson(const PlaceMap& map);
/// map_server's YAML for an image of the map's grid: `mode` is "raw" for
/// the label map (a pixel is its value), "trinary" for the occupancy map.
std::string mapYaml(const PlaceMap& map, const std::string& image, const std::string& mode);
/// The label map: one channel, place id + 1 per pixel (0: no place), 8 bits
/// when every id is below 255, else 16; the top row is the grid's highest.
/// Throws std::runtime_error when the file cannot be written.
void writePlaceLabels(const std::string& path, const PlaceMap& map);
/// Binary PGM: occupied 0, free 254, unknown 205 (map_server's trinary
/// reading of them with occupied_thresh 0.65 and free_thresh 0.196).
void writeOccupancyPgm(const std::string& path, const PlaceMap& map);

/// The label grid of an output folder (places.yaml and the image it names),
/// what PlaceMap::locate needs; the places and doors are left empty. Throws
/// UsageError when the folder holds no places.yaml, InputError naming the
/// file, line and field when it or the image cannot be read.
PlaceMap readPlaceLabels(const std::string& folder);

}  // namespace obsgroup::io
