// The map picture: colour by height, hillshade, unknown and drops distinct; PNG through libpng.

#include <png.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "pitchlab/mapping/elevation_io.hpp"

namespace pitchlab::mapping {

std::array<double, 3> ElevationRamp(double t) {
  static constexpr double kStops[][4] = {{0.00, 40, 70, 160},
                                         {0.25, 60, 150, 90},
                                         {0.50, 170, 190, 90},
                                         {0.75, 150, 100, 60},
                                         {1.00, 250, 250, 250}};
  t = std::clamp(t, 0.0, 1.0);
  for (int s = 1; s < 5; ++s) {
    if (t <= kStops[s][0]) {
      const double u = (t - kStops[s - 1][0]) / (kStops[s][0] - kStops[s - 1][0]);
      return {kStops[s - 1][1] + u * (kStops[s][1] - kStops[s - 1][1]),
              kStops[s - 1][2] + u * (kStops[s][2] - kStops[s - 1][2]),
              kStops[s - 1][3] + u * (kStops[s][3] - kStops[s - 1][3])};
    }
  }
  return {250, 250, 250};
}

std::pair<double, double> ElevationRampRange(const ElevationLayers& L) {
  std::vector<float> z;
  for (std::size_t k = 0; k < L.mean_z.size(); ++k)
    if (L.state[k] == CellState::kObserved) z.push_back(L.mean_z[k]);
  if (z.empty()) return {0.0, 1.0};
  const auto at = [&](double q) {
    auto it = z.begin() + static_cast<std::ptrdiff_t>(q * (z.size() - 1));
    std::nth_element(z.begin(), it, z.end());
    return static_cast<double>(*it);
  };
  const double lo = at(0.02), hi = at(0.98);
  return {lo, hi > lo ? hi : lo + 1.0};
}

namespace {

// Hillshade in [0, 1] of cell (i, j) from central differences of known neighbours (Horn-like).
double Hillshade(const ElevationLayers& L, int i, int j, const ImageOptions& o) {
  const GridGeometry& g = L.geometry;
  const auto z = [&](int a, int b, double fallback) {
    const CellIndex c{a, b};
    if (!g.Contains(c)) return fallback;
    const std::size_t k = g.Linear(c);
    return L.state[k] == CellState::kObserved ? static_cast<double>(L.mean_z[k]) : fallback;
  };
  const double z0 = z(i, j, 0.0);
  const double dzdx = (z(i + 1, j, z0) - z(i - 1, j, z0)) / (2 * g.cell_m) * o.z_exaggeration;
  const double dzdy = (z(i, j + 1, z0) - z(i, j - 1, z0)) / (2 * g.cell_m) * o.z_exaggeration;
  const double az = o.sun_azimuth_deg * M_PI / 180.0, alt = o.sun_altitude_deg * M_PI / 180.0;
  // Light direction: azimuth clockwise from north (y), elevation alt.
  const double lx = std::sin(az) * std::cos(alt), ly = std::cos(az) * std::cos(alt),
               lz = std::sin(alt);
  const double norm = std::sqrt(dzdx * dzdx + dzdy * dzdy + 1.0);
  return std::max(0.0, (-dzdx * lx - dzdy * ly + lz) / norm);
}

}  // namespace

void RgbImage::Set(int x, int y, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  if (x < 0 || y < 0 || x >= width || y >= height) return;
  std::uint8_t* p = &rgb[(static_cast<std::size_t>(y) * width + x) * 3];
  p[0] = r;
  p[1] = g;
  p[2] = b;
}

RgbImage RenderElevationImage(const ElevationLayers& L, const ImageOptions& o) {
  const GridGeometry& g = L.geometry;
  int ppc = o.pixels_per_cell;
  if (ppc <= 0) ppc = std::max(1, o.max_side_px / std::max(g.size_x, g.size_y));
  RgbImage img;
  img.pixels_per_cell = ppc;
  img.width = g.size_x * ppc;
  img.height = g.size_y * ppc;
  img.rgb.assign(static_cast<std::size_t>(img.width) * img.height * 3, 0);
  const auto [lo, hi] = ElevationRampRange(L);
  for (int j = 0; j < g.size_y; ++j) {
    for (int i = 0; i < g.size_x; ++i) {
      const std::size_t k = g.Linear({i, j});
      std::array<double, 3> c;
      if (L.state[k] == CellState::kObserved) {
        const double shade = 0.35 + 0.65 * Hillshade(L, i, j, o);
        c = ElevationRamp((L.mean_z[k] - lo) / (hi - lo));
        for (double& v : c) v *= shade;
      } else if (L.state[k] == CellState::kDrop) {
        c = {220, 0, 220};
      } else {
        const bool dark = ((i / 4) + (j / 4)) % 2;  // checkerboard of 4-cell squares
        c = dark ? std::array<double, 3>{150, 150, 150} : std::array<double, 3>{200, 200, 200};
      }
      const int y0 = (g.size_y - 1 - j) * ppc, x0 = i * ppc;  // north up
      for (int dy = 0; dy < ppc; ++dy)
        for (int dx = 0; dx < ppc; ++dx)
          img.Set(x0 + dx, y0 + dy, static_cast<std::uint8_t>(std::clamp(c[0], 0.0, 255.0)),
                  static_cast<std::uint8_t>(std::clamp(c[1], 0.0, 255.0)),
                  static_cast<std::uint8_t>(std::clamp(c[2], 0.0, 255.0)));
    }
  }
  return img;
}

Eigen::Vector2d MapToPixel(const GridGeometry& g, const RgbImage& image, double x_m, double y_m) {
  const double ppm = image.pixels_per_cell / g.cell_m;
  return {(x_m - g.x_min_m) * ppm, (g.y_max_m() - y_m) * ppm};
}

Result<void> WritePng(const RgbImage& image, const std::string& path) {
  const std::string tmp = path + ".tmp";
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) {
    return Fail(Error::Code::kInvalidArgument, path + ": cannot write: " + std::strerror(errno));
  }
  errno = 0;  // what a failed write below sets names the cause (a full disk)
  // libpng's own handlers print to stderr; the error comes back to the caller here instead.
  const auto on_error = [](png_structp p, png_const_charp) { png_longjmp(p, 1); };
  const auto on_warning = [](png_structp, png_const_charp) {};
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, on_error, on_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    const std::string why = errno != 0 ? std::strerror(errno) : "libpng failed";
    std::remove(tmp.c_str());
    return Fail(Error::Code::kFailed, path + ": cannot write: " + why);
  }
  png_init_io(png, f);
  // Our pictures draw each map cell as a block of pixels, so most rows repeat the one above: the
  // Up filter alone makes them zeros. libpng's default tries all five filters on every row, which
  // took half the encoding time for files as small (issue 21: an office run's six pictures,
  // 5.7 Mpixel, 217 ms -> 98 ms, 145.6 -> 145.9 kB; a terrain run's four, 3.5 Mpixel,
  // 202 ms -> 101 ms, 451 -> 498 kB). Deflate at level 3, not zlib's default 6: every picture of
  // a run (session 27, the deflate alone, level 6 -> 3) office seed 3 146 -> 68 ms and 624 -> 872
  // kB, urban seed 1 211 -> 102 ms and 2.18 -> 2.48 MB, terrain seed 1 419 -> 205 ms and 3.9 ->
  // 4.6 MB: half the time for 1 % more of a run's folder (20-54 MB, mostly its scans).
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
  png_set_compression_level(png, 3);
  png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y) {
    png_write_row(png,
                  const_cast<png_bytep>(&image.rgb[static_cast<std::size_t>(y) * image.width * 3]));
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fclose(f) != 0) {
    const std::string why = std::strerror(errno);
    std::remove(tmp.c_str());
    return Fail(Error::Code::kFailed, path + ": cannot write: " + why);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return Fail(Error::Code::kFailed, path + ": rename failed: " + ec.message());
  return {};
}

}  // namespace pitchlab::mapping
