#pragma once
// Real simulated scans for the mapping tests: SimRig in a built-in world, cached as PCD in the
// build tree (CTest runs every case in its own process; a scan takes seconds to simulate).

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pitchlab/sensors/scan_pcd.hpp"
#include "pitchlab/sim/sim_rig.hpp"

namespace pitchlab::mapping::testing {

/// A full seed-pattern scan (361 x 200, `noise_sigma_m` range noise) of `world` from (x, y, yaw);
/// throws on failure.
inline sensors::Scan3D SimulatedScan(const std::string& world, double x_m, double y_m,
                                     double yaw_deg, std::uint64_t seed = 1,
                                     double noise_sigma_m = 0.005) {
  std::ostringstream name;
  name << world << "_" << x_m << "_" << y_m << "_" << yaw_deg << "_s" << seed << "_n"
       << noise_sigma_m << ".pcd";
  // Keyed by this test binary's build time: it relinks whenever the simulator or a world
  // library changes, so a cached scan never outlives the code that made it.
  const auto built = std::filesystem::last_write_time("/proc/self/exe").time_since_epoch().count();
  const std::filesystem::path dir =
      std::filesystem::path(PITCHLAB_MAPPING_SCAN_CACHE) / std::to_string(built);
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / name.str();
  if (std::filesystem::exists(path)) {
    Result<sensors::Scan3D> cached = sensors::ReadScanPcd(path.string());
    if (cached) return *cached;
  }
  sim::SimRigConfig config;
  // The LMS200 these tests' tolerances were measured with (constant noise, perfect mount), until
  // the registration gates are set relative to the issue-16 model's noise. That model fails 7 of
  // them (benchmarks/README.md), 2 of those by the mount error alone: each scan here has a seed
  // of its own, so a mount error of its own, unlike the scans of one robot.
  config.lms200 = sensors::Lms200Config::Legacy();
  config.lms200.seed = seed;
  config.lms200.noise_sigma_m = noise_sigma_m;
  sim::SimRig rig(std::string(PITCHLAB_WORLDS_DIR) + "/" + world + ".xml", config);
  Result<Eigen::Isometry3d> pose = rig.PlaceRobot(x_m, y_m, yaw_deg * M_PI / 180.0);
  if (!pose) throw std::runtime_error(world + ": " + pose.error().message);
  Result<sensors::Scan3D> scan = rig.Acquire();
  if (!scan) throw std::runtime_error(world + ": " + scan.error().message);
  // Parallel CTest processes may simulate the same scan: each writes its own file, then renames.
  std::filesystem::create_directories(dir);
  const std::string mine = path.string() + "." + std::to_string(::getpid()) + ".pcd";
  Result<void> written = sensors::WriteScanPcd(*scan, mine);
  if (!written) throw std::runtime_error(written.error().message);
  std::filesystem::rename(mine, path);
  // Read back so a fresh and a cached run see the same bytes (VIEWPOINT precision included).
  Result<sensors::Scan3D> again = sensors::ReadScanPcd(path.string());
  if (!again) throw std::runtime_error(again.error().message);
  return *again;
}

}  // namespace pitchlab::mapping::testing
