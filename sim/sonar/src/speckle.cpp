#include "sonarbench/sim/sonar/speckle.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>

#include "kernels.hpp"

namespace sonarbench::sim {
namespace {

// A circular complex Gaussian of unit power: an amplitude √E, E exponential, and one of
// kSpecklePhases evenly spaced phases from the top bits of a second draw.
std::complex<double> DrawPhasor(Rng& rng) {
  static const std::array<std::complex<double>, kSpecklePhases> phases = [] {
    std::array<std::complex<double>, kSpecklePhases> table;
    for (int i = 0; i < kSpecklePhases; ++i) {
      table[static_cast<std::size_t>(i)] =
          std::polar(1.0, 2.0 * std::numbers::pi * i / kSpecklePhases);
    }
    return table;
  }();
  static_assert(kSpecklePhases == 1 << 10, "a phase is a draw's top 10 bits");
  const double amplitude = std::sqrt(rng.Exponential());
  return amplitude * phases[static_cast<std::size_t>(rng.Next() >> 54)];
}

// factors[k] = |Σ_{j=k..k+L-1} amplitudes[j]|² / L, for amplitudes.size() = factors.size() + L - 1.
void WindowPower(std::span<const std::complex<double>> amplitudes, std::size_t window,
                 std::span<double> factors) {
  std::complex<double> sum = 0.0;
  for (std::size_t j = 0; j + 1 < window; ++j) sum += amplitudes[j];
  const double scale = 1.0 / static_cast<double>(window);
  for (std::size_t k = 0; k < factors.size(); ++k) {
    sum += amplitudes[k + window - 1];
    factors[k] = std::norm(sum) * scale;
    sum -= amplitudes[k];
  }
}

// The mean of `looks` independent looks' factors, each drawn by `look(factors, l)`; look 0
// alone written straight into `factors`.
template <typename Look>
void AverageLooks(std::span<double> factors, int looks, Look look) {
  look(factors, 0);
  if (looks <= 1) return;
  thread_local std::vector<double> further;
  further.resize(factors.size());
  for (int l = 1; l < looks; ++l) {
    look(std::span(further), l);
    for (std::size_t k = 0; k < factors.size(); ++k) factors[k] += further[k];
  }
  const double per_look = 1.0 / looks;
  for (double& f : factors) f *= per_look;
}

// SectorSpeckle's look `look` alone.
void SectorSpeckleLook(std::span<double> factors, int window,
                       std::span<const double> amplitude_weights,
                       std::span<const std::uint64_t> sector_seeds, int look) {
  const auto size = static_cast<std::size_t>(std::max(window, 1));
  const std::size_t length = factors.size() + size - 1;
  // A sector's phasors, kept per thread and look for the next beams: a static sonar's
  // neighbouring beams share all but one of their sectors. Keyed by seed and length, so what a
  // beam gets does not depend on which beams the thread did before. The least recently used
  // goes first: a beam's own sector (Acoustics::speckle_own_share), which no other beam hears,
  // then leaves after one beam instead of pushing out sectors the next beam needs.
  struct Sector {
    std::uint64_t seed = 0;
    std::uint64_t used = 0;  // the cache's clock when last asked for; 0 if never
    std::vector<std::complex<double>> phasors;
  };
  struct Cache {
    std::vector<Sector> sectors;
    std::uint64_t clock = 0;
  };
  thread_local std::vector<Cache> caches;
  if (caches.size() <= static_cast<std::size_t>(look)) {
    caches.resize(static_cast<std::size_t>(look) + 1);
  }
  Cache& cache = caches[static_cast<std::size_t>(look)];
  if (cache.sectors.size() < amplitude_weights.size() + 1) {
    cache.sectors.resize(amplitude_weights.size() + 1);
  }
  const auto phasors_of =
      [&](std::uint64_t sector_seed) -> const std::vector<std::complex<double>>& {
    const std::uint64_t seed =
        look == 0 ? sector_seed : DeriveSeed(sector_seed, static_cast<std::uint64_t>(look));
    ++cache.clock;
    Sector* oldest = &cache.sectors.front();
    for (Sector& sector : cache.sectors) {
      if (sector.seed == seed && sector.phasors.size() == length) {
        sector.used = cache.clock;
        return sector.phasors;
      }
      if (sector.used < oldest->used) oldest = &sector;
    }
    Sector& sector = *oldest;
    sector.used = cache.clock;
    sector.seed = seed;
    sector.phasors.resize(length);
    Rng rng(seed);
    for (auto& z : sector.phasors) z = DrawPhasor(rng);
    return sector.phasors;
  };
  thread_local std::vector<std::complex<double>> amplitudes;
  amplitudes.assign(length, 0.0);
  for (std::size_t d = 0; d < amplitude_weights.size(); ++d) {
    const double w = amplitude_weights[d];
    if (w == 0.0) continue;
    const std::vector<std::complex<double>>& z = phasors_of(sector_seeds[d]);
    // A complex number is an array of its real and imaginary parts ([complex.numbers]).
    AddScaled(std::span(reinterpret_cast<double*>(amplitudes.data()), 2 * length),
              std::span(reinterpret_cast<const double*>(z.data()), 2 * length), w);
  }
  WindowPower(amplitudes, size, factors);
}

// Convolves `weights` (the pattern's) with the place's angular correlation.
void CorrelateSectors(const SensorModel& sensor, std::vector<double>& weights) {
  const mapping::SensorGeometry& g = sensor.geometry;
  // Sector s's scatterers are Σ_e c_e u_{s+e}, the u independent and c_e ∝ exp(-|e| Δ / θ)
  // (cut where what is left holds under 1e-12 of its power; normalised with the weights below),
  // so a beam hears Σ_d w_d Σ_e c_e u_{a+d+e}: its weights on the independent sectors are w
  // convolved with c.
  const double steps = sensor.acoustics.speckle.angular_correlation_deg * std::numbers::pi / 180.0 /
                       g.step_angle_rad;
  const std::vector<double> kernel = ExponentialKernel(steps, std::numeric_limits<int>::max());
  const int kernel_reach = static_cast<int>(kernel.size() / 2);
  const int reach = kPatternReach + kernel_reach;
  std::vector<double> spread(2 * static_cast<std::size_t>(reach) + 1, 0.0);
  for (int d = -kPatternReach; d <= kPatternReach; ++d) {
    const double w = weights[static_cast<std::size_t>(d + kPatternReach)];
    for (int e = -kernel_reach; e <= kernel_reach; ++e) {
      spread[static_cast<std::size_t>(d + e + reach)] +=
          w * kernel[static_cast<std::size_t>(e + kernel_reach)];
    }
  }
  // The sectors beyond ±kept dropped while they hold under 1e-3 of the power in all, and never
  // more sectors than a turn has (each sector once).
  double total = 0.0;
  for (const double w : spread) total += w * w;
  const long long turn = std::llround(2.0 * std::numbers::pi / g.step_angle_rad);
  int kept = std::min<int>(reach, static_cast<int>((turn - 1) / 2));
  const auto square = [&](int d) {
    const double w = spread[static_cast<std::size_t>(d + reach)];
    return w * w;
  };
  double dropped = 0.0;
  for (int d = reach; d > kept; --d) dropped += square(d) + square(-d);
  while (kept > 0 && dropped + square(kept) + square(-kept) < 1e-3 * total) {
    dropped += square(kept) + square(-kept);
    --kept;
  }
  weights.assign(spread.begin() + (reach - kept), spread.begin() + (reach + kept + 1));
  double kept_total = 0.0;
  for (const double w : weights) kept_total += w * w;
  for (double& w : weights) w /= std::sqrt(kept_total);
}

}  // namespace

void CorrelatedSpeckle(std::span<double> factors, int window, Rng& rng, int looks) {
  AverageLooks(factors, looks, [&](std::span<double> out, int) {
    if (window <= 1) {
      for (double& f : out) f = rng.Exponential();
      return;
    }
    const auto size = static_cast<std::size_t>(window);
    thread_local std::vector<std::complex<double>> amplitudes;
    amplitudes.resize(out.size() + size - 1);
    for (auto& a : amplitudes) a = DrawPhasor(rng);
    WindowPower(amplitudes, size, out);
  });
}

void SectorSpeckle(std::span<double> factors, int window, std::span<const double> amplitude_weights,
                   std::span<const std::uint64_t> sector_seeds, int looks) {
  AverageLooks(factors, looks, [&](std::span<double> out, int look) {
    SectorSpeckleLook(out, window, amplitude_weights, sector_seeds, look);
  });
}

SpeckleSectors SpeckleSectorsFor(const SensorModel& sensor) {
  const Acoustics& acoustics = sensor.acoustics;
  SpeckleSectors sectors;
  // A bin's speckle is the coherent sum of the scatterers its range response covers: the pulse
  // and, with skirts, one e-folding of each; or the range a scene sets.
  const double speckle_range_m =
      acoustics.speckle.window_m > 0.0
          ? acoustics.speckle.window_m
          : acoustics.pulse.length_m + 2.0 * acoustics.pulse.skirt_length_m;
  sectors.window =
      static_cast<int>(std::max(1L, std::lround(speckle_range_m / sensor.geometry.bin_size_m)));
  // Sector d's share of the two-way horizontal pattern exp(-θ²/2σ²), σ = w_h / √(8 ln 2): the
  // normal distribution's mass over [(d - ½) Δ, (d + ½) Δ], Δ the head step.
  const mapping::SensorGeometry& g = sensor.geometry;
  {
    const double sigma = g.beam_width_horizontal_rad / std::sqrt(8.0 * std::log(2.0));
    const auto cdf = [&](double x) { return 0.5 * std::erfc(-x / (sigma * std::sqrt(2.0))); };
    sectors.weights.assign(2 * kPatternReach + 1, 0.0);
    double total = 0.0;
    for (int d = -kPatternReach; d <= kPatternReach; ++d) {
      const double share = cdf((d + 0.5) * g.step_angle_rad) - cdf((d - 0.5) * g.step_angle_rad);
      if (share < 1e-3) continue;
      sectors.weights[static_cast<std::size_t>(d + kPatternReach)] = share;
      total += share;
    }
    for (double& w : sectors.weights) w = std::sqrt(w / total);
    if (acoustics.speckle.angular_correlation_deg > 0.0) CorrelateSectors(sensor, sectors.weights);
    // The beam's own scatterers' share, after the sectors' (the synthesis seeds it last).
    if (const double own = acoustics.speckle.own_share; own > 0.0) {
      for (double& w : sectors.weights) w *= std::sqrt(1.0 - own);
      sectors.weights.push_back(std::sqrt(own));
    }
  }
  return sectors;
}

}  // namespace sonarbench::sim
