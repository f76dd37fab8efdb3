#pragma once

#include <cstdint>
#include <vector>

#include "sonarbench/sim/world/random.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

namespace sonarbench::sim {

/// The sonar's own ringing (Acoustics::self_reflection_db, one power level per bin from the
/// first): the same at every ping of a head step, varying across head steps by the angle spread
/// and from ping to ping over the ringing bins by the ping spread (docs/physics.md).
class SelfReflection {
 public:
  /// Tables each head step's levels from `run_seed`.
  SelfReflection(const SensorModel& sensor, std::uint64_t run_seed);

  /// The power per bin for a ping at `head_angle_rad`: bin k's profile power P_k times
  ///     10^((σ_a A_jk + σ_p (y_k + y_k+1) / √2) / 10) / exp(½ (ln 10 / 10)² (σ_a² + σ_p²)),
  /// A_jk head step j's tabled draw and y_k standard normals drawn from `ping_rng` (r + 1 for
  /// the r ringing bins; none when σ_p is 0). The divisor keeps P_k the mean power.
  void Draw(double head_angle_rad, Rng& ping_rng, std::vector<double>& power) const;

 private:
  /// Multiplies by_head_ by 10^(σ_a A_jk / 10): A_jk = Σ_e c_e u_(j+e),k, u_jk = (z_jk +
  /// z_j,k+1) / √2 from normals drawn per head step, c_e ∝ exp(-|e| Δ / θ) with Σ c² = 1.
  void SpreadOverHeadSteps(std::uint64_t run_seed);

  Acoustics acoustics_;
  double step_angle_rad_ = 0.0;
  /// Mean power per head step (row j, one row without an angle spread) and bin.
  std::vector<double> by_head_;
  int turn_ = 1;
  /// The bins the ping's spread covers: those within self_reflection_ringing_range_m.
  std::size_t ringing_bins_ = 0;
};

}  // namespace sonarbench::sim
