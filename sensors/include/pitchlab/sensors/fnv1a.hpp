#pragma once
// FNV-1a, 64 bits: a content hash to name things by what they hold (a config, a cache file), not a
// defence against someone forging them. (The .plem elevation format keeps its own checksum: its
// offset basis is part of the file format.)

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace pitchlab::sensors {

class Fnv1a64 {
 public:
  void Add(const void* bytes, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(bytes);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 1099511628211ull;
  }
  void Add(std::string_view text) { Add(text.data(), text.size()); }
  /// The object representation of a trivially copyable value (no padding in what is passed).
  template <typename T>
  void AddValue(const T& value) {
    Add(&value, sizeof value);
  }
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 14695981039346656037ull;  // the offset basis
};

}  // namespace pitchlab::sensors
