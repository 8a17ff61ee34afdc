#pragma once
// Rows of pixels to a PNG file with libpng: the command's pictures and its
// place label map.

#include <png.h>

#include <cstddef>
#include <cstdio>

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

}  // namespace obsgroup::render
