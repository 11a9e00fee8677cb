#pragma once
// What PCL's PCD reader trusts and must not: the data section's sizes against the file's length,
// and the VIEWPOINT's numbers. Checked before PCL reads the data, so a crafted or damaged header
// is an error naming the file instead of a crash (a null memmove on "uncompressed size 0") or a
// 20-second allocation (size 1e9).

#include <cstdint>
#include <string>

#include <Eigen/Geometry>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::sensors::detail {

/// PCL's `data_type` codes from PCDReader::readHeader.
enum class PcdData { kAscii = 0, kBinary = 1, kBinaryCompressed = 2 };

/// What a PCD header promises, read by us before PCL's reader (whose readHeader already allocates
/// POINTS x the record size, 16 GB for "POINTS 1000000000").
struct PcdHeader {
  std::uint64_t points = 0;      ///< POINTS (or WIDTH x HEIGHT)
  std::uint64_t point_step = 0;  ///< sum of SIZE x COUNT [bytes]
  PcdData data = PcdData::kAscii;
  std::uint64_t data_offset = 0;  ///< first byte after the DATA line
  Eigen::Vector4f origin{0, 0, 0, 0};
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
};

/// Reads the header lines of `path` up to DATA; an error naming the file when it has no DATA
/// line, or a number PCL would misread (a VIEWPOINT "nan" leaves PCL's values unset).
[[nodiscard]] Result<PcdHeader> PeekPcdHeader(const std::string& path);

/// The data section of `path` (it starts at byte `data_offset`) can hold `points` records of
/// `point_step` bytes: binary needs them all; binary_compressed needs its two size words, a
/// compressed size within the file and an uncompressed size equal to points x point_step.
[[nodiscard]] Result<void> CheckPcdDataSize(const std::string& path, PcdData type,
                                            std::uint64_t data_offset, std::uint64_t points,
                                            std::uint64_t point_step);

/// The VIEWPOINT: a finite translation within kMaxCoordinate_m of the origin and a quaternion of
/// (nearly) unit length; an error naming the file and the value otherwise.
[[nodiscard]] Result<void> CheckViewpoint(const std::string& path, const Eigen::Vector4f& origin,
                                          const Eigen::Quaternionf& orientation);

}  // namespace pitchlab::sensors::detail
