#pragma once
// Rows of pixels to a PNG file with libpng: the command's pictures and its
// place label map.

#include <png.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <utility>
#include <vector>

namespace obsgroup::render {

/// How the rows given to writePngRows lie in memory.
enum class PngPixels {
  Grey,       ///< one channel of `bit_depth` bits (16-bit samples big-endian, as PNG stores them)
  Rgba,       ///< 8-bit R, G, B, A
  OpaqueBgrx  ///< cairo's opaque ARGB32 on a little-endian machine: B, G, R, unused; written as RGB
};

/// Writes `height` rows of `row_bytes` each, top first, to `file`. `fast`:
/// zlib level 1 and the Sub filter, which suit flat drawings (cairo's own
/// writer, at the default level with every filter tried, spent most of a
/// run's picture time compressing); otherwise libpng's defaults. libpng
/// reports errors by longjmp, so this function holds nothing that needs a
/// destructor; returns false on an error.
inline bool writePngRows(std::FILE* file, int width, int height, int bit_depth, PngPixels pixels,
                         const png_byte* rows, std::size_t row_bytes, bool fast) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, file);
  // A label map one cell a pixel of a long route is wider than libpng's
  // default limit of a million pixels; the format's own is 2^31 - 1.
  png_set_user_limits(png, PNG_UINT_31_MAX, PNG_UINT_31_MAX);
  const int colour = pixels == PngPixels::Grey ? PNG_COLOR_TYPE_GRAY
                     : pixels == PngPixels::Rgba ? PNG_COLOR_TYPE_RGB_ALPHA
                                                 : PNG_COLOR_TYPE_RGB;
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), bit_depth, colour, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (fast) {
    png_set_compression_level(png, 1);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  }
  png_write_info(png, info);
  if (pixels == PngPixels::OpaqueBgrx) {
    png_set_filler(png, 0, PNG_FILLER_AFTER);  // the unused fourth byte of each pixel is dropped
    png_set_bgr(png);
  }
  for (int r = 0; r < height; ++r) png_write_row(png, rows + std::size_t(r) * row_bytes);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

/// An opaque picture as palette indices, one byte a pixel: a third of the
/// bytes of RGB for zlib to compress.
struct IndexedPixels {
  std::vector<png_color> palette;
  std::vector<png_byte> indices;  ///< row by row, `width` a row
};

/// Colours (24-bit) to a count and a palette index: open addressing, for
/// the few hundred colours of a drawing, many times faster per pixel than a
/// node-based map.
class ColourTable {
 public:
  struct Entry {
    std::uint32_t colour = kEmpty;
    std::uint32_t count = 0;
    std::uint16_t order = 0;  ///< the colours in the order they were first met
  };
  static constexpr std::uint32_t kEmpty = 0xffffffffu;  // no 24-bit colour

  ColourTable() : slots_(1024) {}
  Entry& operator[](std::uint32_t colour) {
    std::size_t k = slot(colour);
    if (slots_[k].colour == kEmpty) {
      if (2 * (size_ + 1) > slots_.size()) {
        grow();
        k = slot(colour);
      }
      slots_[k].colour = colour;
      slots_[k].order = std::uint16_t(size_);
      ++size_;
    }
    return slots_[k];
  }
  std::size_t size() const { return size_; }
  const std::vector<Entry>& slots() const { return slots_; }

 private:
  std::size_t slot(std::uint32_t colour) const {
    std::size_t k = (colour * 2654435761u) & (slots_.size() - 1);
    while (slots_[k].colour != kEmpty && slots_[k].colour != colour) k = (k + 1) & (slots_.size() - 1);
    return k;
  }
  void grow() {
    std::vector<Entry> old(slots_.size() * 2);
    old.swap(slots_);
    for (const Entry& e : old)
      if (e.colour != kEmpty) slots_[slot(e.colour)] = e;
  }
  std::vector<Entry> slots_;
  std::size_t size_ = 0;
};

