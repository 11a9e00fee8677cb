#pragma once
// An elevation map kept as one contribution per scan (issue 20, re-posed maps): each scan is
// inserted on its own (ElevationMap::InsertScan over the scan's extent: its rays, overhang,
// height band and underside rules within the scan), and the map is the combination of the
// contributions in scan order. A scan can be removed, put back, or moved to a new pose after a
// pose-graph optimisation, and the map is then exactly (bit for bit) the one built from scratch
// with the scans at their current poses: the map the planner uses can always be the optimised
// one.
//
// Across scans, a scan's cell whose lowest point lies more than InsertConfig::overhang_headroom_m
// above a ray of another scan that crossed the cell is left out (a crown or a sign one scan saw
// from afar, over ground another scan saw under it): InsertScan's overhang rule, applied between
// scans per cell, whatever their order. (Inserting scans one by one into one ElevationMap applies
// it point by point, but only against the rays of scans inserted before.)

#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

/// The elevation map of a set of scans, each kept with its pose so it can be moved or removed.
class PerScanElevationMap {
 public:
  /// Threads Repose re-inserts scans on at most (fewer when the hardware has fewer cores).
  static constexpr unsigned kMaxThreads = 8;

  /// An all-unknown map over `geometry`, scans inserted with `config`. Throws
  /// std::invalid_argument on an empty geometry.
  explicit PerScanElevationMap(const GridGeometry& geometry, const InsertConfig& config = {});

  /// Inserts scan `id` (any number; the map combines scans in increasing id): its points in its
  /// base_link [m], where its laser sits in base_link [m], and its pose. `ground_base`: points
  /// known without a ray (the ground under the robot, which the laser cannot see but the robot
  /// stands on) [m], in base_link, added after the scan as InsertPoints adds them. Errors (the
  /// map left as it was): `id` already present, a non-finite or non-rigid pose. Non-finite
  /// points are skipped as InsertScan skips them.
  [[nodiscard]] Result<void> Insert(std::size_t id, std::vector<Eigen::Vector3f> points_base,
                                    const Eigen::Vector3f& sensor_base,
                                    const Eigen::Isometry3d& T_map_base,
                                    std::vector<Eigen::Vector3f> ground_base = {});
  /// Takes scan `id`'s contribution out. Error: no scan `id`.
  [[nodiscard]] Result<void> Remove(std::size_t id);
  /// Moves scans to new poses (id, T_map_base) and re-inserts those whose pose changed (any bit),
  /// on up to threads() threads (each scan's contribution is its own: the map is the same bits
  /// whatever thread inserted which); returns how many. Errors (the map left as it was): an unknown
  /// id, a non-finite or non-rigid pose.
  [[nodiscard]] Result<std::size_t> Repose(
      const std::vector<std::pair<std::size_t, Eigen::Isometry3d>>& T_map_base);

  /// At most how many threads Repose uses, the calling one included: by default the hardware's
  /// cores up to kMaxThreads; 1 keeps it on the calling thread. 0 is taken as 1.
  unsigned threads() const { return threads_; }
  void set_threads(unsigned threads) { threads_ = threads > 0 ? threads : 1; }

  /// The combined map.
  const ElevationMap& map() const { return map_; }
  std::size_t scan_count() const { return scans_.size(); }
  /// Scan `id`'s pose; aborts when there is none (a bug: check has_scan).
  const Eigen::Isometry3d& pose(std::size_t id) const { return scans_.at(id).T_map_base; }
  bool has_scan(std::size_t id) const { return scans_.count(id) > 0; }
  /// Cells of scans left out by the overhang rule across scans in the last combination [1].
  std::size_t overhang_cells() const { return overhang_cells_; }

 private:
  // One scan's cells, by linear index of the map's grid: its points and its rays' clearance.
  struct Contribution {
    std::vector<std::uint32_t> cells;
    std::vector<CellStats> stats;
  };
  struct Scan {
    std::vector<Eigen::Vector3f> points_base;
    std::vector<Eigen::Vector3f> ground_base;
    Eigen::Vector3f sensor_base;
    Eigen::Isometry3d T_map_base;
    Contribution contribution;
  };
  // Scan's contribution from its points at its pose (into scan.contribution, whose storage is
  // kept for the next re-pose).
  void Contribute(Scan& scan) const;
  // Contribute for each of `scans` (distinct), on up to threads_ threads.
  void ContributeAll(const std::vector<Scan*>& scans) const;
  void Combine();

  GridGeometry geometry_;
  InsertConfig config_;
  std::map<std::size_t, Scan> scans_;
  ElevationMap map_;
  std::size_t overhang_cells_ = 0;
  unsigned threads_;
};

}  // namespace pitchlab::mapping
