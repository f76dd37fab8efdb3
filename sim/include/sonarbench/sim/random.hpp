#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

namespace sonarbench::sim {

/// SplitMix64 finaliser: a strong 64-bit mix, used to derive independent seeds by hashing
/// (seed, stream) rather than adding, so nearby seeds give unrelated streams.
[[nodiscard]] constexpr std::uint64_t Mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// The seed of stream `stream` (a beam index, a shard, ...) under run seed `seed`.
[[nodiscard]] constexpr std::uint64_t DeriveSeed(std::uint64_t seed, std::uint64_t stream) {
  return Mix64(Mix64(seed) ^ Mix64(stream + 0x632be59bd9b4e019ULL));
}

/// A small, fast generator (xoshiro256**) whose draws are defined here, not by the standard
/// library's distributions, so the same seed gives the same bytes on every platform.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) {
    for (auto& s : state_) s = seed = Mix64(seed);
  }

  std::uint64_t Next() {
    const std::uint64_t result = Rotl(state_[1] * 5, 7) * 9;
    const std::uint64_t t = state_[1] << 17;
    state_[2] ^= state_[0];
    state_[3] ^= state_[1];
    state_[1] ^= state_[2];
    state_[0] ^= state_[3];
    state_[2] ^= t;
    state_[3] = Rotl(state_[3], 45);
    return result;
  }

  /// Uniform in [0, 1).
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  /// Exponential with mean 1: the power of a Rayleigh-distributed amplitude.
  double Exponential() { return -std::log1p(-Uniform()); }
  /// Standard normal (Box-Muller, one of the pair).
  double Normal() {
    const double u1 = 1.0 - Uniform();
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  static std::uint64_t Rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t state_[4]{};
};

}  // namespace sonarbench::sim
