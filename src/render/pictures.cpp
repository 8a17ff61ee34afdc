#include "pictures.h"
#include "png_rows.h"

#include <obsgroup/cloud/finite_points.h>
#include <obsgroup/common/parallel_for.h>

#include <cairo-svg.h>
#include <cairo.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <omp.h>

#include <algorithm>
#include <limits>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <exception>
#include <filesystem>
#include <map>
#include <iterator>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>

namespace obsgroup::render {

namespace {

struct Rgb {
  double r, g, b;
};

constexpr int kArcsPerGroup = 3;  ///< map.png shows each group's strongest arcs

/// Colour `index` of the palette: 12 well separated colours (no grey, which
/// the arcs use), then golden-angle hues.
Rgb paletteColour(int index) {
  static const Rgb kPalette[] = {{0.12, 0.47, 0.71}, {1.00, 0.50, 0.05}, {0.17, 0.63, 0.17}, {0.84, 0.15, 0.16},
                                 {0.58, 0.40, 0.74}, {0.55, 0.34, 0.29}, {0.89, 0.47, 0.76}, {0.74, 0.74, 0.13},
                                 {0.09, 0.75, 0.81}, {0.10, 0.15, 0.50}, {0.00, 0.50, 0.42}, {0.60, 0.00, 0.35}};
  if (index < kDistinctColours) return kPalette[index];
  const double h = std::fmod(index * 0.618033988749895, 1.0) * 6.0;
  const double x = 1.0 - std::abs(std::fmod(h, 2.0) - 1.0);
  const double c = 0.8, m = 0.1;
  const int sector = static_cast<int>(h);
  const double rgb[6][3] = {{c, x, 0}, {x, c, 0}, {0, c, x}, {0, x, c}, {x, 0, c}, {c, 0, x}};
  return {rgb[sector][0] * c + m, rgb[sector][1] * c + m, rgb[sector][2] * c + m};
}

}  // namespace

std::string paletteHex(int index) {
  const Rgb c = paletteColour(index);
  const auto byte = [](double v) { return std::clamp(static_cast<int>(std::lround(v * 255.0)), 0, 255); };
  char text[8];
  std::snprintf(text, sizeof text, "#%02x%02x%02x", byte(c.r), byte(c.g), byte(c.b));
  return text;
}

namespace {

Rgb darker(const Rgb& c) { return {c.r * 0.6, c.g * 0.6, c.b * 0.6}; }

using Surface = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using Context = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;
using View = PictureView;

Surface imageSurface(int width, int height) {
  return Surface(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height), cairo_surface_destroy);
}

/// An image surface on this thread's canvas, reused from picture to picture:
/// hundreds of local-map pictures then take their memory once, not a fresh
/// (page-faulted) allocation each. The surface must be gone before the
/// thread's next canvasSurface().
Surface canvasSurface(int width, int height) {
  thread_local std::vector<unsigned char> canvas;
  const int stride = cairo_format_stride_for_width(CAIRO_FORMAT_ARGB32, width);
  canvas.resize(std::size_t(stride) * std::size_t(height));
  return Surface(cairo_image_surface_create_for_data(canvas.data(), CAIRO_FORMAT_ARGB32, width, height, stride),
                 cairo_surface_destroy);
}

/// An ARGB32 image surface as a PNG: an 8-bit palette when every pixel is
/// opaque and it has at most 256 colours (or `quantize`: see indexColours),
/// RGB when it is opaque, else RGBA with cairo's premultiplied alpha undone.
void writePng(const PictureWriter& out, const std::string& name, cairo_surface_t* surface, bool quantize = false) {
  cairo_surface_flush(surface);
  const int width = cairo_image_surface_get_width(surface), height = cairo_image_surface_get_height(surface);
  const int stride = cairo_image_surface_get_stride(surface);
  const unsigned char* data = cairo_image_surface_get_data(surface);
  constexpr bool little_endian = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;
  const std::optional<IndexedPixels> indexed =
      little_endian ? indexColours(data, width, height, std::size_t(stride), quantize) : std::nullopt;
  bool opaque = true;  // so is every picture with a palette
  for (int y = 0; y < height && opaque && !indexed; ++y)
    for (int x = 0; x < width && opaque; ++x)
      opaque = (reinterpret_cast<const std::uint32_t*>(data + y * stride)[x] >> 24) == 0xff;
  // An opaque little-endian surface is written from its own rows; otherwise
  // as RGBA with cairo's premultiplied alpha undone.
  const bool as_is = indexed || (opaque && little_endian);
  std::vector<png_byte> pixels;
  if (!as_is) {
    pixels.resize(std::size_t(width) * height * 4);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const std::uint32_t argb = reinterpret_cast<const std::uint32_t*>(data + y * stride)[x];
        const unsigned a = argb >> 24;
        png_byte* p = &pixels[(std::size_t(y) * width + x) * 4];
        for (int c = 0; c < 3; ++c) {
          const unsigned value = (argb >> (16 - 8 * c)) & 0xff;
          p[c] = png_byte(a == 0 ? 0 : std::min(255u, (value * 255 + a / 2) / a));
        }
        p[3] = png_byte(a);
      }
  }
  out(name, [&](const std::string& temporary) {
    std::FILE* file = std::fopen(temporary.c_str(), "wb");
    const bool written =
        file && (indexed ? writePalettePng(file, width, height, *indexed)
                 : as_is ? writePngRows(file, width, height, 8, PngPixels::OpaqueBgrx, data, std::size_t(stride), true)
                         : writePngRows(file, width, height, 8, PngPixels::Rgba, pixels.data(),
                                        std::size_t(width) * 4, true));
    if (file && std::fclose(file) != 0) throw std::runtime_error(temporary + ": cannot write the PNG");
    if (!written) throw std::runtime_error(temporary + ": cannot write the PNG");
  });
}

void setFont(cairo_t* cr, double size) {
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
}

/// A label of an SVG picture, kept as text: cairo's SVG surface would draw
/// its glyphs as outlines, which a reader cannot search, select or copy.
struct SvgText {
  double x, y, size;  ///< baseline start and font size, in the picture's pixels
  double r, g, b;
  std::string text;
};
const cairo_user_data_key_t kSvgTextKey{};

/// Labels drawn on `cr` are recorded into `texts` rather than drawn.
void recordTextInto(cairo_t* cr, std::vector<SvgText>* texts) { cairo_set_user_data(cr, &kSvgTextKey, texts, nullptr); }

/// Draws `s` from (x, y) (its baseline) and returns its width.
double text(cairo_t* cr, double x, double y, const std::string& s, double size = 14) {
  setFont(cr, size);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, s.c_str(), &extents);
  if (auto* texts = static_cast<std::vector<SvgText>*>(cairo_get_user_data(cr, &kSvgTextKey))) {
    double dx = x, dy = y, dsize = size, zero = 0;
    cairo_user_to_device(cr, &dx, &dy);
    cairo_user_to_device_distance(cr, &dsize, &zero);
    double r = 0, g = 0, b = 0, a = 1;
    cairo_pattern_get_rgba(cairo_get_source(cr), &r, &g, &b, &a);
    texts->push_back({dx, dy, dsize, r, g, b, s});
    return extents.x_advance;
  }
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, s.c_str());
  cairo_new_path(cr);
  return extents.x_advance;
}

