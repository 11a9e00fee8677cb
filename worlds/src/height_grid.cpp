#include "pitchlab/worlds/height_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace pitchlab::worlds {

HeightGrid::HeightGrid(int nx_in, int ny_in, double cell_m_in, double x0_m_in, double y0_m_in)
    : nx(nx_in), ny(ny_in), cell_m(cell_m_in), x0_m(x0_m_in), y0_m(y0_m_in) {
  if (nx < 2 || ny < 2 || !(cell_m > 0.0)) {
    throw std::invalid_argument("HeightGrid: need nx, ny >= 2 and cell_m > 0, got nx " +
                                std::to_string(nx) + ", ny " + std::to_string(ny) + ", cell_m " +
                                std::to_string(cell_m));
  }
  heights_m.assign(static_cast<size_t>(nx) * ny, 0.0);
}

double HeightGrid::MinHeight_m() const {
  return *std::min_element(heights_m.begin(), heights_m.end());
}

double HeightGrid::MaxHeight_m() const {
  return *std::max_element(heights_m.begin(), heights_m.end());
}

namespace {

// Cell index and the fraction inside it along one axis, clamped to the grid.
void Locate(double coord, double origin, double cell, int n, int& i, double& t) {
  const double u = std::clamp((coord - origin) / cell, 0.0, static_cast<double>(n - 1));
  i = std::min(static_cast<int>(std::floor(u)), n - 2);
  t = u - i;
}

}  // namespace

double HeightGrid::HeightOnMesh(double x_m, double y_m) const {
  int ix = 0, iy = 0;
  double tx = 0.0, ty = 0.0;
  Locate(x_m, x0_m, cell_m, nx, ix, tx);
  Locate(y_m, y0_m, cell_m, ny, iy, ty);
  const double h00 = At(ix, iy);
  const double h11 = At(ix + 1, iy + 1);
  // The diagonal (ix, iy)-(ix+1, iy+1) splits the cell; barycentric weights on each triangle.
  if (tx >= ty) {
    const double h10 = At(ix + 1, iy);
    return h00 + tx * (h10 - h00) + ty * (h11 - h10);
  }
  const double h01 = At(ix, iy + 1);
  return h00 + ty * (h01 - h00) + tx * (h11 - h01);
}

double HeightGrid::HeightBilinear(double x_m, double y_m) const {
  int ix = 0, iy = 0;
  double tx = 0.0, ty = 0.0;
  Locate(x_m, x0_m, cell_m, nx, ix, tx);
  Locate(y_m, y0_m, cell_m, ny, iy, ty);
  const double a = At(ix, iy) + tx * (At(ix + 1, iy) - At(ix, iy));
  const double b = At(ix, iy + 1) + tx * (At(ix + 1, iy + 1) - At(ix, iy + 1));
  return a + ty * (b - a);
}

double HeightGrid::Slope_rad(int ix, int iy) const {
  const int x0 = std::max(ix - 1, 0), x1 = std::min(ix + 1, nx - 1);
  const int y0 = std::max(iy - 1, 0), y1 = std::min(iy + 1, ny - 1);
  const double gx = (At(x1, iy) - At(x0, iy)) / ((x1 - x0) * cell_m);
  const double gy = (At(ix, y1) - At(ix, y0)) / ((y1 - y0) * cell_m);
  return std::atan(std::hypot(gx, gy));
}

}  // namespace pitchlab::worlds
