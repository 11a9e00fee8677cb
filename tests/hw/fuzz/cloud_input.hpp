#pragma once
// What the cloud fuzzer does with one input, shared with the GoogleTest that holds its seeds and
// its contract check to known answers (tests/hw/cloud_fuzz_contract_test.cpp): the bytes as a
// cloud file, and whether what ReadCloudFile made of it keeps the reader's contract
// (cloud_file.hpp): a scan holds finite points only, with a finite pose and sensor origin; an
// error names the file.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "pitchlab/sensors/cloud_file.hpp"

namespace pitchlab::fuzz {

/// Writes `data` without its first byte to `stem` plus the extension the first byte picks (.pcd,
/// .ply, .xyz, or .3d with an identity .pose beside it) and returns that path; empty for no bytes.
inline std::string WriteCloudInput(const std::uint8_t* data, std::size_t size,
                                   const std::string& stem) {
  if (size == 0) return {};
  static const char* const kExtensions[] = {".pcd", ".ply", ".xyz", ".3d"};
  const auto write = [](const std::string& path, const std::uint8_t* bytes, std::size_t n) {
    if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
      std::fwrite(bytes, 1, n, f);
      std::fclose(f);
    }
  };
  const std::string path = stem + kExtensions[data[0] % 4];
  write(path, data + 1, size - 1);
  if (data[0] % 4 == 3) {
    static const std::uint8_t kPose[] = "0 0 0\n0 0 0\n";
    write(stem + ".pose", kPose, sizeof(kPose) - 1);
  }
  return path;
}

/// How `scan`, read from `path`, breaks the reader's contract; empty when it keeps it.
inline std::string CloudContractBreach(const Result<sensors::Scan3D>& scan,
                                       const std::string& path) {
  if (!scan) {
    return scan.error().message.find(path) == std::string::npos
               ? "the error does not name the file: " + scan.error().message
               : std::string();
  }
  for (const sensors::ScanPoint& p : scan->points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return "a point is not finite";
    }
  }
  if (!scan->T_world_base.matrix().allFinite()) return "the pose is not finite";
  if (scan->sensor_origin && !scan->sensor_origin->allFinite()) {
    return "the sensor origin is not finite";
  }
  return {};
}

}  // namespace pitchlab::fuzz
