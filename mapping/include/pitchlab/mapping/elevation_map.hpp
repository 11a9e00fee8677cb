#pragma once
// Elevation map (Eq. 2, 3 and the inclination fit): a grid of m x n cells over a map area, each
// keeping running statistics of the heights that fell in it, so clouds are inserted incrementally
// and two maps merge without re-reading any point.
//
// Frames and index order (frame `map`, x east/forward, y north/left, z up):
//
//        y ^
//          |  (0,n-1) (1,n-1) ...  (m-1,n-1)
//          |   ...
//          |  (0,1)   (1,1)   ...
//          |  (0,0)   (1,0)   ...  (m-1,0)
//   origin +----------------------------------> x
//   (x_min_m, y_min_m) is the outer corner of cell (0,0); cell (i,j) spans
//   [x_min + i*cell, x_min + (i+1)*cell) x [y_min + j*cell, y_min + (j+1)*cell);
//   storage index = j * size_x + i (rows of constant y, west to east, south to north).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

/// Integer cell index: i along x, j along y.
struct CellIndex {
  int i = 0;  ///< column (x) [cell]
  int j = 0;  ///< row (y) [cell]
  bool operator==(const CellIndex& o) const { return i == o.i && j == o.j; }
};

/// Where the grid lies in the map frame and how fine it is (Eq. 2).
struct GridGeometry {
  double x_min_m = 0.0;  ///< outer x of column 0 [m]
  double y_min_m = 0.0;  ///< outer y of row 0 [m]
  double cell_m = 0.1;   ///< cell edge [m/cell]
  int size_x = 0;        ///< m: cells along x [cell]
  int size_y = 0;        ///< n: cells along y [cell]

  /// Eq. 2: m = round(size_x_m / cell_m), n = round(size_y_m / cell_m) cells from the corner
  /// (x_min_m, y_min_m). Throws std::invalid_argument on a non-positive size or cell, or more than
  /// 2^31 cells.
  static GridGeometry FromArea(double x_min_m, double y_min_m, double size_x_m, double size_y_m,
                               double cell_m);
  /// The grid of `cell_m` cells aligned to multiples of cell_m that covers [lo, hi] (plus
  /// `margin_m`). Throws as FromArea.
  static GridGeometry Covering(const Eigen::Vector2d& lo_m, const Eigen::Vector2d& hi_m,
                               double cell_m, double margin_m = 0.0);

  std::size_t cell_count() const { return static_cast<std::size_t>(size_x) * size_y; }
  double x_max_m() const { return x_min_m + size_x * cell_m; }  ///< [m]
  double y_max_m() const { return y_min_m + size_y * cell_m; }  ///< [m]
  bool Contains(const CellIndex& c) const {
    return c.i >= 0 && c.j >= 0 && c.i < size_x && c.j < size_y;
  }
  /// Cell under the point (x, y) [m]; may be outside the grid (check Contains).
  CellIndex IndexOf(double x_m, double y_m) const {
    return {static_cast<int>(std::floor((x_m - x_min_m) / cell_m)),
            static_cast<int>(std::floor((y_m - y_min_m) / cell_m))};
  }
  /// Centre of cell c in the map frame [m].
  Eigen::Vector2d CenterOf(const CellIndex& c) const {
    return {x_min_m + (c.i + 0.5) * cell_m, y_min_m + (c.j + 0.5) * cell_m};
  }
  std::size_t Linear(const CellIndex& c) const {
    return static_cast<std::size_t>(c.j) * size_x + c.i;
  }
  CellIndex FromLinear(std::size_t k) const {
    return {static_cast<int>(k % size_x), static_cast<int>(k / size_x)};
  }
  /// Same cell size and size, origins equal within 1e-9 m.
  bool SameAs(const GridGeometry& o) const;
};

/// WGS84 position of the map frame's origin (not of the grid corner).
struct GeodeticOrigin {
  double latitude_deg = 0.0;   ///< [deg]
  double longitude_deg = 0.0;  ///< [deg]
  double height_m = 0.0;       ///< ellipsoidal height of map z = 0 [m]
};

/// Running statistics of one cell: 60 bytes. Positions are relative to the cell centre, so float
/// keeps sub-micrometre resolution; the co-moments are updated by Welford's method (stable).
struct CellStats {
  std::uint32_t count = 0;                   ///< points in the cell [1]
  float mean_x = 0, mean_y = 0, mean_z = 0;  ///< mean point, x/y from the cell centre [m]
  /// Co-moments sum((a - mean_a)(b - mean_b)) [m^2].
  float c_xx = 0, c_xy = 0, c_xz = 0, c_yy = 0, c_yz = 0, c_zz = 0;
  float min_z = std::numeric_limits<float>::infinity();   ///< lowest point [m]
  float max_z = -std::numeric_limits<float>::infinity();  ///< highest point [m]
  /// Lowest height at which a laser ray passed over the cell without hitting it: the surface
  /// here is below this [m]; +inf when no ray crossed. What makes unobserved drops visible.
  float clearance_z = std::numeric_limits<float>::infinity();
  /// The second lowest and second highest point [m] (+-inf with fewer than two points): a step
  /// inside a cell needs two points to say so, where one may be a mixed pixel at a depth edge or
  /// an outlier (ElevationLayers::next_min_z).
  float next_min_z = std::numeric_limits<float>::infinity();
  float next_max_z = -std::numeric_limits<float>::infinity();

