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
  /// The two mean profiles by range: over the bins whose centres lie in each band of
  /// kRangeBandsM [m, half-open], the mean of sim_mean and of real_mean; none for a band
  /// without such a bin.
  static constexpr std::array<std::array<double, 2>, 7> kRangeBandsM = {
      {{0.4, 1.5}, {1.5, 2.0}, {2.0, 2.5}, {2.5, 3.0}, {3.0, 4.0}, {4.0, 4.5}, {4.5, 5.0}}};
  /// A value per band of kRangeBandsM.
  using RangeBands = std::array<std::optional<double>, kRangeBandsM.size()>;
  RangeBands sim_band_means{};
  RangeBands real_band_means{};
  /// Per head-angle step (index = angle / step): the median, over sweeps, of the range [m] of
  /// the strongest echo beyond `wall_min_range_m` (the wall, in a tank).
  std::vector<std::optional<double>> sim_wall_m;
  std::vector<std::optional<double>> real_wall_m;
  /// The same for the strongest echo's intensity (how bright each wall is, angle by angle).
  std::vector<std::optional<double>> sim_wall_peak_by_angle;
  std::vector<std::optional<double>> real_wall_peak_by_angle;
  /// The strongest echo's intensity beyond `wall_min_range_m`, per beam: its 10th, 50th and
  /// 90th percentiles over all beams (how bright the walls are; the mean profile alone cannot
  /// tell saturated walls with dark gaps from moderate walls with a tail).
  std::array<double, 3> sim_wall_peak{};
  std::array<double, 3> real_wall_peak{};
  /// The mean intensity around each beam's strongest echo beyond `wall_min_range_m`, aligned
  /// on it: entry i is the mean, over the beams that reach it, of the bin at offset
  /// i - kWallProfileBefore from the strongest bin (the wall's echo, its width and the tail
  /// behind it, which the profile against range blurs over the tank's walls' ranges).
  std::vector<double> sim_wall_profile;
  std::vector<double> real_wall_profile;
  static constexpr int kWallProfileBefore = 40;
  static constexpr int kWallProfileAfter = 120;
  /// Mean |sim - real| of the two wall-aligned profiles from kWallTailStart bins behind the
  /// strongest echo to the end: the tail behind the walls (reverberation, ghosts) alone.
  double wall_tail_mean_abs_difference = 0.0;
  static constexpr int kWallTailStart = 16;
  /// What lies behind the walls against how squarely a beam meets them: the wall profile (above)
  /// over the beams whose head angle lies within kSquareDeg of a side's normal (0°, 90°, 180°,
  /// 270°: a tank square to head angle 0), and over those kCornerFromDeg-45° off it (towards the
  /// corners), each averaged over the offsets kBehindFirst..kBehindLast past the strongest echo.
  /// The real tank is quiet behind walls met squarely and loud towards its corners; a tail that
  /// every echo feeds alike is not (docs/fidelity.md, behind the walls).
  std::array<double, 2> sim_behind_walls{};  // {met squarely, towards the corners}
  std::array<double, 2> real_behind_walls{};
  /// The first of those (met squarely) side by side: over the beams within kSquareDeg of head
  /// angle 0°, 90°, 180° and 270°. A side unlike the others (a vehicle's part shadowing one, an
  /// object behind one) shows here, averaged away above.
  std::array<double, 4> sim_behind_walls_by_side{};
  std::array<double, 4> real_behind_walls_by_side{};
  static constexpr double kSquareDeg = 20.0;
  static constexpr double kCornerFromDeg = 30.0;
  static constexpr int kBehindFirst = 10;
  static constexpr int kBehindLast = 69;
  /// The wall profile again over the beams whose strongest echo is the wall the simulation
  /// puts there: within kDirectWallReach bins of the simulated run's median strongest range at
  /// the beam's head angle (sim_wall_m). The real log's strongest echo lies far behind its wall
  /// at some head angles (a ghost or a fixture of the tank); these beams leave them out, so the
  /// front of the wall's echo (the pulse's rise and skirts, the beam's footprint) is compared
  /// echo for echo. How many beams each averaged.
  std::vector<double> sim_direct_wall_profile;
  std::vector<double> real_direct_wall_profile;
  std::size_t sim_direct_wall_beams = 0;
  std::size_t real_direct_wall_beams = 0;
  static constexpr int kDirectWallReach = 8;
  /// Mean |sim - real| of the two direct wall profiles over the kWallFront bins in front of the
  /// strongest echo.
  double wall_front_mean_abs_difference = 0.0;
  static constexpr int kWallFront = 20;
  /// The second trip (the echo the sonar head sends out again): the mean intensity aligned on
  /// twice each beam's strongest bin beyond `wall_min_range_m`, entry i at offset
  /// i - kSecondTripReach, over the beams whose whole window lies in the usable bins. Its
  /// excess: Σ over the ring's offsets [kRingFirst, kRingLast] of (mean - the flanks' line),
  /// the flanks being the window's other offsets and their line the least-squares fit to their
  /// means (the tail behind the walls falls with range) [intensity × bins]. Without a second
  /// trip nothing marks twice the strongest bin, and the excess is near 0.
  std::vector<double> sim_second_trip_profile;
  std::vector<double> real_second_trip_profile;
  double sim_second_trip_excess = 0.0;
  double real_second_trip_excess = 0.0;
  std::size_t sim_second_trip_beams = 0;
  std::size_t real_second_trip_beams = 0;
  /// Mean |sim - real| of the two second-trip profiles over the whole window: the ring's level
  /// and shape, where the excess is its height over its flanks alone.
  double second_trip_mean_abs_difference = 0.0;
  static constexpr int kSecondTripReach = 40;
  static constexpr int kRingFirst = -30;
  static constexpr int kRingLast = 10;
  /// Median over head angles of |sim - real| wall range, in bins; and how many angles had both.
  double median_wall_difference_bins = 0.0;
  std::size_t wall_angles_compared = 0;
  /// Sweep-to-sweep spread [intensity]: per head-angle step and usable bin, the standard
  /// deviation of the intensity over the sweeps that saw it, averaged over those cells (with two
  /// or more sweeps). A static sonar's echoes and speckle repeat; only noise varies.
  double sim_sweep_spread = 0.0;
  double real_sweep_spread = 0.0;
  /// The same over the usable bins whose centres lie in each band of kRangeBandsM (none for a
  /// band without such a bin). Noise that enters a receiver before its time-varied gain rises
  /// with range, and so does the spread it gives; noise after the gain is as loud near as far.
  RangeBands sim_sweep_spread_by_band{};
  RangeBands real_sweep_spread_by_band{};
  /// The texture along range: entry m (m = 0 .. kTextureLags) is the correlation of intensities
  /// m bins apart within a beam, over the far half of the usable bins (each beam's mean taken
  /// out; covariances and variances summed over beams). Speckle that changes over the pulse
  /// length keeps it high for a few bins; structure (walls, bands) holds it up beyond.
  std::vector<double> sim_range_correlation;
  std::vector<double> real_range_correlation;
  static constexpr int kTextureLags = 8;
  /// The texture across beams: entry m (m = 0 .. kBeamLags) is the correlation of the same bins
  /// (the far half) of beams m head steps apart, m beams apart in time order (each beam's mean
  /// taken out; covariances and the geometric mean of the variances summed over pairs).
  /// Overlapping beams share scatterers, so their speckle correlates.
  std::vector<double> sim_beam_correlation;
  std::vector<double> real_beam_correlation;
  static constexpr int kBeamLags = 3;
  /// The fine texture alone: as the two correlations above, but each bin's intensity less its
  /// beam's mean over the bins within kLocalReach of it (fewer at the beam's ends), so structure
  /// wider than that window (walls' arcs, ghost bands, the fall with range) no longer holds the
  /// correlations up; what is left is the speckle's own grain. The correlations above mix the
  /// two: a log with fine, low-contrast speckle on broad structure and one with coarse speckle
  /// on little structure can give the same ones.
  std::vector<double> sim_local_range_correlation;
  std::vector<double> real_local_range_correlation;
  std::vector<double> sim_local_beam_correlation;
  std::vector<double> real_local_beam_correlation;
  /// The fine texture's contrast: the root mean square of those deviations over the mean
  /// intensity, in the same bins. Fully developed speckle (an exponential power) shows about
  /// 5.6 dB of spread in a log detector's levels; fewer deep fades, less.
  double sim_local_contrast = 0.0;
  double real_local_contrast = 0.0;
  static constexpr int kLocalReach = 15;
  /// The self-reflection (the sonar's own ringing), over the ringing bins: the bins before the
  /// usable ones whose real mean intensity is at least half the largest there (the Micron's
  /// bins 5-22), the same bins for both. Per head-angle step and bin, the intensity's mean and
  /// standard deviation over the sweeps (cells seen twice or more); then `mean`: the mean
  /// intensity; `ping_spread`: the standard deviation within a cell, averaged over the cells
  /// (how much it changes from ping to ping); `angle_spread`: per bin, the standard deviation of
  /// the cells' means over head steps, averaged over the bins (how much it changes with head
  /// angle, sweep after sweep alike); `angle_correlation`: per bin, the correlation of the cells'
  /// means 1 and kRingingFarStep head steps apart (around the turn), averaged over the bins.
  /// `by_head_angle`: per head-angle step, the mean intensity over its cells (none where no
  /// beam was), what by_head_angle.csv writes.
  struct HeadAngleCells {
    std::size_t first_bin = 0;
    std::size_t last_bin = 0;
    double mean = 0.0;
    double ping_spread = 0.0;
    double angle_spread = 0.0;
    std::array<double, 2> angle_correlation{};
    std::vector<std::optional<double>> by_head_angle;
  };
  HeadAngleCells sim_ringing;
  HeadAngleCells real_ringing;
  static constexpr int kRingingFarStep = 5;
  /// The same over the near range past the self-reflection: the first usable bin to the last
  /// whose centre lies within kNearRangeM, where a vehicle's own parts echo (by head angle, still
  /// from ping to ping: a large `angle_spread` and a small `ping_spread`).
  HeadAngleCells sim_near_range;
  HeadAngleCells real_near_range;
  static constexpr double kNearRangeM = 0.8;
  /// Intensity histograms (fractions of all usable bins), and their intersection Σ min(p, q):
  /// 1 for identical distributions, 0 for disjoint ones.
  std::array<double, 256> sim_histogram{};
  std::array<double, 256> real_histogram{};
  double histogram_intersection = 0.0;
  /// How many of the 256 values each holds, and how many the simulation holds that the real
  /// log never does: a sonar that reports fewer steps than 256 (Acoustics::ad_levels) shows
  /// as values only the simulation holds.
  std::size_t sim_values = 0;
  std::size_t real_values = 0;
  std::size_t sim_values_not_real = 0;
};

