#pragma once
// Writes PNG files with libpng (the simulated depth images, the readers' tests): any bit depth
// and colour type, so that the wrong kinds can be tested too.

#include <png.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace obsgroup::test {

/// Samples row-major, `channels` per pixel, each in the low `bit_depth`
/// bits. Creates the folder; returns false when the file cannot be written.
inline bool writePng(const std::string& path, int width, int height, const std::vector<std::uint16_t>& samples,
                     int bit_depth = 16, int colour_type = PNG_COLOR_TYPE_GRAY) {
  const int channels = colour_type == PNG_COLOR_TYPE_RGB ? 3 : colour_type == PNG_COLOR_TYPE_RGB_ALPHA ? 4
                       : colour_type == PNG_COLOR_TYPE_GRAY_ALPHA ? 2 : 1;
  std::error_code ec;
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) return false;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  std::vector<png_byte> row(std::size_t(width) * channels * (bit_depth == 16 ? 2 : 1));
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(file);
    return false;
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, width, height, bit_depth, colour_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) {
    for (int k = 0; k < width * channels; ++k) {
      const std::uint16_t s = samples[std::size_t(y) * width * channels + k];
      if (bit_depth == 16) {
        row[2 * k] = png_byte(s >> 8);  // big-endian, as PNG stores it
        row[2 * k + 1] = png_byte(s & 0xff);
      } else {
        row[k] = png_byte(s);
      }
    }
    png_write_row(png, row.data());
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return std::fclose(file) == 0;
}

}  // namespace obsgroup::test