  bool known() const { return count > 0; }
};
static_assert(sizeof(CellStats) <= 64, "issue 4: map memory <= 64 bytes per cell");

/// Adds `from`'s points into `into` as if they had been inserted there: Chan's parallel update of
/// the moments (both cells' positions relative to the same cell centre), min, max and the lower
/// clearance. Order matters to the last float bit only.
void CombineCells(CellStats& into, const CellStats& from);

/// Insertion options.
struct InsertConfig {
  /// Length of each ray, back from its hit, along which cells get their clearance updated [m];
  /// 0 disables clearance. Drops appear where rays pass below the ground around them, close to
  /// the far hit; overhangs (a crown, a sign) need the rays that pass under them to the ground a
  /// few metres behind: on `urban` the surface RMSE at 0.1 m cells is 0.29 m with 2 m, 0.21 m
  /// with 5 m and the same with 10 or 40 m (elevation_truth_benchmark).
  double clearance_length_m = 5.0;
  /// Points outside [min_z, max_z] (map frame) are ignored: ceiling, outliers [m].
  double min_z_m = -1e6;
  double max_z_m = 1e6;
  /// InsertScan: a point more than this above a ray that crossed its cell (the cell's clearance,
  /// with this scan's rays traced first) is not ground the robot stands on but something it
  /// passes under (a sign, a canopy, a crown), or a point of the face beside the cell that the
  /// range noise put over the cell edge; it is left out of the cell [m]. The P3 with its laser
  /// is ~0.6 m tall (as TruthConfig::min_headroom_m). 0 or less keeps every point.
  double overhang_headroom_m = 0.6;
  /// InsertScan's height band: a point higher than `max_height_m` above the ground under the
  /// sensor that saw it (the sensor's z minus `sensor_height_m`) is not ground (a ceiling, a
  /// canopy, a tree's crown) and is left out (InsertStats::above_band), unless its surface was
  /// seen from above (the plane of this scan's points in the 3 x 3 cells around it, see
  /// drop_undersides): that is terrain rising ahead, kept up to `band_grade` per metre of
  /// horizontal distance higher (the P3-AT climbs 35 %), so a hill the robot could drive up stays
  /// ground however high it is. A far ceiling's single scan line, whose side no plane decides, is
  /// left out. +inf: no band.
  double max_height_m = std::numeric_limits<double>::infinity();
  /// The laser above the ground the robot stands on: the P3's mount (MountConfig: pitch axis
  /// 0.45 m over base_link, mirror 0.09 m above it; base_link on the ground) [m].
  double sensor_height_m = 0.54;
  double band_grade = 0.35;  ///< see max_height_m; P3-AT datasheet: 35 % grade [1]
  /// InsertScan: points a ray rose to that lie on a surface seen from below (the plane through
  /// this scan's rising points in the 3 x 3 cells around them is within 60 deg of level, and the
  /// ray met it from its underside: a ceiling, the underside of a desk, a bridge or a canopy) are
  /// left out (InsertStats::underside): ground is always seen from above, whatever its height (a
  /// hill ahead rises away from the ray that meets it). Left in, a corridor's ceiling became the
  /// ground of every cell whose floor the scan did not reach.
  bool drop_undersides = true;
};

/// What one insertion did.
struct InsertStats {
  std::size_t inserted = 0;         ///< points that landed in a cell
  std::size_t outside = 0;          ///< points off the grid or outside the z limits
  std::size_t non_finite = 0;       ///< NaN / inf points skipped
  std::size_t clearance_cells = 0;  ///< cell updates by ray clearance
  std::size_t overhang =
      0;  ///< points left out over a lower ray (InsertConfig::overhang_headroom_m)
  std::size_t above_band = 0;  ///< points above the height band (InsertConfig::max_height_m)
  std::size_t underside = 0;   ///< points on surfaces seen from below (drop_undersides)
};

/// The elevation grid: geometry, georeference and one CellStats per cell.
class ElevationMap {
 public:
  ElevationMap() = default;
  /// An all-unknown map over `geometry`. Throws std::invalid_argument on an empty geometry.
  explicit ElevationMap(const GridGeometry& geometry,
                        std::optional<GeodeticOrigin> geodetic_origin = std::nullopt);
  /// A map over `geometry` holding `cells` (a copy of part of another, a loaded one), without
  /// first clearing a grid of its own. Throws std::invalid_argument on an empty geometry or when
  /// the size does not match it.
  ElevationMap(const GridGeometry& geometry, std::vector<CellStats> cells,
               std::optional<GeodeticOrigin> geodetic_origin);

