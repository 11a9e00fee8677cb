#pragma once
// A PCD file's data section as packed records (every field's values in FIELDS order, as binary
// PCD stores them), whichever of the three encodings it is in: binary, binary_compressed (LZF,
// each field's values for all points stored together) or ascii (one point a line).

#include <cstdint>
#include <string>
#include <vector>

#include "pcd_checks.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::sensors::detail {

/// The header's `points` records of `point_step` bytes from `path`, whose header (PeekPcdHeader)
/// and data sizes (CheckPcdDataSize) have been checked. An error naming the file when the data
/// is not what the header says: LZF data that does not decompress to the stated size, an ascii
/// line with too few values, a value that is no number or out of its field's range.
[[nodiscard]] Result<std::vector<std::uint8_t>> ReadPcdRecords(const std::string& path,
                                                               const PcdHeader& header);

/// LZF (liblzf's format, the one binary_compressed PCD uses): `in` decompressed into exactly
/// `out.size()` bytes; false when the stream is corrupt or decompresses to another size.
[[nodiscard]] bool LzfDecompress(const std::uint8_t* in, std::size_t in_size,
                                 std::vector<std::uint8_t>& out);

}  // namespace pitchlab::sensors::detail
