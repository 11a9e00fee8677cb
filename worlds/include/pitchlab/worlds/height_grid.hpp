#pragma once

#include <cstddef>
#include <vector>

namespace pitchlab::worlds {

/// A regular height grid in a local metric frame (x east, y north, z up). Vertex (ix, iy) sits at
/// (x0_m + ix * cell_m, y0_m + iy * cell_m): iy = 0 is the southern row, ix = 0 the western column.
struct HeightGrid {
  /// An nx x ny grid of zero heights; throws std::invalid_argument unless nx, ny >= 2, cell_m > 0.
  HeightGrid(int nx, int ny, double cell_m, double x0_m, double y0_m);

  int nx = 0;                     ///< vertices west to east
  int ny = 0;                     ///< vertices south to north
  double cell_m = 0.0;            ///< vertex spacing [m]
  double x0_m = 0.0;              ///< x of the western column [m]
  double y0_m = 0.0;              ///< y of the southern row [m]
  std::vector<double> heights_m;  ///< [m], index iy * nx + ix

  /// Height of vertex (ix, iy) [m]; no bounds check beyond the vector's.
  double& At(int ix, int iy) { return heights_m[static_cast<std::size_t>(iy) * nx + ix]; }
  /// Height of vertex (ix, iy) [m].
  double At(int ix, int iy) const { return heights_m[static_cast<std::size_t>(iy) * nx + ix]; }
  /// x of the eastern column [m].
  double XMax_m() const { return x0_m + (nx - 1) * cell_m; }
  /// y of the northern row [m].
  double YMax_m() const { return y0_m + (ny - 1) * cell_m; }
  /// Lowest vertex height [m].
  double MinHeight_m() const;
  /// Highest vertex height [m].
  double MaxHeight_m() const;
  /// Height [m] at (x, y) on the triangle mesh MuJoCo builds from an hfield: each cell is split
  /// along its diagonal from (ix, iy) to (ix + 1, iy + 1). Points outside are clamped to the grid.
  double HeightOnMesh(double x_m, double y_m) const;
  /// Bilinear height [m] at (x, y); points outside are clamped to the grid.
  double HeightBilinear(double x_m, double y_m) const;
  /// Slope [rad] at vertex (ix, iy) from central differences (one-sided at the border).
  double Slope_rad(int ix, int iy) const;
};

}  // namespace pitchlab::worlds