/// The recorded labels as SVG <text> elements, inserted before the closing
/// tag of the SVG file cairo wrote at `path`.
void insertSvgTexts(const std::string& path, const std::vector<SvgText>& texts) {
  std::string svg;
  {
    std::ifstream in(path, std::ios::binary);
    svg.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::size_t end = svg.rfind("</svg>");
  if (end == std::string::npos) throw std::runtime_error(path + ": cairo wrote no closing </svg>");
  std::string elements = "<g font-family=\"sans-serif\">\n";
  char head[200];
  for (const SvgText& t : texts) {
    std::snprintf(head, sizeof head, "<text x=\"%.2f\" y=\"%.2f\" font-size=\"%.2f\" fill=\"#%02x%02x%02x\">", t.x, t.y,
                  t.size, int(std::lround(t.r * 255)), int(std::lround(t.g * 255)), int(std::lround(t.b * 255)));
    elements += head;
    for (char c : t.text) {
      if (c == '<') elements += "&lt;";
      else if (c == '>') elements += "&gt;";
      else if (c == '&') elements += "&amp;";
      else elements += c;
    }
    elements += "</text>\n";
  }
  elements += "</g>\n";
  svg.insert(end, elements);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << svg;
  if (!out.flush()) throw std::runtime_error(path + ": cannot write the SVG");
}

/// A view of `box` (at least 1 m a side) whose longer side is `longest`
/// pixels, within the margin, with `below` pixels more below for a caption or
/// legend. A picture narrower than `min_width` is widened about the box.
View fitView(Eigen::AlignedBox2d box, double longest, int min_width, int below) {
  if (box.isEmpty()) box.extend(Eigen::Vector2d::Zero());
  const Eigen::Vector2d size = box.sizes().cwiseMax(1.0);
  View v;
  v.scale = longest / size.maxCoeff();
  v.min_x = box.min().x();
  v.max_y = box.max().y();
  v.width = static_cast<int>(std::ceil(size.x() * v.scale + 2 * v.margin));
  v.height = static_cast<int>(std::ceil(size.y() * v.scale + 2 * v.margin + below));
  if (v.width < min_width) {
    v.min_x -= (min_width - v.width) / 2.0 / v.scale;
    v.width = min_width;
  }
  return v;
}

/// The q- and (1-q)-quantiles of `values` (reordered).
std::pair<double, double> quantiles(std::vector<float>& values, double q) {
  const std::size_t lo = std::size_t(q * (values.size() - 1)), hi = values.size() - 1 - lo;
  std::nth_element(values.begin(), values.begin() + lo, values.end());
  const double low = values[lo];
  std::nth_element(values.begin(), values.begin() + hi, values.end());
  return {low, values[hi]};
}

/// The bulk of what is drawn: every position, and the points [begin, end)
/// between the q- and (1-q)-quantiles on each axis (of at most 200000 of
/// them, evenly spaced), grown on each side by 4% of its size on that axis
/// (at least 1 m). A few far returns (through a window, a door) do not set
/// the extent.
Eigen::AlignedBox2d bulkBox(const Eigen::Vector3f* begin, const Eigen::Vector3f* end,
                            const std::vector<Eigen::Vector2d>& positions, double q) {
  Eigen::AlignedBox2d box;
  for (const auto& p : positions) box.extend(p);
  const std::size_t n = std::size_t(end - begin), step = std::max<std::size_t>(1, n / 200000);
  if (n > 0) {
    std::vector<float> xs, ys;
    for (std::size_t k = 0; k < n; k += step) xs.push_back(begin[k].x()), ys.push_back(begin[k].y());
    const auto [x0, x1] = quantiles(xs, q);
    const auto [y0, y1] = quantiles(ys, q);
    box.extend(Eigen::Vector2d(x0, y0));
    box.extend(Eigen::Vector2d(x1, y1));
  }
  if (box.isEmpty()) return box;
  const Eigen::Array2d grow = (0.04 * box.sizes().array()).max(1.0);
  return Eigen::AlignedBox2d(box.min().array() - grow, box.max().array() + grow);
}

std::uint32_t argbOf(const Rgb& c) {
  return 0xff000000u | (std::uint32_t(c.r * 255) << 16) | (std::uint32_t(c.g * 255) << 8) | std::uint32_t(c.b * 255);
}

Rgb pale(const Rgb& c) { return {0.72 + 0.28 * c.r, 0.72 + 0.28 * c.g, 0.72 + 0.28 * c.b}; }

/// Fills the `half`-pixel square about (cx, cy) of an image surface's pixels.
void fillSquare(const View& v, int cx, int cy, int half, std::uint32_t argb, unsigned char* data, int stride) {
  for (int y = std::max(0, cy - half); y < std::min(v.height, cy + half); ++y)
    for (int x = std::max(0, cx - half); x < std::min(v.width, cx + half); ++x)
      reinterpret_cast<std::uint32_t*>(data + y * stride)[x] = argb;
}

/// Each region cell in a pale shade of the group the largest share of whose
/// observations hold it (ties: the lower group), the rule of the places'
/// floor (buildPlaceMap). Cells of 3D regions are seen from above.
void tintRegions(const ObservationRegions& regions, const Partition& partition, const std::vector<int>& colours,
                 const View& v, unsigned char* data, int stride) {
  std::vector<std::pair<std::uint64_t, int>> cells;  // (plane cell, group)
  cells.reserve(regions.totalCells());
  for (int i = 0; i < regions.size(); ++i)
    regions.forEachCell(i, [&](std::uint64_t key) {
      const Eigen::Vector3d c = regions.cellCentre(key);
      const std::uint64_t px = std::uint64_t(std::uint32_t(std::lround(v.px(c.x()))));
      const std::uint64_t py = std::uint64_t(std::uint32_t(std::lround(v.py(c.y()))));
      cells.emplace_back((px << 32) | py, partition.group_of[i]);
    });
  std::sort(cells.begin(), cells.end());
  const int half = std::max(1, int(std::ceil(regions.cell_size * v.scale / 2)));
  for (std::size_t a = 0; a < cells.size();) {
    int best = -1;
    std::size_t best_count = 0;
    std::size_t b = a;
    while (b < cells.size() && cells[b].first == cells[a].first) {
      std::size_t e = b;
      while (e < cells.size() && cells[e] == cells[b]) ++e;
      const std::size_t g = std::size_t(cells[b].second);
      if (best < 0 || (e - b) * partition.groups[std::size_t(best)].size() > best_count * partition.groups[g].size())
        best = cells[b].second, best_count = e - b;
      b = e;
    }
    const int cx = int(std::int32_t(cells[a].first >> 32)), cy = int(std::int32_t(cells[a].first & 0xffffffffu));
    fillSquare(v, cx, cy, half, argbOf(pale(paletteColour(colours[best]))), data, stride);
    a = b;
  }
}

/// Each cell of a place's floor in a pale shade of its group's colour (place
/// g of group g): only where the place's observations saw free floor, not
/// the wedges a view reaches through a door (buildPlaceMap drops them).
/// The places are in the world frame; the view is re-centred on `origin`.
void tintPlaces(const PlaceMap& places, const std::vector<int>& colours, const Eigen::Vector3d& origin,
                const View& v, unsigned char* data, int stride) {
  std::map<int, std::size_t> index_of;
  for (std::size_t g = 0; g < places.places.size() && g < colours.size(); ++g) index_of[places.places[g].id] = g;
  const FloorGrid& grid = places.grid;
  const double cell = grid.resolution * v.scale;
  for (int j = 0; j < grid.height; ++j)
    for (int i = 0; i < grid.width; ++i) {
      const auto it = index_of.find(places.labels[grid.index(i, j)]);
      if (it == index_of.end()) continue;
      const Eigen::Vector2d c = grid.cellCentre(i, j);
      const double x0 = v.px(c.x() - origin.x()) - cell / 2, y0 = v.py(c.y() - origin.y()) - cell / 2;
      const std::uint32_t argb = argbOf(pale(paletteColour(colours[it->second])));
      // Cells tile the picture: each fills the pixels whose centres it holds.
      for (int y = std::max(0, int(std::ceil(y0 - 0.5))); y < std::min(v.height, int(std::ceil(y0 + cell - 0.5))); ++y)
        for (int x = std::max(0, int(std::ceil(x0 - 0.5))); x < std::min(v.width, int(std::ceil(x0 + cell - 0.5))); ++x)
          reinterpret_cast<std::uint32_t*>(data + y * stride)[x] = argb;
    }
}

/// One pixel per point, or a 2x2 block when they are few (fewer than 300000).
int dotSize(std::size_t points) { return points < 300000 ? 2 : 1; }

/// Points [begin, end) seen from above, `dot` pixels square each, into an
/// image surface's pixels; those outside the picture are left out.
void plotPoints(const View& v, const Eigen::Vector3f* begin, const Eigen::Vector3f* end, std::uint32_t argb, int dot,
                unsigned char* data, int stride) {
  for (const Eigen::Vector3f* p = begin; p != end; ++p) {
    const double fx = v.px(p->x()), fy = v.py(p->y());
    if (!(fx >= 0 && fy >= 0 && fx < v.width && fy < v.height)) continue;
    const int x = static_cast<int>(fx), y = static_cast<int>(fy);
    for (int dy = 0; dy < dot; ++dy)
      for (int dx = 0; dx < dot; ++dx)
        if (x + dx < v.width && y + dy < v.height)
          reinterpret_cast<std::uint32_t*>(data + (y + dy) * stride)[x + dx] = argb;
  }
}

/// `c` shaded for a height `t` in [0, 1] of the band: pale low, full colour high.
Rgb shadeForHeight(const Rgb& c, double t) {
  const double white = 0.65 * (1.0 - std::clamp(t, 0.0, 1.0));
  return {c.r + (1 - c.r) * white, c.g + (1 - c.g) * white, c.b + (1 - c.b) * white};
}

/// Per pixel, the highest point drawn so far (heights above the sensor, in
/// the band): a point is drawn over another only from above it.
class HeightBuffer {
 public:
  HeightBuffer(const View& v, const HeightBand& band)
      : band_(band), width_(v.width), top_(std::size_t(v.width) * v.height, -std::numeric_limits<float>::infinity()) {}

  /// Plots [begin, end), their sensor `height` above the world's zero, in `c`.
  void plot(const View& v, const Eigen::Vector3f* begin, const Eigen::Vector3f* end, double height, const Rgb& c,
            int dot, unsigned char* data, int stride) {
    const double span = band_.high - band_.low;
    for (const Eigen::Vector3f* p = begin; p != end; ++p) {
      const double above = p->z() - height;
      if (!(above >= band_.low && above <= band_.high)) continue;
      const double fx = v.px(p->x()), fy = v.py(p->y());
      if (!(fx >= 0 && fy >= 0 && fx < v.width && fy < v.height)) continue;
      const int x = static_cast<int>(fx), y = static_cast<int>(fy);
      float& top = top_[std::size_t(y) * width_ + x];
      if (float(above) <= top) continue;
      top = float(above);
      const std::uint32_t argb = argbOf(shadeForHeight(c, span > 0 ? (above - band_.low) / span : 1.0));
      for (int dy = 0; dy < dot; ++dy)
        for (int dx = 0; dx < dot; ++dx)
          if (x + dx < v.width && y + dy < v.height) reinterpret_cast<std::uint32_t*>(data + (y + dy) * stride)[x + dx] = argb;
    }
  }

 private:
  HeightBand band_;
  int width_;
  std::vector<float> top_;
};

/// The points of `world` within the band above their sensor (its height
/// `heights[i]` in `world`'s frame): what a 3D map is framed and drawn from.
WorldPoints withinBand(const WorldPoints& world, const std::vector<double>& heights, const HeightBand& band) {
  WorldPoints kept;
  kept.origin = world.origin;
  kept.boxes = world.boxes;
  kept.offsets.reserve(world.offsets.size());
  for (int i = 0; i < world.size(); ++i) {
    for (const Eigen::Vector3f* p = world.begin(i); p != world.end(i); ++p) {
      const double above = p->z() - heights[std::size_t(i)];
      if (above >= band.low && above <= band.high) kept.points.push_back(*p);
    }
    kept.offsets.push_back(kept.points.size());
  }
  return kept;
}

/// A fresh surface for map.png's drawing above the legend, and its pixels,
/// written directly (cairo_surface_mark_dirty when done).
struct MapRaster {
  explicit MapRaster(const MapLayout& layout)
      : view(layout.view), surface(imageSurface(layout.view.width, layout.legend_top)) {
    view.height = layout.legend_top;
    cairo_surface_flush(surface.get());
    data = cairo_image_surface_get_data(surface.get());
    stride = cairo_image_surface_get_stride(surface.get());
  }
  std::uint32_t& pixel(int x, int y) { return reinterpret_cast<std::uint32_t*>(data + y * stride)[x]; }

  View view;  ///< the layout's, ending at the legend
  Surface surface;
  unsigned char* data = nullptr;
  int stride = 0;
};

/// The points coloured by group over the tinted regions when there are some,
/// on a transparent background above the legend. With a band, each
/// observation's points are drawn by height above its sensor (`heights`).
Surface rasterPoints(const WorldPoints& world, const Partition& partition, const MapLayout& layout,
                     const ObservationRegions* regions, const PlaceMap* places, const HeightBand* band = nullptr,
                     const std::vector<double>& heights = {}) {
  MapRaster raster(layout);
  const View& v = raster.view;
  unsigned char* data = raster.data;
  const int stride = raster.stride;
  if (regions && places)
    tintPlaces(*places, layout.colours, world.origin, v, data, stride);
  else if (regions)
    tintRegions(*regions, partition, layout.colours, v, data, stride);
  const int dot = dotSize(world.points.size());
  if (band) {
    HeightBuffer buffer(v, *band);
    for (int i = 0; i < world.size(); ++i)
      buffer.plot(v, world.begin(i), world.end(i), heights[std::size_t(i)],
                  paletteColour(layout.colours[partition.group_of[i]]), dot, data, stride);
  } else {
    for (int i = 0; i < world.size(); ++i)
      plotPoints(v, world.begin(i), world.end(i), argbOf(paletteColour(layout.colours[partition.group_of[i]])), dot,
                 data, stride);
  }
  cairo_surface_mark_dirty(raster.surface.get());
  return std::move(raster.surface);
}

/// A coarse map's drawing (MapLayout::coarse), opaque, above the legend:
/// each block of `layout.block` pixels that holds observations in the colour
/// of the group with most of them there (ties: the lower group), from pale
/// for one to full colour for the most any block holds (on a log scale);
/// the points over it in translucent grey, darker where more fall.
Surface rasterDensity(const WorldPoints& world, const std::vector<Eigen::Vector2d>& positions,
                      const Partition& partition, const MapLayout& layout) {
  MapRaster raster(layout);
  const View& v = raster.view;
  for (int y = 0; y < v.height; ++y) std::fill_n(&raster.pixel(0, y), v.width, 0xffffffffu);
  const int side = layout.block, columns = (v.width + side - 1) / side;
  std::vector<std::uint64_t> entries;  // (block << 32) | group, one per observation in the picture
  entries.reserve(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const double fx = v.px(positions[i].x()), fy = v.py(positions[i].y());
    if (!(fx >= 0 && fy >= 0 && fx < v.width && fy < v.height)) continue;
    const std::uint64_t block = std::uint64_t(int(fy) / side) * columns + std::uint64_t(int(fx) / side);
    entries.push_back((block << 32) | std::uint32_t(partition.group_of[i]));
  }
  std::sort(entries.begin(), entries.end());
  struct Block {
    std::uint64_t block;
    int group;
    std::size_t count;
  };
  std::vector<Block> blocks;
  std::size_t most = 1;
  for (std::size_t a = 0; a < entries.size();) {
    Block b{entries[a] >> 32, -1, 0};
    std::size_t best = 0;
    while (a < entries.size() && (entries[a] >> 32) == b.block) {
      std::size_t e = a;
      while (e < entries.size() && entries[e] == entries[a]) ++e;
      if (e - a > best) best = e - a, b.group = int(entries[a] & 0xffffffffu);  // ascending: ties keep the lower
      b.count += e - a;
      a = e;
    }
    most = std::max(most, b.count);
    blocks.push_back(b);
  }
  for (const Block& b : blocks) {
    const Rgb c = paletteColour(layout.colours[std::size_t(b.group)]);
    const double t = 0.3 + 0.7 * std::log1p(double(b.count)) / std::log1p(double(most));
    const std::uint32_t argb = argbOf({1 - t + t * c.r, 1 - t + t * c.g, 1 - t + t * c.b});
    const int x0 = int(b.block % columns) * side, y0 = int(b.block / columns) * side;
    for (int y = y0; y < std::min(v.height, y0 + side); ++y)
      for (int x = x0; x < std::min(v.width, x0 + side); ++x) raster.pixel(x, y) = argb;
  }
  for (const Eigen::Vector3f& p : world.points) {
    const double fx = v.px(p.x()), fy = v.py(p.y());
    if (!(fx >= 0 && fy >= 0 && fx < v.width && fy < v.height)) continue;
    std::uint32_t& pixel = raster.pixel(int(fx), int(fy));
    const auto toward_grey = [](std::uint32_t channel) { return (channel * 3 + 0x50) / 4; };  // a quarter of the way
    pixel = 0xff000000u | (toward_grey((pixel >> 16) & 255u) << 16) | (toward_grey((pixel >> 8) & 255u) << 8) |
            toward_grey(pixel & 255u);
  }
  cairo_surface_mark_dirty(raster.surface.get());
  return std::move(raster.surface);
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

/// A bar of a round length (1, 2 or 5 times a power of ten metres) at most
/// `most` pixels long, labelled on its left, its right end at (x1, y).
void drawScaleBar(cairo_t* cr, double scale, double most, double x1, double y) {
  const double metres = most / scale;
  double length = std::pow(10.0, std::floor(std::log10(metres)));
  if (5 * length <= metres) length *= 5;
  else if (2 * length <= metres) length *= 2;
  const double x0 = x1 - length * scale;
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
  setFont(cr, 12);
  cairo_text_extents(cr, label, &extents);
  text(cr, x0 - extents.x_advance - 6, y + 4, label, 12);
}

constexpr int kLegendHeight = 90;  ///< map.png's legend band

/// Sizes of map.png's marks, from the typical distance in pixels between a
/// group centre and the nearest other one: a picture of 10 groups and one
/// of 1,000 are both readable.
struct MarkSizes {
  double label_radius = 11, dot_radius = 5, arc_width = 3, arrow = 10, arrow_width = 1.5;
  double spacing = 60;  ///< median pixels from a group's mark to the nearest other
};

/// Below this median spacing of the group marks, in pixels, a group's dot
/// would cover its neighbours': map.png is drawn coarse (MapLayout::coarse).
constexpr double kCoarseSpacing = 4.0;
constexpr std::size_t kCoarseGroups = 1000;

/// Each centre's distance to the nearest other one, by a kd-tree: a million
/// scans make 50,000 groups, and all pairs would be 2.5 billion distances.
std::vector<double> nearestOtherDistances(const std::vector<Eigen::Vector2d>& centres) {
  if (centres.size() < 2) return {};
  const pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& c : centres) cloud->push_back(pcl::PointXYZ(float(c.x()), float(c.y()), 0.0f));
  pcl::search::KdTree<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  std::vector<double> nearest(centres.size());
  std::vector<int> index;
  std::vector<float> squared;
  for (std::size_t a = 0; a < centres.size(); ++a) {
    // Two neighbours: the first may be the centre itself or another at the same place.
    tree.nearestKSearch(int(a), 2, index, squared);
    double d = 1e300;
    for (int b : index)
      if (b != int(a)) d = std::min(d, (centres[a] - centres[std::size_t(b)]).norm());
    nearest[a] = d;
  }
  return nearest;
}

MarkSizes markSizes(const MapLayout& layout, std::size_t observations) {
  const auto& c = layout.centres;
  std::vector<double> nearest = nearestOtherDistances(c);
  double spacing = 60;
  if (!nearest.empty()) {
    std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
    spacing = nearest[nearest.size() / 2];
  }
  MarkSizes s;
  if (c.size() > 10000) s.label_radius = 16;  // room for five digits
  else if (c.size() > 1000) s.label_radius = 13;  // four
  s.dot_radius = std::clamp(0.3 * spacing, 2.5, 5.0);
  s.arc_width = std::clamp(0.15 * spacing, 1.2, 3.5);
  s.arrow = std::clamp(0.5 * layout.view.scale, 6.0, 12.0);
  s.arrow_width = observations > 500 ? 1.0 : 1.5;
  s.spacing = spacing;
  return s;
}

/// Centre of each group (mean of its members' positions), in pixels.
std::vector<Eigen::Vector2d> groupCentres(const View& v, const std::vector<Eigen::Vector2d>& positions,
                                          const Partition& partition) {
  std::vector<Eigen::Vector2d> centres(partition.groups.size(), Eigen::Vector2d::Zero());
  for (std::size_t g = 0; g < partition.groups.size(); ++g) {
    for (int i : partition.groups[g]) centres[g] += positions[i];
    centres[g] /= double(std::max<std::size_t>(1, partition.groups[g].size()));
    centres[g] = Eigen::Vector2d(v.px(centres[g].x()), v.py(centres[g].y()));
  }
  return centres;
}

/// The arcs of the topology summed between blocks of `layout.arc_block`
/// pixels: one line per pair of blocks, between the mean mark of each
/// block's groups; arcs within one block are left out. Ordered by the pair
/// of blocks (row, column).
std::vector<MapLayout::BlockArc> blockArcs(const MapLayout& layout, const TopologicalMap& topology) {
  const double side = layout.arc_block;
  const auto blockOf = [&](const Eigen::Vector2d& c) {
    return std::pair<long, long>(long(std::floor(c.y() / side)), long(std::floor(c.x() / side)));
  };
  std::map<std::pair<long, long>, std::pair<Eigen::Vector2d, int>> marks;  // block: sum of marks, count
  for (const Eigen::Vector2d& c : layout.centres) {
    auto& [sum, count] = marks.try_emplace(blockOf(c), Eigen::Vector2d::Zero(), 0).first->second;
    sum += c, ++count;
  }
  std::map<std::pair<std::pair<long, long>, std::pair<long, long>>, MapLayout::BlockArc> summed;
  for (const TopologicalArc& arc : topology.arcs) {
    if (arc.from < 0 || arc.to < 0 || std::size_t(std::max(arc.from, arc.to)) >= layout.centres.size()) continue;
    auto a = blockOf(layout.centres[std::size_t(arc.from)]), b = blockOf(layout.centres[std::size_t(arc.to)]);
    if (a == b) continue;
    if (b < a) std::swap(a, b);
    MapLayout::BlockArc& line = summed[{a, b}];
    if (line.arcs == 0) {
      line.from = marks.at(a).first / marks.at(a).second;
      line.to = marks.at(b).first / marks.at(b).second;
    }
    line.weight += arc.weight;
    ++line.arcs;
  }
  std::vector<MapLayout::BlockArc> lines;
  lines.reserve(summed.size());
  for (const auto& entry : summed) lines.push_back(entry.second);
  return lines;
}

/// The summed arcs of a coarse map, thicker and darker for a larger sum.
void drawBlockArcs(cairo_t* cr, const MapLayout& layout) {
  double strongest = 0.0;
  for (const auto& line : layout.coarse_arcs) strongest = std::max(strongest, line.weight);
  for (const auto& line : layout.coarse_arcs) {
    const double strength = strongest > 0.0 ? line.weight / strongest : 0.0;
    // Translucent and thin: on a coarse map the arcs run along the density they join.
    cairo_set_source_rgba(cr, 0.15, 0.15, 0.15, 0.3 + 0.4 * strength);
    cairo_set_line_width(cr, std::max(1.0, 2.5 * std::sqrt(strength)));
    cairo_move_to(cr, line.from.x(), line.from.y());
    cairo_line_to(cr, line.to.x(), line.to.y());
    cairo_stroke(cr);
  }
}

/// Each shown arc as a solid grey line between the group centres, thicker
/// and darker for a larger cut weight (all alike when none overlaps).
void drawArcs(cairo_t* cr, const MapLayout& layout, const TopologicalMap& topology, const MarkSizes& sizes) {
  double strongest = 0.0;
  for (std::size_t a : layout.shown_arcs) strongest = std::max(strongest, topology.arcs[a].weight);
  for (std::size_t a : layout.shown_arcs) {
    const TopologicalArc& arc = topology.arcs[a];
    const double strength = strongest > 0.0 ? arc.weight / strongest : 0.0;
    cairo_set_source_rgba(cr, 0.15, 0.15, 0.15, 0.6 + 0.3 * strength);
    cairo_set_line_width(cr, std::max(1.2, sizes.arc_width * (0.3 + 0.7 * strength)));
    cairo_move_to(cr, layout.centres[arc.from].x(), layout.centres[arc.from].y());
    cairo_line_to(cr, layout.centres[arc.to].x(), layout.centres[arc.to].y());
    cairo_stroke(cr);
  }
}

/// Each pose as an arrow in a darker shade of its group's colour, but one
/// within an arrow's length of the last drawn in its group left out.
void drawPoses(cairo_t* cr, const MapLayout& layout, const std::vector<Eigen::Vector2d>& positions,
               const std::vector<double>& headings, const Partition& partition, const MarkSizes& sizes) {
  const View& v = layout.view;
  std::vector<Eigen::Vector2d> last(partition.groups.size(), Eigen::Vector2d::Constant(-1e9));
  cairo_set_line_width(cr, sizes.arrow_width);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const int g = partition.group_of[i];
    const Eigen::Vector2d p(v.px(positions[i].x()), v.py(positions[i].y()));
    if ((p - last[g]).norm() < sizes.arrow) continue;
    last[g] = p;
    const Rgb c = darker(paletteColour(layout.colours[g]));
    cairo_set_source_rgb(cr, c.r, c.g, c.b);
    arrowPath(cr, p.x(), p.y(), headings[i], sizes.arrow);
    cairo_stroke(cr);
  }
}

