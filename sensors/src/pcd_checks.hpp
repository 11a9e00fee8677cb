#pragma once
// A PCD file's header, and what must hold before its data is read: the data section's sizes
// against the file's length, and the VIEWPOINT's numbers. Checked before any allocation, so a
// crafted or damaged header is an error naming the file, not a 16 GB allocation ("POINTS 1e9").

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::sensors::detail {

/// How the data section is stored (the DATA line).
enum class PcdData { kAscii = 0, kBinary = 1, kBinaryCompressed = 2 };

/// One FIELDS entry with its SIZE, TYPE and COUNT.
struct PcdField {
  std::string name;
  int size = 4;     ///< bytes of one value
  char type = 'F';  ///< 'F' float, 'U' unsigned, 'I' signed
  int count = 1;    ///< values per point
};

/// What a PCD header promises.
struct PcdHeader {
  std::vector<PcdField> fields;  ///< in record order: a record is their values, packed
  std::uint64_t points = 0;      ///< POINTS (or WIDTH x HEIGHT)
  std::uint64_t point_step = 0;  ///< sum of SIZE x COUNT [bytes]
  PcdData data = PcdData::kAscii;
  std::uint64_t data_offset = 0;  ///< first byte after the DATA line
  Eigen::Vector4f origin{0, 0, 0, 0};
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
};

/// Reads the header lines of `path` up to DATA; an error naming the file when it has no DATA
/// line, FIELDS, SIZE, TYPE and COUNT of different lengths, a field of a type and size no PCD
/// writer makes (F 4 or 8; U, I 1, 2, 4 or 8) or a VIEWPOINT that is not seven numbers.
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
