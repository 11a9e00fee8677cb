#pragma once
// A PNG file's pixels for tests that check what a picture shows (libpng's simplified API): the
// run folder's maps, the report's screenshot.

#include <png.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace pitchlab::test_support {

/// 8-bit RGB pixels, row by row; width 0 when the file could not be read.
struct Rgb8 {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
  /// Pixels of exactly the colour `c`.
  int Count(std::array<int, 3> c) const {
    int n = 0;
    for (std::size_t k = 0; k + 2 < rgb.size(); k += 3)
      n += rgb[k] == c[0] && rgb[k + 1] == c[1] && rgb[k + 2] == c[2];
    return n;
  }
};

inline Rgb8 ReadPng(const std::filesystem::path& file) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  Rgb8 out;
  if (!png_image_begin_read_from_file(&image, file.c_str())) return out;
  image.format = PNG_FORMAT_RGB;
  out.rgb.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr)) return {};
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  return out;
}

}  // namespace pitchlab::test_support