/// A group's mark: a white disc ringed in its colour holding its number, or
/// (`label` false) a dot of its colour ringed dark.
void groupMark(cairo_t* cr, double x, double y, int group, const Rgb& c, bool label, const MarkSizes& sizes) {
  cairo_new_path(cr);
  if (!label) {
    cairo_arc(cr, x, y, sizes.dot_radius, 0, 2 * M_PI);
    cairo_set_source_rgb(cr, c.r, c.g, c.b);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
    return;
  }
  const std::string number = std::to_string(group);
  const double size = number.size() > 4 ? 9.5 : number.size() > 3 ? 10 : (number.size() > 2 ? 11 : 13);
  cairo_arc(cr, x, y, sizes.label_radius, 0, 2 * M_PI);
  cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
  cairo_fill_preserve(cr);
  cairo_set_source_rgb(cr, c.r, c.g, c.b);
  cairo_set_line_width(cr, 2);
  cairo_stroke(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  setFont(cr, size);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, number.c_str(), &extents);
  text(cr, x - extents.x_advance / 2, y + size * 0.36, number, size);
}

/// Which groups are numbered: where the numbers fit (the larger groups
/// first, no two numbered circles overlapping, and when the groups are dense
/// a circle's width apart so that the map shows between them).
std::vector<char> numberedGroups(const std::vector<Eigen::Vector2d>& centres, const Partition& partition,
                                 const MarkSizes& sizes) {
  const double gap = (sizes.dot_radius < 5.0 ? 4 : 2) * sizes.label_radius + 1;
  std::vector<int> order(partition.groups.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return partition.groups[a].size() > partition.groups[b].size(); });
  std::vector<char> numbered(order.size(), 0);
  std::vector<int> placed;
  for (int g : order) {
    bool fits = true;
    for (int h : placed) fits = fits && (centres[g] - centres[h]).norm() >= gap;
    if (fits) numbered[g] = 1, placed.push_back(g);
  }
  return numbered;
}