/// The colours of a picture in cairo's ARGB32 words (little-endian: B, G, R,
/// A) as a palette: exact when it has at most 256 colours. Otherwise, with
/// `quantize`, the 256 most frequent (ties: the smaller colour) and every
/// other colour drawn as the nearest of them: in a drawing of a few colours,
/// the rare ones are antialiased edges between them. Without `quantize`, none;
/// none either when a pixel is not opaque.
inline std::optional<IndexedPixels> indexColours(const unsigned char* bgrx, int width, int height,
                                                 std::size_t row_bytes, bool quantize) {
  // One pass over the picture, run by run: each colour counted and each pixel
  // given its colour's order of appearance; the palette index follows from it.
  constexpr std::size_t kMaxColours = 65535;  // orders fit 16 bits; a drawing has a few hundred
  thread_local std::vector<std::uint16_t> order;
  order.resize(std::size_t(width) * height);
  ColourTable table;
  std::vector<std::uint32_t> colours;  // by order
  for (int y = 0; y < height; ++y) {
    const auto* row = reinterpret_cast<const std::uint32_t*>(bgrx + std::size_t(y) * row_bytes);
    std::uint16_t* orders = &order[std::size_t(y) * width];
    int x = 0;
    while (x < width) {
      const std::uint32_t word = row[x];
      if (word >> 24 != 0xffu) return std::nullopt;  // not opaque: no palette
      int end = x + 1;
      while (end < width && row[end] == word) ++end;
      ColourTable::Entry& e = table[word & 0xffffffu];
      if (e.count == 0) colours.push_back(word & 0xffffffu);
      e.count += std::uint32_t(end - x);
      std::fill(orders + x, orders + end, e.order);
      x = end;
    }
    if ((!quantize && table.size() > 256) || table.size() > kMaxColours) return std::nullopt;
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> by_count;  // (count, colour)
  for (std::uint32_t c : colours) by_count.push_back({table[c].count, c});
  std::sort(by_count.begin(), by_count.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  const std::size_t kept = std::min<std::size_t>(256, by_count.size());
  IndexedPixels out;
  std::vector<png_byte> index_of_order(colours.size(), 0);
  for (std::size_t k = 0; k < kept; ++k) {
    const std::uint32_t c = by_count[k].second;
    out.palette.push_back({png_byte(c >> 16), png_byte(c >> 8), png_byte(c)});
    index_of_order[table[c].order] = png_byte(k);
  }
  for (std::size_t k = kept; k < by_count.size(); ++k) {  // the nearest kept colour
    const std::uint32_t c = by_count[k].second;
    long best_distance = -1;
    png_byte best = 0;
    for (std::size_t j = 0; j < kept; ++j) {
      const long dr = long(c >> 16 & 0xff) - out.palette[j].red, dg = long(c >> 8 & 0xff) - out.palette[j].green,
                 db = long(c & 0xff) - out.palette[j].blue;
      const long distance = dr * dr + dg * dg + db * db;
      if (best_distance < 0 || distance < best_distance) best_distance = distance, best = png_byte(j);
    }
    index_of_order[table[c].order] = best;
  }
  out.indices.resize(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) out.indices[i] = index_of_order[order[i]];
  return out;
}

/// An 8-bit palette PNG of `pixels` (indexColours), zlib level 1 and no
/// filter (the PNG specification's advice for palette images). Returns false
/// on an error.
inline bool writePalettePng(std::FILE* file, int width, int height, const IndexedPixels& pixels) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, file);
  png_set_user_limits(png, PNG_UINT_31_MAX, PNG_UINT_31_MAX);  // as writePngRows
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8, PNG_COLOR_TYPE_PALETTE, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_PLTE(png, info, pixels.palette.data(), int(pixels.palette.size()));
  png_set_compression_level(png, 1);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
  png_write_info(png, info);
  for (int r = 0; r < height; ++r) png_write_row(png, &pixels.indices[std::size_t(r) * width]);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace obsgroup::render
