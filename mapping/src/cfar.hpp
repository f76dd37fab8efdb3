#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/mapper_config.hpp"

namespace sonarbench::mapping {

/// CA-CFAR's threshold factor α over `n` training bins: in exponential noise a bin passes
/// α · (the training bins' mean) with probability (1 + α/n)^-n = `false_alarm` (docs/mapper.md).
[[nodiscard]] double CaCfarFactor(int n, double false_alarm);
/// OS-CFAR's factor over the `k`-th smallest of `n` training bins: the false-alarm probability
/// Π_{i<k} (n - i) / (n - i + α) = `false_alarm`, solved for α.
[[nodiscard]] double OsCfarFactor(int n, int k, double false_alarm);

/// A configuration's factors (and, for OS-CFAR, order statistics) for each count of training
/// bins a bin can have: fewer than 2 · training_bins near a beam's ends.
class CfarFactors {
 public:
  explicit CfarFactors(const DetectionConfig& config);
  /// The factor over `count` training bins (2 <= count <= 2 · training_bins).
  [[nodiscard]] double factor(int count) const { return factor_[static_cast<std::size_t>(count)]; }
  /// OS-CFAR's k over `count` training bins: ceil(order · count), at least 1.
  [[nodiscard]] int order(int count) const { return order_[static_cast<std::size_t>(count)]; }
  /// The linear power of an 8-bit intensity: 10^(count · db_per_count / 10).
  [[nodiscard]] double power(std::uint8_t count) const { return power_[count]; }

 private:
  std::vector<double> factor_;
  std::vector<int> order_;
  std::array<double, 256> power_{};
};

/// Which bins of `power` (linear, from bin `first` on; those before are never training bins nor
/// detections) pass their CFAR threshold, by `config.method` (kCaCfar or kOsCfar), with the
/// factors made for `config`. A bin near the ends trains on the bins it has, its factor set for
/// their count; with fewer than two it passes none.
[[nodiscard]] std::vector<bool> CfarPasses(std::span<const double> power, int first,
                                           const DetectionConfig& config,
                                           const CfarFactors& factors);

/// A beam's 8-bit intensities as linear power (CfarFactors::power).
[[nodiscard]] std::vector<double> BeamPower(const Beam& beam, const CfarFactors& factors);

}  // namespace sonarbench::mapping
