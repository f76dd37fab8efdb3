#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::sim {

/// How a simulated run compares with a real log of the same place.
struct FidelityReport {
  /// Mean intensity per range bin over all beams.
  std::vector<double> sim_mean;
  std::vector<double> real_mean;
  /// Pearson correlation of the two mean profiles over all bins, and over the usable bins only
  /// (past the self-reflection range).
  double profile_correlation_all = 0.0;
  double profile_correlation_usable = 0.0;
  /// Mean absolute difference of the two mean profiles over the usable bins [intensity]: the
  /// level, which a correlation ignores.
  double profile_mean_abs_difference = 0.0;
  /// Per head-angle step (index = angle / step): the median, over sweeps, of the range [m] of
  /// the strongest echo beyond `wall_min_range_m` (the wall, in a tank).
  std::vector<std::optional<double>> sim_wall_m;
  std::vector<std::optional<double>> real_wall_m;
  /// Median over head angles of |sim - real| wall range, in bins; and how many angles had both.
  double median_wall_difference_bins = 0.0;
  std::size_t wall_angles_compared = 0;
  /// Sweep-to-sweep spread [intensity]: per head-angle step and usable bin, the standard
  /// deviation of the intensity over the sweeps that saw it, averaged over those cells (with two
  /// or more sweeps). A static sonar's echoes and speckle repeat; only noise varies.
  double sim_sweep_spread = 0.0;
  double real_sweep_spread = 0.0;
  /// Intensity histograms (fractions of all usable bins), and their intersection Σ min(p, q):
  /// 1 for identical distributions, 0 for disjoint ones.
  std::array<double, 256> sim_histogram{};
  std::array<double, 256> real_histogram{};
  double histogram_intersection = 0.0;
};

/// Compares simulated beams with real ones (both in time order; bins beyond the shorter of two
/// beams are ignored).
[[nodiscard]] FidelityReport CompareWithLog(std::span<const mapping::Beam> sim,
                                            std::span<const mapping::Beam> real,
                                            const mapping::SensorGeometry& sensor,
                                            double wall_min_range_m);

/// Pearson correlation of two equally long series (0 if either is constant).
[[nodiscard]] double PearsonCorrelation(std::span<const double> a, std::span<const double> b);

/// Writes fidelity.json, profile.csv, wall_range.csv, histogram.csv, profile.png (the two mean
/// profiles), and polar and fan images of each run's first sweep side by side (sim left, real
/// right) into `out_dir`.
void WriteFidelityOutputs(const std::string& out_dir, const FidelityReport& report,
                          std::span<const mapping::Beam> sim_sweep,
                          std::span<const mapping::Beam> real_sweep,
                          const mapping::SensorGeometry& sensor, const std::string& scene_file,
                          const std::string& log_file);

}  // namespace sonarbench::sim
