#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "sonarbench/mapping/sensor_geometry.hpp"
#include "sonarbench/sim/world/random.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

namespace sonarbench::sim {

/// The sonar's receiver: the range loss left after the time-varied gain, the noise, the level
/// jitter and the converter from a bin's power to the reported 8-bit level (docs/physics.md).
/// Powers are linear, relative to a perfect reflector at 1 m.
class Receiver {
 public:
  explicit Receiver(const SensorModel& sensor);

  /// The 8-bit intensity for a level [dB]: the AD window's step, under the receiver's ceiling
  /// (Acoustics::ad_knee, ad_ceiling), rounded to the converter's reading (ad_levels).
  [[nodiscard]] std::uint8_t Quantise(double level_db) const;
  /// The same for a power, by table (no logarithm): equal to Quantise(10 log10 power).
  [[nodiscard]] std::uint8_t QuantisePower(double power) const;
  /// QuantisePower for each of `powers`, into `levels`.
  void Convert(std::span<const double> powers, std::uint8_t* levels) const;

  /// The range loss 10^(-((S - G)·log10 r + α·r)/10) at `range_m` [m], exactly.
  [[nodiscard]] double RangeLoss(double range_m) const;
  /// The same from a table at 1/16 of a bin, linearly interpolated from 8 bins out (relative
  /// error under 1e-4 for |S - G| ≤ 20 dB per decade); exact nearer and beyond the table.
  [[nodiscard]] double RangeLossFromTable(double range_m) const;

  /// Multiplies each of `powers` by the receiver's level jitter (Acoustics::level_jitter_db),
  /// drawn from `rng`: tabled factors 10^(σ z_i / 10) at the normal's kLevelJitters quantiles,
  /// 12 bits a pick, five picks a draw; neighbouring bins share a second pick when they
  /// correlate (level_jitter_bin_correlation). No draw without jitter.
  void Jitter(std::span<double> powers, Rng& rng) const;
  static constexpr int kLevelJitters = 4096;

  /// Per bin i, the time-varied gain r^(G/10) at its centre r = (i + ½) bins, and its inverse.
  [[nodiscard]] std::span<const double> TvgAtBin() const { return tvg_at_bin_; }
  [[nodiscard]] std::span<const double> UntvgAtBin() const { return untvg_at_bin_; }
  /// Per bin, the background noise's mean power: noise_level_db's, plus noise_before_tvg_db's
  /// times the gain at the bin's centre.
  [[nodiscard]] std::span<const double> NoiseAtBin() const { return noise_at_bin_; }

 private:
  void TabulateGain(const mapping::SensorGeometry& g);
  void TabulateConverter();
  void TabulateRangeLoss(double max_range_m);
  void TabulateJitter();

  Acoustics acoustics_;
  double bin_size_m_ = 0.0;
  std::vector<double> tvg_at_bin_;
  std::vector<double> untvg_at_bin_;
  std::vector<double> noise_at_bin_;
  /// The jitter's factors, 10^(σ a z_i / 10), and the next bin's share's, 10^(σ b z_i / 10)
  /// (empty without a correlation); both empty without jitter.
  std::vector<double> level_jitter_factors_;
  std::vector<double> level_jitter_next_factors_;
  /// Power at which each converter reading begins (index 0 unused; infinite past ad_levels),
  /// the 8-bit value reported for each reading, the highest reading under the ceiling.
  std::array<double, 256> ad_thresholds_{};
  std::array<std::uint8_t, 256> ad_reported_{};
  std::uint8_t ad_top_reading_ = 255;
  /// Per bucket of powers (a double's exponent and top mantissa bits, from the bucket of
  /// ad_thresholds_[1] on), the reading at the bucket's start.
  std::vector<std::uint8_t> ad_bucket_steps_;
  std::uint64_t ad_first_bucket_ = 0;
  int ad_bucket_shift_ = 52;
  /// RangeLoss at every 1/16 of a bin from 0.
  std::vector<double> range_loss_;
  double range_steps_per_m_ = 0.0;
};

// Inline: the synthesis calls it for every echo.
[[gnu::always_inline]] inline double Receiver::RangeLossFromTable(double range_m) const {
  const double x = range_m * range_steps_per_m_;
  // From 8 bins out (128 steps) to the table's last interval; nearer, exactly (docs/physics.md).
  if (!(x >= 128.0 && x < static_cast<double>(range_loss_.size() - 1))) return RangeLoss(range_m);
  const auto k = static_cast<std::size_t>(x);
  const double f = x - static_cast<double>(k);
  return range_loss_[k] + f * (range_loss_[k + 1] - range_loss_[k]);
}

}  // namespace sonarbench::sim
