// OrderByCell (internal to mapping) against std::sort of (key, index) pairs, the order the voxel
// grid and the voxel hash were built on: the same permutation, ties in index order.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include "cell_sort.hpp"
#include "voxel_hash.hpp"

namespace pitchlab::mapping {
namespace {

std::vector<int> SortedPairs(const std::vector<std::uint64_t>& keys) {
  std::vector<std::pair<std::uint64_t, int>> keyed;
  for (int i = 0; i < static_cast<int>(keys.size()); ++i) keyed.emplace_back(keys[i], i);
  std::sort(keyed.begin(), keyed.end());
  std::vector<int> order;
  for (const auto& [key, i] : keyed) order.push_back(i);
  return order;
}

// Cells of integer coordinates in [-span, span) per axis (negative ones too: CellKey offsets
// them), `n` of them, many repeated.
std::vector<std::uint64_t> RandomKeys(std::size_t n, std::int64_t span, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::int64_t> c(-span, span - 1);
  std::vector<std::uint64_t> keys;
  for (std::size_t i = 0; i < n; ++i) keys.push_back(CellKey(c(rng), c(rng), c(rng)));
  return keys;
}

TEST(OrderByCell, OrdersAsASortOfKeyIndexPairs) {
  // Spans from one cell to the whole 21-bit range per axis (63 bits: six passes of the radix
  // sort), sizes from none to more points than cells.
  for (const std::int64_t span : {1, 2, 3, 40, 1000, 1 << 20}) {
    for (const std::size_t n : {0, 1, 2, 7, 5000}) {
      const std::vector<std::uint64_t> keys = RandomKeys(n, span, static_cast<unsigned>(span + n));
      EXPECT_EQ(internal::OrderByCell(keys), SortedPairs(keys)) << "span " << span << ", n " << n;
    }
  }
}

TEST(OrderByCell, KeepsPointsOfOneCellInIndexOrderAndOrdersXThenYThenZ) {
  const std::vector<std::uint64_t> keys = {CellKey(1, 0, 0), CellKey(0, 5, 0), CellKey(0, 0, 9),
                                           CellKey(0, 5, 0), CellKey(-1, 7, 7)};
  EXPECT_EQ(internal::OrderByCell(keys), (std::vector<int>{4, 2, 1, 3, 0}));
}

}  // namespace
}  // namespace pitchlab::mapping
