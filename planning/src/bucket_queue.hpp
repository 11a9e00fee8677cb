#pragma once
// Monotone priority queues for the searches (private to planning/).

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace pitchlab::planning {

/// Dinitz's bucket queue, label-correcting inside the current bucket: buckets of `width` over the
/// key in a ring of at least `ring` buckets (a power of two, so the ring index is a mask, not a
/// division). The caller works through the current bucket by index while it may still grow: a key
/// below the current bucket's end lands in it (a label lowered after its cell was expanded is
/// expanded again). Contract: every key pushed is >= 0 and below the current bucket's start plus
/// (ring - 1) widths. O(1) per push, no heap.
class BucketQueue {
 public:
  BucketQueue(double width, std::size_t ring)
      : inv_width_(1.0 / width), buckets_(RoundUpToPowerOfTwo(ring)), mask_(buckets_.size() - 1) {}

  void Push(double key, std::uint32_t value) {
    std::int64_t b = static_cast<std::int64_t>(key * inv_width_);
    if (b <= current_) {
      b = current_;
    } else {
      ++pending_;
    }
    buckets_[b & mask_].push_back(value);
  }
  /// The bucket being worked through (initially bucket 0).
  std::vector<std::uint32_t>& Current() { return buckets_[current_ & mask_]; }
  /// The bucket after it, for prefetching (it may still grow).
  const std::vector<std::uint32_t>& Following() const { return buckets_[(current_ + 1) & mask_]; }
  /// Empties the current bucket and makes the next non-empty one current; false when none is left.
  bool Advance() {
    Current().clear();
    if (pending_ == 0) return false;
    do {
      ++current_;
    } while (Current().empty());
    pending_ -= Current().size();
    return true;
  }

 private:
  static std::size_t RoundUpToPowerOfTwo(std::size_t n) {
    std::size_t p = 1;
    while (p < n) p <<= 1;
    return p;
  }
  double inv_width_;
  std::vector<std::vector<std::uint32_t>> buckets_;
  std::int64_t mask_;
  std::int64_t current_ = 0;
  std::size_t pending_ = 0;  // entries in buckets after the current one
};

/// Radix heap (Ahuja, Mehlhorn, Orlin, Tarjan 1990) on the bit pattern of non-negative doubles,
/// which orders like the doubles: O(1) push, each item moves down at most 64 buckets in all.
/// Contract: keys pushed are >= the last popped key (monotone); smaller keys are raised to it.
class RadixHeap {
 public:
  void Push(double key, std::uint32_t value) {
    std::uint64_t bits;
    std::memcpy(&bits, &key, sizeof bits);
    if (bits < last_) bits = last_;
    buckets_[BucketOf(bits)].push_back({bits, value});
    ++size_;
  }
  bool Empty() const { return size_ == 0; }
  /// Value of a least key. Precondition: !Empty().
  std::uint32_t Pop() {
    if (buckets_[0].empty()) Refill();
    const std::uint32_t v = buckets_[0].back().value;
    buckets_[0].pop_back();
    --size_;
    return v;
  }

 private:
  struct Item {
    std::uint64_t key;
    std::uint32_t value;
  };
  int BucketOf(std::uint64_t key) const {
    return key == last_ ? 0 : 64 - __builtin_clzll(key ^ last_);
  }
  // Moves the lowest non-empty bucket down around its least key.
  void Refill() {
    std::size_t i = 1;
    while (buckets_[i].empty()) ++i;
    std::uint64_t least = buckets_[i].front().key;
    for (const Item& it : buckets_[i]) least = it.key < least ? it.key : least;
    last_ = least;
    for (const Item& it : buckets_[i]) buckets_[BucketOf(it.key)].push_back(it);
    buckets_[i].clear();
  }
  std::array<std::vector<Item>, 65> buckets_;
  std::uint64_t last_ = 0;
  std::size_t size_ = 0;
};

}  // namespace pitchlab::planning
