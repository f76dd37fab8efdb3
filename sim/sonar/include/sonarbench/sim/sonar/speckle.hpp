#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "sonarbench/sim/world/random.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

namespace sonarbench::sim {

/// Phases of the speckle's complex Gaussians.
inline constexpr int kSpecklePhases = 1024;
/// Head-step-wide azimuth sectors on each side of a beam's own that its pattern covers.
inline constexpr int kPatternReach = 4;

/// Speckle factors (power, mean 1) for consecutive range bins: factor k is |Σ g_j|² / L over
/// the L = `window` bins j = k - L + 1 .. k, the g_j independent circular complex Gaussians of
/// unit power drawn from `rng` (amplitude √E, E exponential; one of kSpecklePhases phases).
/// Bins m apart correlate by (1 - m/L)² for m < L. With `looks` N > 1, the mean of N such
/// factors: gamma of shape N (docs/physics.md, speckle).
void CorrelatedSpeckle(std::span<double> factors, int window, Rng& rng, int looks = 1);

/// The same for a beam whose scatterers lie in azimuth sectors, sector d's Gaussians drawn by
/// Rng(sector_seeds[d]) (look l > 0 by Rng(DeriveSeed(sector_seeds[d], l))): bin j's amplitude
/// is Σ_d amplitude_weights[d] · g_j(d). Beams that share sectors correlate by (Σ_d w_d w'_d)²;
/// one sector of weight 1 gives CorrelatedSpeckle's factors for Rng(sector_seeds[0]) when L > 1.
void SectorSpeckle(std::span<double> factors, int window, std::span<const double> amplitude_weights,
                   std::span<const std::uint64_t> sector_seeds, int looks = 1);

/// A sensor's speckle layout.
struct SpeckleSectors {
  /// The correlation window L in bins: the pulse plus one e-folding of each skirt
  /// (pulse_length_m + 2 pulse_skirt_length_m), or Acoustics::speckle_window_m; at least 1.
  int window = 1;
  /// Amplitude weights of the sectors around a beam's own (2R + 1, index R the beam's), their
  /// squares summing to 1: the two-way horizontal pattern's share of power per sector (under
  /// 1e-3 dropped), convolved with the place's angular correlation when it has one; then the
  /// beam's own scatterers' weight when Acoustics::speckle_own_share is set.
  std::vector<double> weights;
};
[[nodiscard]] SpeckleSectors SpeckleSectorsFor(const SensorModel& sensor);

}  // namespace sonarbench::sim