/// Compares simulated beams with real ones (both in time order; bins beyond the shorter of two
/// beams are ignored).
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

/// Writes fidelity.json, profile.csv, wall_range.csv, wall_profile.csv,
/// direct_wall_profile.csv, second_trip_profile.csv, histogram.csv, by_head_angle.csv (the
/// self-reflection's and the near range's mean per head angle: where a vehicle's parts echo),
/// profile.png (the two mean profiles), and polar and fan images of each run's first sweep side
/// by side (sim left, real right) into `out_dir`.
/// The files WriteFidelityOutputs writes, relative to its `out_dir`.
inline const std::vector<std::string> kFidelityOutputFiles = {"fidelity.json",
                                                              "profile.csv",
                                                              "profile.png",
                                                              "wall_range.csv",
                                                              "wall_profile.csv",
                                                              "direct_wall_profile.csv",
                                                              "second_trip_profile.csv",
                                                              "histogram.csv",
                                                              "by_head_angle.csv",
                                                              "polar.png",
                                                              "fan.png"};

void WriteFidelityOutputs(const std::string& out_dir, const FidelityReport& report,
                          std::span<const mapping::Beam> sim_sweep,
                          std::span<const mapping::Beam> real_sweep,
                          const mapping::SensorGeometry& sensor, const std::string& scene_file,
                          const std::string& log_file);

}  // namespace sonarbench::sim
