#include "pitchlab/worlds/dem_projection.hpp"

#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/UTMUPS.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace pitchlab::worlds {
namespace {

// Inclusive cell ranges of the DEM that are free of NODATA.
struct CellRect {
  int row0 = 0, row1 = -1, col0 = 0, col1 = -1;
  long Area() const { return static_cast<long>(row1 - row0 + 1) * (col1 - col0 + 1); }
};

// Largest all-valid rectangle: per row, the run of valid cells above each column forms a
// histogram whose largest rectangle a monotone stack finds in O(ncols).
CellRect LargestValidRectangle(const EsriGrid& dem) {
  std::vector<int> run(dem.ncols + 1, 0);  // sentinel 0 at the end flushes the stack
  CellRect best;
  for (int row = 0; row < dem.nrows; ++row) {
    for (int col = 0; col < dem.ncols; ++col) {
      run[col] = std::isnan(dem.At(row, col)) ? 0 : run[col] + 1;
    }
    std::vector<int> stack;
    for (int col = 0; col <= dem.ncols; ++col) {
      while (!stack.empty() && run[stack.back()] >= run[col]) {
        const int height = run[stack.back()];
        stack.pop_back();
        const int left = stack.empty() ? 0 : stack.back() + 1;
        const CellRect candidate{row - height + 1, row, left, col - 1};
        if (height > 0 && candidate.Area() > best.Area()) best = candidate;
      }
      stack.push_back(col);
    }
  }
  return best;
}

// Catmull-Rom weights for fraction t in [0, 1).
std::array<double, 4> CubicWeights(double t) {
  const double t2 = t * t, t3 = t2 * t;
  return {0.5 * (-t + 2 * t2 - t3), 0.5 * (2 - 5 * t2 + 3 * t3), 0.5 * (t + 4 * t2 - 3 * t3),
          0.5 * (-t2 + t3)};
}

// Bicubic sample at fractional (row, col) cell-centre indices, neighbours clamped to `rect`.
double SampleBicubic(const EsriGrid& dem, const CellRect& rect, double row, double col) {
  row = std::clamp(row, static_cast<double>(rect.row0), static_cast<double>(rect.row1));
  col = std::clamp(col, static_cast<double>(rect.col0), static_cast<double>(rect.col1));
  const int r = static_cast<int>(std::floor(row));
  const int c = static_cast<int>(std::floor(col));
  const auto wr = CubicWeights(row - r);
  const auto wc = CubicWeights(col - c);
  double sum = 0.0;
  for (int i = 0; i < 4; ++i) {
    const int rr = std::clamp(r - 1 + i, rect.row0, rect.row1);
    for (int j = 0; j < 4; ++j) {
      const int cc = std::clamp(c - 1 + j, rect.col0, rect.col1);
      sum += wr[i] * wc[j] * dem.At(rr, cc);
    }
  }
  return sum;
}

// The two directions between the DEM's file coordinates and the local ENU frame.
struct Frame {
  std::function<void(double x_file, double y_file, double& east, double& north)> to_enu;
  std::function<void(double east, double north, double& x_file, double& y_file)> to_file;
  std::optional<GeodeticPoint> origin;
};

Frame MakeFrame(const DemPlacement& placement, double x_center, double y_center) {
  using GeographicLib::LocalCartesian;
  using GeographicLib::UTMUPS;
  Frame frame;
  if (placement.coordinates == DemCoordinates::kLocal) {
    frame.to_enu = [=](double x, double y, double& e, double& n) {
      e = x - x_center, n = y - y_center;
    };
    frame.to_file = [=](double e, double n, double& x, double& y) {
      x = e + x_center, y = n + y_center;
    };
    return frame;
  }
  double lat0 = 0.0, lon0 = 0.0;
  if (placement.coordinates == DemCoordinates::kUtm) {
    UTMUPS::Reverse(placement.utm_zone, placement.northern_hemisphere, x_center, y_center, lat0,
                    lon0);
  } else {
    lon0 = x_center, lat0 = y_center;
  }
  frame.origin = GeodeticPoint{lat0, lon0, 0.0};
  const LocalCartesian local(lat0, lon0, 0.0);
  const bool utm = placement.coordinates == DemCoordinates::kUtm;
  const int zone = placement.utm_zone;
  const bool northp = placement.northern_hemisphere;
  frame.to_enu = [=](double x, double y, double& e, double& n) {
    double lat = y, lon = x, up = 0.0;
    if (utm) UTMUPS::Reverse(zone, northp, x, y, lat, lon);
    local.Forward(lat, lon, 0.0, e, n, up);
  };
  frame.to_file = [=](double e, double n, double& x, double& y) {
    double lat = 0.0, lon = 0.0, h = 0.0;
    local.Reverse(e, n, 0.0, lat, lon, h);
    if (!utm) {
      x = lon, y = lat;
      return;
    }
    int zone_out = 0;
    bool northp_out = true;
    UTMUPS::Forward(lat, lon, zone_out, northp_out, x, y, zone);  // stay in the DEM's zone
  };
  return frame;
}

}  // namespace

