// libFuzzer: arbitrary bytes as a cloud file through sensors::ReadCloudFile, its format picked by
// the first byte (.pcd, .ply, .xyz, or .3d with a valid .pose beside it). Never a crash, a
// sanitizer report or a read out of bounds, and the reader's contract (cloud_file.hpp) holds, else
// abort: a scan holds finite points only, with a finite pose and sensor origin; an error names
// the file. Files users bring are untrusted input as much as a serial line is. Seeds:
// corpus/cloud/ (one file of each format and encoding).
// Its first 5 minutes found a DATA line without a newline read from offset -1 (std::length_error).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "pitchlab/sensors/cloud_file.hpp"

namespace {
void WriteFile(const std::string& path, const std::uint8_t* data, std::size_t size) {
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".pcd", ".ply", ".xyz", ".3d"};
  static const std::string stem = "/dev/shm/pitchlab_cloud_fuzz_" + std::to_string(::getpid());
  const std::string path = stem + kExtensions[data[0] % 4];
  WriteFile(path, data + 1, size - 1);
  if (data[0] % 4 == 3) {
    static const std::uint8_t kPose[] = "0 0 0\n0 0 0\n";
    WriteFile(stem + ".pose", kPose, sizeof(kPose) - 1);
  }
  const auto scan = pitchlab::sensors::ReadCloudFile(path);
  if (!scan) {
    if (scan.error().message.find(path) == std::string::npos) std::abort();
    return 0;
  }
  for (const pitchlab::sensors::ScanPoint& p : scan->points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
  }
  if (!scan->T_world_base.matrix().allFinite()) std::abort();
  if (scan->sensor_origin && !scan->sensor_origin->allFinite()) std::abort();
  return 0;
}
