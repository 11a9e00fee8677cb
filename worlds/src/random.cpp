#include "random.hpp"

#include <cmath>

namespace pitchlab::worlds {
namespace {

double Fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

}  // namespace

double LatticeValue(std::uint64_t seed, int layer, long ix, long iy) {
  // Hash the coordinates into a SplitMix64 state: order-free, so any point can be evaluated alone.
  std::uint64_t key = seed * 0xD1B54A32D192ED03ULL;
  key ^= static_cast<std::uint64_t>(layer) * 0xABC98388FB8FAC03ULL;
  key ^= static_cast<std::uint64_t>(ix) * 0x8CB92BA72F3D8DD7ULL;
  key ^= static_cast<std::uint64_t>(iy) * 0x9E3779B97F4A7C15ULL;
  SplitMix64 mix(key);
  return mix.Uniform() * 2.0 - 1.0;
}

double ValueNoise(std::uint64_t seed, int layer, double x, double y) {
  const double fx = std::floor(x);
  const double fy = std::floor(y);
  const long ix = static_cast<long>(fx);
  const long iy = static_cast<long>(fy);
  const double u = Fade(x - fx);
  const double v = Fade(y - fy);
  const double v00 = LatticeValue(seed, layer, ix, iy);
  const double v10 = LatticeValue(seed, layer, ix + 1, iy);
  const double v01 = LatticeValue(seed, layer, ix, iy + 1);
  const double v11 = LatticeValue(seed, layer, ix + 1, iy + 1);
  const double a = v00 + (v10 - v00) * u;
  const double b = v01 + (v11 - v01) * u;
  return a + (b - a) * v;
}

double FractalNoise(std::uint64_t seed, double x, double y, int octaves) {
  double sum = 0.0;
  double amplitude = 1.0;
  double total = 0.0;
  double frequency = 1.0;
  for (int k = 0; k < octaves; ++k) {
    sum += amplitude * ValueNoise(seed, k, x * frequency, y * frequency);
    total += amplitude;
    amplitude *= 0.5;
    frequency *= 2.0;
  }
  return total > 0.0 ? sum / total : 0.0;
}

}  // namespace pitchlab::worlds