DemPlacement ParseUtmZone(const std::string& text) {
  DemPlacement placement;
  placement.coordinates = DemCoordinates::kUtm;
  size_t used = 0;
  int zone = 0;
  try {
    zone = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  const std::string rest = used > 0 ? text.substr(used) : "";
  if (used == 0 || zone < 1 || zone > 60 ||
      (rest != "N" && rest != "n" && rest != "S" && rest != "s")) {
    throw std::invalid_argument("UTM zone '" + text + "': expected 1..60 and N or S, e.g. 13N");
  }
  placement.utm_zone = zone;
  placement.northern_hemisphere = rest == "N" || rest == "n";
  return placement;
}

ProjectedDem ProjectDem(const EsriGrid& dem, const DemPlacement& placement, double cell_m,
                        long max_vertices) {
  if (!(cell_m > 0.0)) throw std::invalid_argument("ProjectDem: cell_m must be > 0");
  const CellRect rect = LargestValidRectangle(dem);
  if (rect.row1 - rect.row0 < 1 || rect.col1 - rect.col0 < 1) {
    throw std::invalid_argument("DEM has no 2 x 2 block of valid (non-NODATA) cells");
  }
  // Local origin: the centre of the valid rectangle (between cell centres).
  const double row_c = 0.5 * (rect.row0 + rect.row1), col_c = 0.5 * (rect.col0 + rect.col1);
  Frame frame = MakeFrame(placement, dem.ColumnX(col_c), dem.RowY(row_c));

  // The metric rectangle inscribed in the projected corners of the valid cell centres.
  double e[4], n[4];
  const int rows[4] = {rect.row1, rect.row1, rect.row0, rect.row0};  // SW, SE, NW, NE
  const int cols[4] = {rect.col0, rect.col1, rect.col0, rect.col1};
  for (int k = 0; k < 4; ++k) frame.to_enu(dem.ColumnX(cols[k]), dem.RowY(rows[k]), e[k], n[k]);
  const double x_min = std::max(e[0], e[2]), x_max = std::min(e[1], e[3]);
  const double y_min = std::max(n[0], n[1]), y_max = std::min(n[2], n[3]);
  const long nx = static_cast<long>(std::floor((x_max - x_min) / cell_m + 1e-9)) + 1;
  const long ny = static_cast<long>(std::floor((y_max - y_min) / cell_m + 1e-9)) + 1;
  if (nx < 2 || ny < 2) throw std::invalid_argument("DEM is smaller than one output cell");
  if (nx * ny > max_vertices) {
    const double smallest = std::sqrt((x_max - x_min) * (y_max - y_min) / max_vertices);
    throw std::invalid_argument("DEM of " + std::to_string(x_max - x_min) + " x " +
                                std::to_string(y_max - y_min) + " m needs a cell of at least " +
                                std::to_string(smallest) + " m, got " + std::to_string(cell_m));
  }
  HeightGrid grid(static_cast<int>(nx), static_cast<int>(ny), cell_m,
                  0.5 * (x_min + x_max) - 0.5 * (nx - 1) * cell_m,
                  0.5 * (y_min + y_max) - 0.5 * (ny - 1) * cell_m);

  const double origin_height_m = SampleBicubic(dem, rect, row_c, col_c);
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) {
      double x_file = 0.0, y_file = 0.0;
      frame.to_file(grid.x0_m + ix * cell_m, grid.y0_m + iy * cell_m, x_file, y_file);
      const double col = (x_file - dem.xll_corner) / dem.cell_size - 0.5;
      const double row = dem.nrows - 0.5 - (y_file - dem.yll_corner) / dem.cell_size_y;
      grid.At(ix, iy) = SampleBicubic(dem, rect, row, col) - origin_height_m;
    }
  }
  if (frame.origin) frame.origin->height_m = origin_height_m;
  return ProjectedDem{std::move(grid), frame.origin, origin_height_m};
}

}  // namespace pitchlab::worlds
