#pragma once
// Private: points ordered by their cell (CellKey), as std::sort of (key, index) pairs orders them,
// in linear time. The voxel grid and the voxel hash sort every cloud registration makes (the scan,
// the local map, each at two scales, every stop); a comparison sort of 10^5 pairs was a tenth of
// registration's time on the mission's own thread.

#include <cstdint>
#include <vector>

namespace pitchlab::mapping::internal {

/// Indices 0 .. keys.size() - 1 ordered by key, equal keys by index: the order of std::sort over
/// the pairs (keys[i], i). `keys` are CellKeys (voxel_hash.hpp): each 21-bit coordinate is spread
/// over only the bits its span needs, then sorted by a stable radix sort.
std::vector<int> OrderByCell(const std::vector<std::uint64_t>& keys);

}  // namespace pitchlab::mapping::internal
