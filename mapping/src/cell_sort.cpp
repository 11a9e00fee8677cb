#include "cell_sort.hpp"

#include <algorithm>
#include <array>
#include <numeric>

namespace pitchlab::mapping::internal {
namespace {

constexpr int kAxisBits = 21;  // CellKey: x << 42 | y << 21 | z, each coordinate offset to >= 0
constexpr std::uint64_t kAxisMask = (std::uint64_t{1} << kAxisBits) - 1;
constexpr int kDigitBits = 11;  // 2048 buckets: a histogram in L1, three passes for 33 bits
constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;

int BitsFor(std::uint64_t span) {
  int bits = 0;
  while (bits < 64 && (span >> bits) != 0) ++bits;
  return bits;
}

}  // namespace

std::vector<int> OrderByCell(const std::vector<std::uint64_t>& keys) {
  const std::size_t n = keys.size();
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  if (n < 2) return order;
  // Each coordinate less its minimum, packed as tightly as its span allows: the packed keys
  // order like the keys (x, then y, then z), in fewer bits.
  std::array<std::uint64_t, 3> lo, hi;
  lo.fill(~std::uint64_t{0});
  hi.fill(0);
  for (const std::uint64_t key : keys) {
    for (int a = 0; a < 3; ++a) {
      const std::uint64_t c = (key >> (kAxisBits * (2 - a))) & kAxisMask;
      lo[a] = std::min(lo[a], c);
      hi[a] = std::max(hi[a], c);
    }
  }
  std::array<int, 3> bits;
  for (int a = 0; a < 3; ++a) bits[a] = BitsFor(hi[a] - lo[a]);
  const int total = bits[0] + bits[1] + bits[2];
  if (total == 0) return order;  // one cell: index order
  std::vector<std::uint64_t> packed(n), packed_tmp(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t p = 0;
    for (int a = 0; a < 3; ++a) {
      p = (p << bits[a]) | (((keys[i] >> (kAxisBits * (2 - a))) & kAxisMask) - lo[a]);
    }
    packed[i] = p;
  }
  // Least significant digit first; each pass is stable, so equal keys keep index order.
  std::vector<int> order_tmp(n);
  std::vector<std::size_t> count(kBuckets);
  for (int shift = 0; shift < total; shift += kDigitBits) {
    std::fill(count.begin(), count.end(), 0);
    for (std::size_t i = 0; i < n; ++i) ++count[(packed[i] >> shift) & (kBuckets - 1)];
    std::size_t sum = 0;
    for (std::size_t& c : count) {
      const std::size_t here = c;
      c = sum;
      sum += here;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t at = count[(packed[i] >> shift) & (kBuckets - 1)]++;
      packed_tmp[at] = packed[i];
      order_tmp[at] = order[i];
    }
    packed.swap(packed_tmp);
    order.swap(order_tmp);
  }
  return order;
}

}  // namespace pitchlab::mapping::internal
