#pragma once

#include <cstdint>

namespace pitchlab::worlds {

// Our own generator and noise: std:: distributions are implementation-defined, and worlds must be
// the same bytes from the same seed on every standard library.

/// SplitMix64 (Steele, Lea, Flood 2014): a tiny, well-mixed 64-bit sequence.
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t Next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1) from the top 53 bits.
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  /// Uniform in [lo, hi).
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }

 private:
  std::uint64_t state_;
};

/// Lattice value in [-1, 1] at integer point (ix, iy) of noise layer `layer` for `seed`.
double LatticeValue(std::uint64_t seed, int layer, long ix, long iy);

/// Smooth value noise in [-1, 1]: lattice values at integer points blended by a quintic fade.
double ValueNoise(std::uint64_t seed, int layer, double x, double y);

/// Fractal sum of `octaves` value-noise layers, frequency doubling and amplitude halving; the
/// result lies in about [-1, 1] (normalized by the total amplitude).
double FractalNoise(std::uint64_t seed, double x, double y, int octaves);

}  // namespace pitchlab::worlds
