#pragma once
// Monotone priority queues for the label-setting searches (private to planning/).

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace pitchlab::planning {

/// Dinitz's bucket queue: buckets of `width` over the key, kept in a ring of at least `ring`
/// buckets (a power of two, so the ring index is a mask, not a division).
/// Contract: every key pushed lies in [current bucket + 1, current bucket + ring) whenever the
/// caller is inside a bucket, i.e. each edge adds at least `width` and less than (ring-1)*width
/// to the key. Then every cell in the lowest bucket already has its final key, and a bucket is
/// settled in any order: no heap, O(1) per push and pop. Keys are >= 0.
class BucketQueue {
 public:
  BucketQueue(double width, std::size_t ring)
      : inv_width_(1.0 / width), buckets_(RoundUpToPowerOfTwo(ring)), mask_(buckets_.size() - 1) {}

  /// Bucket of a key [1].
  std::size_t BucketOf(double key) const { return static_cast<std::size_t>(key * inv_width_); }
  void Push(double key, std::uint32_t value) {
    std::size_t b = BucketOf(key);
    if (started_ && b <= current_) b = current_ + 1;  // rounding at a bucket's edge: never back
    buckets_[b & mask_].push_back(value);
    ++size_;
  }
  bool Empty() const { return size_ == 0; }
  /// The next non-empty bucket's values, handed over whole (cleared by the next call); the
  /// caller settles them in any order. Precondition: !Empty().
  std::vector<std::uint32_t>& NextBucket() {
    if (started_) buckets_[current_++ & mask_].clear();
    started_ = true;
    while (buckets_[current_ & mask_].empty()) ++current_;
    std::vector<std::uint32_t>& b = buckets_[current_ & mask_];
    size_ -= b.size();
    return b;
  }

 private:
  static std::size_t RoundUpToPowerOfTwo(std::size_t n) {
    std::size_t p = 1;
    while (p < n) p <<= 1;
    return p;
  }
  double inv_width_;
  std::vector<std::vector<std::uint32_t>> buckets_;
  std::size_t mask_;
  std::size_t current_ = 0, size_ = 0;
  bool started_ = false;
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