/// The groups' marks: numbered circles (MapLayout::numbered), dots elsewhere
/// (none on a coarse map, where they would cover each other).
void drawGroupMarks(cairo_t* cr, const MapLayout& layout, const MarkSizes& sizes) {
  for (int pass = layout.coarse ? 1 : 0; pass < 2; ++pass)  // dots first, numbers on top
    for (std::size_t g = 0; g < layout.centres.size(); ++g)
      if (bool(layout.numbered[g]) == (pass == 1))
        groupMark(cr, layout.centres[g].x(), layout.centres[g].y(), int(g), paletteColour(layout.colours[g]),
                  layout.numbered[g], sizes);
}

/// What the legend says beside each mark.
struct LegendText {
  std::size_t observations = 0, groups = 0, numbered = 0, arcs = 0, shown_arcs = 0, outside = 0;
  bool regions = false;
  bool places = false;
  bool coarse = false;
  int block = 4, arc_block = 24;
};

/// The legend's first row, at `row`: a group's circle, a dot (when some
/// groups are not numbered), a pose's arrow; the scale bar on the right.
void legendMarks(cairo_t* cr, const View& v, double row, const LegendText& t, const MarkSizes& sizes) {
  const Rgb sample = paletteColour(0);
  groupMark(cr, v.margin + 11, row, 7, sample, true, sizes);
  cairo_set_source_rgb(cr, 0, 0, 0);
  double x = v.margin + 28;
  if (t.coarse) {
    x += text(cr, x, row + 4, "group, numbered where there is room", 12) + 14;
    for (int k = 0; k < 4; ++k) {  // the density scale: one observation to the most
      const double s = 0.3 + 0.7 * k / 3.0;
      cairo_set_source_rgb(cr, 1 - s + s * sample.r, 1 - s + s * sample.g, 1 - s + s * sample.b);
      cairo_rectangle(cr, x + 13 * k, row - 6, 12, 12);
      cairo_fill(cr);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    char density[160];
    std::snprintf(density, sizeof density, "observations per %d-pixel block, pale few to full many, in the colour of the"
                  " group with most there; grey: points", t.block);
    text(cr, x + 58, row + 4, density, 12);
    drawScaleBar(cr, v.scale, std::min(320.0, (v.width - 2 * v.margin) / 4.0), v.width - v.margin, row + 2);
    return;
  }
  x += text(cr, x, row + 4, t.places ? "group, on its floor" : "group, at its observations' mean", 12) + 14;
  if (t.numbered < t.groups) {
    groupMark(cr, x + 5, row, 0, sample, false, sizes);
    cairo_set_source_rgb(cr, 0, 0, 0);
    x += 16 + text(cr, x + 14, row + 4, "group (no room for its number)", 12) + 14;
  }
  const Rgb arrow = darker(sample);
  cairo_set_source_rgb(cr, arrow.r, arrow.g, arrow.b);
  cairo_set_line_width(cr, 1.5);
  arrowPath(cr, x, row, 0.0, 14);
  cairo_stroke(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  text(cr, x + 20, row + 4, "observation pose (thinned where dense)", 12);
  drawScaleBar(cr, v.scale, std::min(320.0, (v.width - 2 * v.margin) / 4.0), v.width - v.margin, row + 2);
}

/// The legend's second row, at `row`: an arc and which are shown, a tinted
/// cell (with regions); then the counts.
void legendArcsAndCounts(cairo_t* cr, const View& v, double row, const LegendText& t) {
  const double x0 = v.margin;
  cairo_set_source_rgba(cr, 0.15, 0.15, 0.15, 0.85);
  cairo_set_line_width(cr, 3);
  cairo_move_to(cr, x0, row);
  cairo_line_to(cr, x0 + 22, row);
  cairo_stroke(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  char arcs[200];
  if (t.coarse)
    std::snprintf(arcs, sizeof arcs, "arcs of the topology summed between %d-pixel blocks, thicker = larger summed cut"
                  " weight (%zu lines for %zu arcs; all in topology.json)", t.arc_block, t.shown_arcs, t.arcs);
  else
    std::snprintf(arcs, sizeof arcs, "arc of the topology, thicker = larger cut weight: the %d strongest of each group"
                  " (%zu of %zu; all in topology.json)", kArcsPerGroup, t.shown_arcs, t.arcs);
  const double x = x0 + 28 + text(cr, x0 + 28, row + 4, arcs, 12) + 14;
  if (t.regions && !t.coarse) {
    const Rgb p = pale(paletteColour(0));
    cairo_set_source_rgb(cr, p.r, p.g, p.b);
    cairo_rectangle(cr, x, row - 6, 12, 12);
    cairo_fill(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    text(cr, x + 18, row + 4,
         t.places ? "each place's floor: free space its observations sensed" : "space sensed, tinted by the group holding it most",
         12);
  }
  char caption[240], outside[64] = "";
  if (t.outside > 0)
    std::snprintf(outside, sizeof outside, "; %zu far point%s outside the picture", t.outside,
                  t.outside == 1 ? "" : "s");
  if (t.coarse)
    std::snprintf(caption, sizeof caption, "%zu observations, %zu groups (%zu numbered): too close together at this scale"
                  " for a mark each, drawn as a density%s%s", t.observations, t.groups, t.numbered,
                  t.places ? "; outlines and doors in places.json" : "", outside);
  else
    std::snprintf(caption, sizeof caption, "%zu observations, %zu groups (%zu numbered); neighbouring groups differ in"
                  " colour%s%s", t.observations, t.groups, t.numbered,
                  t.places ? "; lines: each place's floor, black bars: doors (places.json)" : "", outside);
  text(cr, x0, row + 24, caption, 12);
}

/// The legend band below the drawing: one sample of each mark with what it
/// means, a scale bar, and the counts.
void drawLegend(cairo_t* cr, const MapLayout& layout, const LegendText& t, const MarkSizes& sizes) {
  const View& v = layout.view;
  cairo_set_source_rgb(cr, 0.96, 0.96, 0.96);
  cairo_rectangle(cr, 0, layout.legend_top, v.width, v.height - layout.legend_top);
  cairo_fill(cr);
  legendMarks(cr, v, layout.legend_top + 18, t, sizes);
  legendArcsAndCounts(cr, v, layout.legend_top + 40, t);
}


/// Each place's outline in its group's darker colour, each door a black bar
/// (the places are in the world frame; the view is re-centred on `origin`).
void drawPlaces(cairo_t* cr, const MapLayout& layout, const PlaceMap& places, const Eigen::Vector3d& origin) {
  const PictureView& v = layout.view;
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_MITER);
  cairo_set_line_width(cr, 1.5);
  for (std::size_t g = 0; g < places.places.size() && g < layout.colours.size(); ++g) {
    const Rgb c = darker(paletteColour(layout.colours[g]));
    cairo_set_source_rgb(cr, c.r, c.g, c.b);
    for (const auto& ring : places.places[g].outline) {
      for (std::size_t k = 0; k < ring.size(); ++k) {
        const double x = v.px(ring[k].x() - origin.x()), y = v.py(ring[k].y() - origin.y());
        if (k == 0) cairo_move_to(cr, x, y);
        else cairo_line_to(cr, x, y);
      }
      cairo_close_path(cr);
    }
    cairo_stroke(cr);
  }
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 4.0);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  for (const Door& d : places.doors) {
    cairo_move_to(cr, v.px(d.end_a.x() - origin.x()), v.py(d.end_a.y() - origin.y()));
    cairo_line_to(cr, v.px(d.end_b.x() - origin.x()), v.py(d.end_b.y() - origin.y()));
  }
  cairo_stroke(cr);
}

/// The picture over `points` (the rasterised points), with its legend.
void drawMap(cairo_t* cr, cairo_surface_t* points, const MapLayout& layout,
             const std::vector<Eigen::Vector2d>& positions, const std::vector<double>& headings,
             const Partition& partition, const TopologicalMap& topology, bool regions, const PlaceMap* places,
             const Eigen::Vector3d& origin) {
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_set_source_surface(cr, points, 0, 0);
  cairo_paint(cr);
  const MarkSizes sizes = markSizes(layout, positions.size());
  if (layout.coarse) {  // outlines, doors and arrows would be smaller than a pixel
    drawBlockArcs(cr, layout);
  } else {
    if (places) drawPlaces(cr, layout, *places, origin);
    drawArcs(cr, layout, topology, sizes);
    drawPoses(cr, layout, positions, headings, partition, sizes);
  }
  drawGroupMarks(cr, layout, sizes);
  LegendText legend;
  legend.numbered = std::size_t(std::count(layout.numbered.begin(), layout.numbered.end(), 1));
  legend.observations = positions.size();
  legend.groups = partition.groups.size();
  legend.arcs = topology.arcs.size();
  legend.shown_arcs = layout.coarse ? layout.coarse_arcs.size() : layout.shown_arcs.size();
  legend.outside = layout.points_outside;
  legend.regions = regions;
  legend.places = places != nullptr;
  legend.coarse = layout.coarse;
  legend.block = layout.block;
  legend.arc_block = layout.arc_block;
  drawLegend(cr, layout, legend, sizes);
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

/// The layout of the map of `world` (already at the drawn poses) whose
/// observations are at `positions` (re-centred like `world`).
MapLayout layoutOf(const WorldPoints& world, const std::vector<Eigen::Vector2d>& positions,
                   const Partition& partition, const TopologicalMap& topology, const PlaceMap* places = nullptr) {
  MapLayout layout;
  const Eigen::AlignedBox2d box =
      bulkBox(world.points.data(), world.points.data() + world.points.size(), positions, 0.025);
  // A larger picture for many groups, so that they keep some room each.
  const double longest = std::clamp(1600.0 * std::sqrt(partition.groups.size() / 200.0), 1600.0, 2800.0);
  layout.view = fitView(box, longest, 1100, kLegendHeight);
  layout.legend_top = layout.view.height - kLegendHeight;
  layout.centres = groupCentres(layout.view, positions, partition);
  if (places && places->places.size() == partition.groups.size())  // the number on its tint
    for (std::size_t g = 0; g < partition.groups.size(); ++g)
      if (const Place& place = places->places[g]; place.area_m2 > 0)
        layout.centres[g] = Eigen::Vector2d(layout.view.px(place.label_point.x() - world.origin.x()),
                                            layout.view.py(place.label_point.y() - world.origin.y()));
  layout.colours = groupColours(topology);
  layout.colours.resize(partition.groups.size(), 0);  // a topology of other groups
  layout.shown_arcs = shownArcs(topology, kArcsPerGroup);
  const MarkSizes sizes = markSizes(layout, positions.size());
  layout.label_radius = sizes.label_radius;
  layout.numbered = numberedGroups(layout.centres, partition, sizes);
  layout.spacing = sizes.spacing;
  // Many groups, not a few at one spot (a robot standing still), make a map coarse.
  layout.coarse = layout.centres.size() >= kCoarseGroups && sizes.spacing < kCoarseSpacing;
  if (layout.coarse) layout.coarse_arcs = blockArcs(layout, topology);
  for (const Eigen::Vector3f& p : world.points) {
    const double x = layout.view.px(p.x()), y = layout.view.py(p.y());
    layout.points_outside += !(x >= 0 && y >= 0 && x < layout.view.width && y < layout.legend_top);
  }
  return layout;
}

void planarPoses(const std::vector<Eigen::Isometry3d>& drawn, const Eigen::Vector3d& origin,
                 std::vector<Eigen::Vector2d>& positions, std::vector<double>& headings) {
  positions.resize(drawn.size());
  headings.resize(drawn.size());
  for (std::size_t i = 0; i < drawn.size(); ++i) planarPose(drawn[i], origin, positions[i], headings[i]);
}

/// Each member's pose as an arrow in a darker shade of `c`, the reference's
/// black and longer, in a ring.
void drawMemberPoses(cairo_t* cr, const View& v, const LocalMapFrame& frame, const Rgb& c) {
  const double length = std::clamp(0.5 * v.scale, 10.0, 30.0);
  for (std::size_t k = 0; k < frame.members.size(); ++k) {
    Eigen::Vector2d position;
    double heading;
    planarPose(frame.member_poses[k], Eigen::Vector3d::Zero(), position, heading);
    const double x = v.px(position.x()), y = v.py(position.y());
    if (frame.members[k] != frame.reference) {
      const Rgb d = darker(c);
      cairo_set_source_rgb(cr, d.r, d.g, d.b);
      cairo_set_line_width(cr, 1.5);
      arrowPath(cr, x, y, heading, length);
      cairo_stroke(cr);
      continue;
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 2.5);
    arrowPath(cr, x, y, heading, 1.3 * length);
    cairo_stroke(cr);
    cairo_new_path(cr);
    cairo_arc(cr, x, y, 6, 0, 2 * M_PI);
    cairo_set_line_width(cr, 2);
    cairo_stroke(cr);
  }
}

/// local_maps/group_NNN.png of one local map, whose points (in its frame)
/// are given without the non-finite ones.
/// How far around its members' positions a local map's picture frames the
/// place, metres: the visibility model's default range, how far the
/// grouping itself looks. Returns beyond it (through a door, a window) are
/// ticks on the picture's edge, so that they do not shrink the place.
constexpr double kPlaceReach = 6.0;

/// Points outside the view as ticks on its edge, where a line from the
/// view's centre towards them leaves it, in a darker shade.
std::size_t tickFarPoints(const View& v, const std::vector<Eigen::Vector3f>& points, const Rgb& colour,
                          unsigned char* data, int stride) {
  const std::uint32_t argb = argbOf(darker(colour));
  const double bottom = v.height - 30.0;  // the drawing ends above the caption
  const double cx = v.width / 2.0, cy = bottom / 2.0;
  const double inf = std::numeric_limits<double>::infinity();
  std::size_t ticked = 0;
  for (const Eigen::Vector3f& p : points) {
    const double x = v.px(p.x()), y = v.py(p.y());
    if (x >= 0 && y >= 0 && x < v.width && y < bottom) continue;
    const double dx = x - cx, dy = y - cy;
    const double t = std::min(dx != 0 ? (cx - 2) / std::abs(dx) : inf, dy != 0 ? (cy - 2) / std::abs(dy) : inf);
    const int ex = int(std::clamp(cx + dx * t, 0.0, v.width - 3.0)), ey = int(std::clamp(cy + dy * t, 0.0, bottom - 3.0));
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) reinterpret_cast<std::uint32_t*>(data + (ey + b) * stride)[ex + a] = argb;
    ++ticked;
  }
  return ticked;
}

void writeLocalMapPicture(const PictureWriter& out, int group, const LocalMapFrame& frame,
                          const std::vector<Eigen::Vector3f>& points, const Rgb& colour, const HeightBand* band) {
  std::vector<Eigen::Vector2d> positions(frame.member_poses.size());
  Eigen::AlignedBox2d reach;
  for (std::size_t k = 0; k < positions.size(); ++k) {
    positions[k] = frame.member_poses[k].translation().head<2>();
    reach.extend(positions[k]);
  }
  reach = Eigen::AlignedBox2d(reach.min().array() - kPlaceReach, reach.max().array() + kPlaceReach);
  std::vector<Eigen::Vector3f> near;
  for (const Eigen::Vector3f& p : points)
    if (reach.contains(p.head<2>().cast<double>())) near.push_back(p);
  const View v = fitView(bulkBox(near.data(), near.data() + near.size(), positions, 0.005), 700.0, 640, 20);
  Surface surface = canvasSurface(v.width, v.height);
  Context cr(cairo_create(surface.get()), cairo_destroy);
  cairo_set_source_rgb(cr.get(), 1, 1, 1);
  cairo_paint(cr.get());
  cairo_surface_flush(surface.get());
  unsigned char* data = cairo_image_surface_get_data(surface.get());
  const int stride = cairo_image_surface_get_stride(surface.get());
  if (band)  // the map's frame is its reference sensor's: heights above it
    HeightBuffer(v, *band).plot(v, points.data(), points.data() + points.size(), 0.0, colour, dotSize(points.size()),
                                data, stride);
  else
    plotPoints(v, points.data(), points.data() + points.size(), argbOf(colour), dotSize(points.size()), data, stride);
  const std::size_t ticked = tickFarPoints(v, points, colour, data, stride);
  cairo_surface_mark_dirty(surface.get());
  drawMemberPoses(cr.get(), v, frame, colour);
  drawScaleBar(cr.get(), v.scale, (v.width - 2 * v.margin) / 5.0, v.width - v.margin, v.margin / 2);
  cairo_set_source_rgb(cr.get(), 0, 0, 0);
  char caption[240], far[80] = "";
  if (ticked > 0) std::snprintf(far, sizeof far, " (%zu far: ticks on the edge)", ticked);
  std::snprintf(caption, sizeof caption, "local map %d: %zu observations, %zu points%s; ringed: reference %d", group,
                frame.members.size(), points.size(), far, frame.reference);
  text(cr.get(), v.margin, v.height - 12, caption, 12);
  char name[64];
  std::snprintf(name, sizeof name, "local_maps/group_%03d.png", group);
  // A few colours and their antialiased edges: drawn from a palette, a third of the bytes to compress.
  writePng(out, name, surface.get(), true);
}

}  // namespace

template <typename PointT>
void writeLocalMapPictures(const PictureWriter& out, const std::vector<LocalMap<PointT>>& maps, int threads,
                           const std::vector<int>& colours, const HeightBand* band) {
  parallelFor(maps.size(), threads, [&](std::size_t g) {
    std::vector<Eigen::Vector3f> points;
    if (maps[g].cloud)
      for (const PointT& p : finitePoints(*maps[g].cloud).points)
        if (!band || (p.z >= band->low && p.z <= band->high)) points.emplace_back(p.x, p.y, p.z);
    const int colour = g < colours.size() ? colours[g] : static_cast<int>(g);
    writeLocalMapPicture(out, static_cast<int>(g), maps[g].frame, points, paletteColour(colour), band);
  });
}

template void writeLocalMapPictures(const PictureWriter&, const std::vector<LocalMap<pcl::PointXYZ>>&, int,
                                    const std::vector<int>&, const HeightBand*);
template void writeLocalMapPictures(const PictureWriter&, const std::vector<LocalMap<pcl::PointXYZI>>&, int,
                                    const std::vector<int>&, const HeightBand*);
template void writeLocalMapPictures(const PictureWriter&, const std::vector<LocalMap<pcl::PointXYZRGB>>&, int,
                                    const std::vector<int>&, const HeightBand*);

MapLayout mapLayout(const WorldPoints& world, const std::vector<Eigen::Isometry3d>& poses,
                    const std::vector<Eigen::Isometry3d>& drawn, const Partition& partition,
                    const TopologicalMap& topology) {
  std::vector<Eigen::Vector2d> positions;
  std::vector<double> headings;
  planarPoses(drawn, world.origin, positions, headings);
  return layoutOf(atDrawnPoses(world, poses, drawn), positions, partition, topology);
}

void writeMapPictures(const PictureWriter& out, const WorldPoints& input_world,
                      const std::vector<Eigen::Isometry3d>& poses, const std::vector<Eigen::Isometry3d>& drawn,
                      const Partition& partition, const TopologicalMap& topology, const ObservationRegions* regions,
                      const PlaceMap* places, const HeightBand* band) {
  WorldPoints world = atDrawnPoses(input_world, poses, drawn);
  std::vector<Eigen::Vector2d> positions;
  std::vector<double> headings;
  planarPoses(drawn, world.origin, positions, headings);
  std::vector<double> heights;  // each sensor's, in the frame of `world`
  if (band) {
    for (const auto& pose : drawn) heights.push_back(pose.translation().z() - world.origin.z());
    world = withinBand(world, heights, *band);
  }
  const MapLayout layout = layoutOf(world, positions, partition, topology, places);
  // The regions describe the input poses (they gave W) and stay there.
  const Surface points = layout.coarse ? rasterDensity(world, positions, partition, layout)
                                       : rasterPoints(world, partition, layout, regions, places, band, heights);
  const auto draw = [&](cairo_surface_t* target, std::vector<SvgText>* texts) {
    Context cr(cairo_create(target), cairo_destroy);
    if (texts) recordTextInto(cr.get(), texts);
    drawMap(cr.get(), points.get(), layout, positions, headings, partition, topology, regions != nullptr, places,
            world.origin);
  };
  Surface png = imageSurface(layout.view.width, layout.view.height);
  draw(png.get(), nullptr);
  writePng(out, "map.png", png.get());
  out("map.svg", [&](const std::string& temporary) {
    Surface svg(cairo_svg_surface_create(temporary.c_str(), layout.view.width, layout.view.height),
                cairo_surface_destroy);
    std::vector<SvgText> texts;
    draw(svg.get(), &texts);
    cairo_surface_finish(svg.get());
    if (cairo_surface_status(svg.get()) != CAIRO_STATUS_SUCCESS)
      throw std::runtime_error(temporary + ": cairo cannot write the SVG");
    insertSvgTexts(temporary, texts);
  });
}

namespace {

/// The darkness (W, at most 1) of each pixel of a `side`-pixel square
/// picture of W whose rows and columns are at `position` (order by group).
std::vector<float> weightDarkness(const WeightMatrix& W, const std::vector<int>& position, int side) {
  const double cell = double(side) / W.rows();
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
  return darkness;
}

/// One split's eigenvector in the `w` x `h` box at (ox, oy), its threshold
/// in red, titled.
void drawFiedlerPlot(cairo_t* cr, const SplitNode& node, int index, double ox, double oy, double w, double h) {
  const Eigen::VectorXd& y = node.eigenvector;
  double lo = std::min(y.minCoeff(), node.threshold), hi = std::max(y.maxCoeff(), node.threshold);
  if (hi - lo < 1e-12) hi = lo + 1.0;
  const auto sx = [&](double i) { return ox + (y.size() > 1 ? i / (y.size() - 1) : 0.5) * w; };
  const auto sy = [&](double value) { return oy + h - (value - lo) / (hi - lo) * h; };
  cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
  cairo_set_line_width(cr, 1);
  cairo_rectangle(cr, ox, oy, w, h);
  cairo_stroke(cr);
  cairo_set_source_rgb(cr, 0.12, 0.47, 0.71);
  cairo_set_line_width(cr, 1.2);
  for (Eigen::Index i = 0; i < y.size(); ++i) (i ? cairo_line_to : cairo_move_to)(cr, sx(i), sy(y[i]));
  cairo_stroke(cr);
  for (Eigen::Index i = 0; i < y.size() && y.size() <= 400; ++i) {
    cairo_new_path(cr);
    cairo_arc(cr, sx(i), sy(y[i]), 2.5, 0, 2 * M_PI);
    cairo_fill(cr);
  }
  cairo_set_source_rgb(cr, 0.85, 0.1, 0.1);
  cairo_move_to(cr, ox, sy(node.threshold));
  cairo_line_to(cr, ox + w, sy(node.threshold));
  cairo_stroke(cr);
  char value[32];
  std::snprintf(value, sizeof value, "%.3g", node.threshold);
  text(cr, ox + w - 48, sy(node.threshold) - 4, value, 10);  // inside the plot, above its line
  // The y axis: its ends, and 0 where the range holds it, with ticks.
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1);
  std::vector<double> ticks{lo, hi};
  if (lo < 0 && hi > 0 && std::min(sy(0) - sy(hi), sy(lo) - sy(0)) > 14) ticks.push_back(0.0);
  for (double tick : ticks) {
    cairo_move_to(cr, ox - 4, sy(tick));
    cairo_line_to(cr, ox, sy(tick));
    cairo_stroke(cr);
    std::snprintf(value, sizeof value, "%.3g", tick);
    text(cr, ox - 46, sy(tick) + 4, value, 10);
  }
  char title[200];
  std::snprintf(title, sizeof title, "split %d: %zu observations, Ncut %.3f, %s", index, node.members.size(), node.ncut,
                node.accepted ? "accepted" : "rejected");
  text(cr, ox, oy - 12, title);
  text(cr, ox, oy + h + 20, "observation " + std::to_string(node.members.front()) + " ... " +
                                std::to_string(node.members.back()) + " (in order); red: threshold", 12);
}

}  // namespace

void writeWeightsPicture(const PictureWriter& out, const WeightMatrix& W, const Partition& partition) {
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
  const std::vector<float> darkness = weightDarkness(W, position, side);
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

void writeFiedlerPicture(const PictureWriter& out, const Partition& partition) {
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
  for (std::size_t k = 0; k < shown.size(); ++k)
    drawFiedlerPlot(cr.get(), *shown[k], int(shown[k] - partition.splits.data()), (k % 2) * plot_w + 50,
                    (k / 2) * plot_h + 40, plot_w - 80, plot_h - 80);
  writePng(out, "fiedler.png", surface.get());
}

PictureWriter folderWriter(const std::string& folder) {
  return [folder](const std::string& name, const std::function<void(const std::string& path)>& write) {
    const std::filesystem::path path = std::filesystem::path(folder) / name;
    std::filesystem::create_directories(path.parent_path());
    write(path.string());
  };
}

}  // namespace obsgroup::render