  const GridGeometry& geometry() const { return geometry_; }
  const std::optional<GeodeticOrigin>& geodetic_origin() const { return geodetic_origin_; }
  void set_geodetic_origin(std::optional<GeodeticOrigin> g) { geodetic_origin_ = g; }

  const CellStats& at(const CellIndex& c) const { return cells_[geometry_.Linear(c)]; }
  const CellStats& at(std::size_t linear) const { return cells_[linear]; }
  const std::vector<CellStats>& cells() const { return cells_; }
  /// Bytes held per cell (the CellStats array only) [B/cell].
  static constexpr std::size_t kBytesPerCell = sizeof(CellStats);

  /// Eq. 2: each point goes to the cell under its x, y and updates that cell's statistics.
  /// Points are in the map frame [m]. No allocation.
  InsertStats InsertPoints(const Eigen::Vector3f* points_m, std::size_t count,
                           const InsertConfig& config = {});
  /// As InsertPoints, and for each point the ray from `sensor_origin_m` (map frame) to it sets
  /// the clearance of the cells it crosses over its last `clearance_length_m`. All rays are traced
  /// before any point is added, so a point over a ray of the same call that passed more than
  /// `overhang_headroom_m` below it in its cell is left out (InsertStats::overhang). Pass a whole
  /// scan at once: rays of a later call do not take back points already added.
  InsertStats InsertScan(const Eigen::Vector3f* points_m, std::size_t count,
                         const Eigen::Vector3f& sensor_origin_m, const InsertConfig& config = {});
  /// Any container of points with float members x, y, z (pcl::PointCloud<pcl::PointXYZ>,
  /// std::vector<sensors::ScanPoint>), transformed by T_map_cloud on the way in. With a sensor
  /// origin the cloud is one InsertScan (its rays all traced first); without, it goes in chunks.
  template <typename Cloud>
  InsertStats Insert(const Cloud& cloud, const Eigen::Isometry3f& T_map_cloud,
                     const std::optional<Eigen::Vector3f>& sensor_origin_m = std::nullopt,
                     const InsertConfig& config = {});

  /// Which cells of this map Merge adds to.
  enum class MergeCells {
    kAll,      ///< every cell, as if `other`'s points had been inserted here
    kUnknown,  ///< only cells without a point: a view from an uncertain pose fills the map's
               ///< gaps and never blends into (and contradicts) ground the map has seen
  };
  /// Adds every cell of `other` into this map as if its points had been inserted here (Chan's
  /// parallel update of the moments), or with MergeCells::kUnknown only those this map has no
  /// point in (the others are left as they are, clearance included). Fails (kInvalidArgument) when
  /// the cell sizes differ or the grids are not aligned to a whole number of cells; cells of
  /// `other` off this grid are counted in the returned number and dropped.
  [[nodiscard]] Result<std::size_t> Merge(const ElevationMap& other,
                                          MergeCells cells = MergeCells::kAll);

  /// Replaces the statistics of every cell (for the loader); throws std::invalid_argument when
  /// the size does not match the geometry.
  void SetCells(std::vector<CellStats> cells);

 private:
  GridGeometry geometry_;
  std::optional<GeodeticOrigin> geodetic_origin_;
  std::vector<CellStats> cells_;
};

template <typename Cloud>
InsertStats ElevationMap::Insert(const Cloud& cloud, const Eigen::Isometry3f& T_map_cloud,
                                 const std::optional<Eigen::Vector3f>& sensor_origin_m,
                                 const InsertConfig& config) {
  if (sensor_origin_m) {
    std::vector<Eigen::Vector3f> points;
    points.reserve(cloud.size());
    for (const auto& p : cloud) points.push_back(T_map_cloud * Eigen::Vector3f(p.x, p.y, p.z));
    return InsertScan(points.data(), points.size(), *sensor_origin_m, config);
  }
  constexpr std::size_t kChunk = 1024;
  Eigen::Vector3f buffer[kChunk];
  InsertStats total;
  std::size_t n = 0;
  auto flush = [&] {
    const InsertStats s = InsertPoints(buffer, n, config);
    total.inserted += s.inserted;
    total.outside += s.outside;
    total.non_finite += s.non_finite;
    n = 0;
  };
  for (const auto& p : cloud) {
    buffer[n++] = T_map_cloud * Eigen::Vector3f(p.x, p.y, p.z);
    if (n == kChunk) flush();
  }
  if (n > 0) flush();
  return total;
}

}  // namespace pitchlab::mapping
