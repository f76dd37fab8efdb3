#pragma once

#include <cmath>
#include <cstddef>
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

/// Decibels to nepers of power: 10^(x/10) = exp(x · this).
inline constexpr double kNepersPerDecibel = 0.23025850929940458;

/// The standard normal's quantile at u in (0, 1), by bisection on Φ(z) = ½ erfc(-z/√2): 64
/// halvings of [-8, 8] leave an interval under a double's spacing, so z is as exact as erfc.
[[nodiscard]] inline double NormalQuantile(double u) {
  double low = -8.0;
  double high = 8.0;
  for (int i = 0; i < 64; ++i) {
    const double mid = 0.5 * (low + high);
    (0.5 * std::erfc(-mid / std::numbers::sqrt2) < u ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

/// The tables of the ziggurat for the exponential distribution (Marsaglia and Tsang, "The
/// Ziggurat Method for Generating Random Variables", J. Stat. Software 5(8), 2000), scaled to
/// 53-bit draws: 256 layers of equal area V under e^-x, the last edge at R.
struct ExponentialZiggurat {
  static constexpr double kR = 7.697117470131487;
  static constexpr double kV = 3.949659822581572e-3;
  std::uint64_t inside[256];  ///< draws below this lie wholly under the curve
  double width[256];          ///< a draw times this is x
  double f[256];              ///< e^-x at each layer's edge

  static const ExponentialZiggurat& Get() {
    static const ExponentialZiggurat tables;
    return tables;
  }

 private:
  ExponentialZiggurat() {
    constexpr double m = 0x1.0p53;
    double d = kR;
    double t = kR;
    const double q = kV / std::exp(-d);
    inside[0] = static_cast<std::uint64_t>(d / q * m);
    inside[1] = 0;
    width[0] = q / m;
    width[255] = d / m;
    f[0] = 1.0;
    f[255] = std::exp(-d);
    for (int i = 254; i >= 1; --i) {
      d = -std::log(kV / d + std::exp(-d));
      inside[i + 1] = static_cast<std::uint64_t>(d / t * m);
      t = d;
      f[i] = std::exp(-d);
      width[i] = d / m;
    }
  }
};

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
  /// Exponential with mean 1: the power of a Rayleigh-distributed amplitude. Marsaglia and
  /// Tsang's ziggurat (256 layers): one draw, a table look-up and a compare for 98.9% of
  /// values, a logarithm only for the rest; exact, not an approximation of the distribution.
  double Exponential() {
    const ExponentialZiggurat& z = ExponentialZiggurat::Get();
    for (;;) {
      const std::uint64_t bits = Next();
      const std::size_t layer = bits & 0xff;  // the low 8 bits pick the layer,
      const std::uint64_t j = bits >> 11;     // the top 53 the point along it
      const double x = static_cast<double>(j) * z.width[layer];
      if (j < z.inside[layer]) return x;
      if (layer == 0) return ExponentialZiggurat::kR - std::log1p(-Uniform());  // the tail
      if (z.f[layer] + Uniform() * (z.f[layer - 1] - z.f[layer]) < std::exp(-x)) return x;
    }
  }
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
