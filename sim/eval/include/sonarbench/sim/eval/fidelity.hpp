#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::sim {

/// How a simulated run compares with a real log of the same place: each side's statistics
/// (Stats, from Measure), then what compares them. docs/fidelity.md explains each statistic.
struct FidelityReport {
  /// Range bands [m, half-open] over which profiles and spreads are averaged, a value per band
  /// (none for a band without a bin whose centre lies in it).
  static constexpr std::array<std::array<double, 2>, 7> kRangeBandsM = {
      {{0.4, 1.5}, {1.5, 2.0}, {2.0, 2.5}, {2.5, 3.0}, {3.0, 4.0}, {4.0, 4.5}, {4.5, 5.0}}};
  using RangeBands = std::array<std::optional<double>, kRangeBandsM.size()>;
  /// The wall-aligned profiles: offsets -kWallProfileBefore..kWallProfileAfter bins around each
  /// beam's strongest echo; the tail from kWallTailStart behind it; the front, kWallFront bins
  /// before it, over the beams within kDirectWallReach bins of the reference wall.
  static constexpr int kWallProfileBefore = 40;
  static constexpr int kWallProfileAfter = 120;
  static constexpr int kWallTailStart = 16;
  static constexpr int kDirectWallReach = 8;
  static constexpr int kWallFront = 20;
  /// Behind the walls: the mean over offsets kBehindFirst..kBehindLast past the strongest echo,
  /// over beams within kSquareDeg of a side's normal (0°, 90°, 180°, 270°) and beams
  /// kCornerFromDeg-45° off it.
  static constexpr double kSquareDeg = 20.0;
  static constexpr double kCornerFromDeg = 30.0;
  static constexpr int kBehindFirst = 10;
  static constexpr int kBehindLast = 69;
  /// The second trip: offsets ±kSecondTripReach around twice the strongest bin, the ring over
  /// [kRingFirst, kRingLast].
  static constexpr int kSecondTripReach = 40;
  static constexpr int kRingFirst = -30;
  static constexpr int kRingLast = 10;
  /// Texture: correlations at 0..kTextureLags bins and 0..kBeamLags head steps, over the far
  /// half of the usable bins; the fine texture less each bin's mean over ±kLocalReach bins.
  static constexpr int kTextureLags = 8;
  static constexpr int kBeamLags = 3;
  static constexpr int kLocalReach = 15;
  /// Cells' correlation across head angles at 1 and kRingingFarStep steps; the near range ends
  /// at kNearRangeM.
  static constexpr int kRingingFarStep = 5;
  static constexpr double kNearRangeM = 0.8;

  /// Per head-angle step and bin over bins [first_bin, last_bin], the intensity's mean and
  /// spread over sweeps: `mean`; `ping_spread` (within a cell, averaged); `angle_spread` (of
  /// the cells' means across head steps, averaged over bins); `angle_correlation` of the cells'
  /// means 1 and kRingingFarStep steps apart; `by_head_angle` the mean per head-angle step.
  struct HeadAngleCells {
    std::size_t first_bin = 0;
    std::size_t last_bin = 0;
    double mean = 0.0;
    double ping_spread = 0.0;
    double angle_spread = 0.0;
    std::array<double, 2> angle_correlation{};
    std::vector<std::optional<double>> by_head_angle;
  };

  /// One side's statistics. Intensities are the sonar's 0-255 levels; bins past the
  /// self-reflection are the usable ones; the strongest echo is sought past the walls' minimum
  /// range.
  struct Stats {
    /// Mean intensity per range bin, and per range band.
    std::vector<double> mean;
    RangeBands band_means{};
    /// Per head-angle step (index = angle / step), the median over sweeps of the strongest
    /// echo's range [m] and intensity.
    std::vector<std::optional<double>> wall_m;
    std::vector<std::optional<double>> wall_peak_by_angle;
    /// The strongest echo's intensity per beam: its 10th, 50th and 90th percentiles.
    std::array<double, 3> wall_peak{};
    /// Mean intensity aligned on each beam's strongest echo (entry i at offset
    /// i - kWallProfileBefore), over all beams and over the direct-wall beams.
    std::vector<double> wall_profile;
    std::vector<double> direct_wall_profile;
    std::size_t direct_wall_beams = 0;
    /// Behind the walls {met squarely, towards the corners}, and met squarely by side.
    std::array<double, 2> behind_walls{};
    std::array<double, 4> behind_walls_by_side{};
    /// Mean intensity aligned on twice the strongest bin (entry i at offset
    /// i - kSecondTripReach), its ring's excess over the flanks' line [intensity × bins], and
    /// the beams it averaged.
    std::vector<double> second_trip_profile;
    double second_trip_excess = 0.0;
    std::size_t second_trip_beams = 0;
    /// Sweep-to-sweep standard deviation per head-angle step and usable bin, averaged; and per
    /// range band.
    double sweep_spread = 0.0;
    RangeBands sweep_spread_by_band{};
    /// Correlation of intensities m bins apart along a beam and of beams m head steps apart;
    /// the same for the fine texture; and the fine texture's contrast (RMS over the mean).
    std::vector<double> range_correlation;
    std::vector<double> beam_correlation;
    std::vector<double> local_range_correlation;
    std::vector<double> local_beam_correlation;
    double local_contrast = 0.0;
    /// The self-reflection's ringing bins and the near range past them, per head angle.
    HeadAngleCells ringing;
    HeadAngleCells near_range;
    /// Intensity histogram (fractions of all usable bins) and how many of the 256 values occur.
    std::array<double, 256> histogram{};
    std::size_t values = 0;
  };
  Stats sim;
  Stats real;

  /// Pearson correlation of the two mean profiles over all bins and over the usable bins, and
  /// their mean |difference| over the usable bins.
  double profile_correlation_all = 0.0;
  double profile_correlation_usable = 0.0;
  double profile_mean_abs_difference = 0.0;
  /// Mean |sim - real| of the wall profiles' tails, of the direct wall profiles' fronts, and of
  /// the second-trip profiles.
  double wall_tail_mean_abs_difference = 0.0;
  double wall_front_mean_abs_difference = 0.0;
  double second_trip_mean_abs_difference = 0.0;
  /// Median over head angles of |sim - real| wall range [bins], and the angles that had both.
  double median_wall_difference_bins = 0.0;
  std::size_t wall_angles_compared = 0;
  /// Σ min(p, q) of the histograms, and the values only the simulation holds.
  double histogram_intersection = 0.0;
  std::size_t sim_values_not_real = 0;
};

/// What Measure needs besides the beams: where walls begin, the walls' ranges per head-angle
/// step that pick the direct-wall beams (empty: the beams' own), and the ringing bins (none: no
/// ringing statistics).
struct FidelitySettings {
  double wall_min_range_m = 1.6;
  std::vector<std::optional<double>> reference_wall_m;
  std::optional<std::array<std::size_t, 2>> ringing_bins;
};

/// One side's statistics.
[[nodiscard]] FidelityReport::Stats Measure(std::span<const mapping::Beam> beams,
                                            const mapping::SensorGeometry& sensor,
                                            const FidelitySettings& settings);

/// The comparisons of two sides' statistics.
void Compare(FidelityReport& report, const mapping::SensorGeometry& sensor);

/// Compares simulated beams with real ones (both in time order; bins beyond the shorter of two
/// beams are ignored): both measured with the real log's ringing bins and the simulated walls as
/// the direct-wall reference, then compared.
[[nodiscard]] FidelityReport CompareWithLog(std::span<const mapping::Beam> sim,
                                            std::span<const mapping::Beam> real,
                                            const mapping::SensorGeometry& sensor,
                                            double wall_min_range_m);

/// Pearson correlation of two equally long series (0 if either is constant).
[[nodiscard]] double PearsonCorrelation(std::span<const double> a, std::span<const double> b);

/// The second-trip profile and excess of FidelityReport for `beams`, whose strongest bins
/// beyond the walls' minimum range are `strongest` and whose usable bins start at
/// `first_usable`; returns how many beams it averaged.
std::size_t SecondTripProfile(std::span<const mapping::Beam> beams,
                              std::span<const std::optional<std::size_t>> strongest,
                              std::size_t first_usable, std::vector<double>& profile,
                              double& excess);

}  // namespace sonarbench::sim
