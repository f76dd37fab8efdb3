#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <numbers>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/app/map_log.hpp"
#include "sonarbench/sim/app/scenario.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/report/fidelity_report.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/scene.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

using mapping::kDegToRad;
using test::RealLogPath;

// Two sweeps of beams at the sensor's head steps, beam b's bin k holding intensity(b, k).
template <typename Intensity>
std::vector<mapping::Beam> TwoSweeps(const mapping::SensorGeometry& sensor, Intensity intensity) {
  std::vector<mapping::Beam> beams;
  for (int b = 0; b < 2 * sensor.BeamsPerSweep(); ++b) {
    mapping::Beam beam;
    beam.head_angle_rad = b * sensor.step_angle_rad;
    beam.bin_size_m = sensor.bin_size_m;
    for (int k = 0; k < sensor.num_bins; ++k) beam.intensities.push_back(intensity(b, k));
    beams.push_back(beam);
  }
  return beams;
}

// Comparing a run with itself is perfect agreement; with a copy shifted by k bins, the wall
// ranges differ by exactly k bins.
TEST(Fidelity, SelfComparisonAgreesAndShiftsAreMeasuredInBins) {
  const mapping::SensorGeometry sensor;
  const std::vector<mapping::Beam> beams = TwoSweeps(sensor, [](int b, int k) -> std::uint8_t {
    if (k < 40) return 100;
    return k == 170 + b % 7 ? 200 : 10;
  });
  const auto same = sim::CompareWithLog(beams, beams, sensor, 1.6);
  EXPECT_NEAR(same.profile_correlation_all, 1.0, 1e-12);
  EXPECT_NEAR(same.histogram_intersection, 1.0, 1e-12);
  EXPECT_EQ(same.sim.values, 3u);  // 100, 200 and 10
  EXPECT_EQ(same.real.values, 3u);
  EXPECT_EQ(same.sim_values_not_real, 0u);
  EXPECT_EQ(same.median_wall_difference_bins, 0.0);
  EXPECT_EQ(same.wall_angles_compared, static_cast<std::size_t>(sensor.BeamsPerSweep()));
  std::vector<mapping::Beam> shifted = beams;
  for (auto& beam : shifted)
    std::rotate(beam.intensities.rbegin(), beam.intensities.rbegin() + 3, beam.intensities.rend());
  EXPECT_NEAR(sim::CompareWithLog(shifted, beams, sensor, 1.6).median_wall_difference_bins, 3.0,
              1e-9);
  // The background at 11 instead of 10: one value the real run never holds.
  std::vector<mapping::Beam> brighter = beams;
  for (auto& beam : brighter)
    std::replace(beam.intensities.begin(), beam.intensities.end(), 10, 11);
  const auto odd = sim::CompareWithLog(brighter, beams, sensor, 1.6);
  EXPECT_EQ(odd.sim.values, 3u);
  EXPECT_EQ(odd.sim_values_not_real, 1u);
}

// The profile by range: intensity 10 up to bin 358 and 50 from bin 359, which starts at 4.4986 m
// but whose centre, 4.5049 m, lies in the last band (4.5-5 m): a bin belongs to the band of its
// centre. So every band reads 10 but the last, 50 (its bins end at bin 398, 4.9932 m). A sensor
// whose 100 bins end at 1.25 m has bins in the first band only (from bin 32: bin 31's centre is
// 0.3947 m), and the other bands are none; sim and real are each their own run's.
TEST(Fidelity, RangeBandsAreTheMeanProfileOverTheirBins) {
  const mapping::SensorGeometry sensor;
  const std::vector<mapping::Beam> beams =
      TwoSweeps(sensor, [](int, int k) -> std::uint8_t { return k < 359 ? 10 : 50; });
  const std::vector<mapping::Beam> flat =
      TwoSweeps(sensor, [](int, int) -> std::uint8_t { return 30; });
  const auto r = sim::CompareWithLog(beams, flat, sensor, 1.6);
  const std::array<double, 7> expected = {10, 10, 10, 10, 10, 10, 50};
  for (std::size_t b = 0; b < expected.size(); ++b) {
    ASSERT_TRUE(r.sim.band_means[b].has_value()) << b;
    EXPECT_DOUBLE_EQ(*r.sim.band_means[b], expected[b]) << b;
    EXPECT_DOUBLE_EQ(r.real.band_means[b].value_or(-1.0), 30.0) << b;
  }
  mapping::SensorGeometry short_range;
  short_range.num_bins = 100;
  const std::vector<mapping::Beam> near = TwoSweeps(
      short_range, [](int, int k) -> std::uint8_t { return static_cast<std::uint8_t>(k); });
  const auto n = sim::CompareWithLog(near, near, short_range, 0.5);
  ASSERT_TRUE(n.sim.band_means[0].has_value());
  EXPECT_DOUBLE_EQ(*n.sim.band_means[0], (32 + 99) / 2.0);  // bins 32-99, intensity k
  for (std::size_t b = 1; b < n.sim.band_means.size(); ++b) {
    EXPECT_FALSE(n.sim.band_means[b].has_value()) << b;
  }
}

// The wall's echo strength: each beam's strongest intensity beyond the wall's minimum range,
// 100 + (beam mod 100) here, so the 400 beams hold each of 100..199 four times and the sorted
// values at 40, 200 and 360 are 110, 150 and 190. Brighter echoes before that range (the
// self-reflection's 230) do not count.
TEST(Fidelity, WallPeaksArePercentilesOfEachBeamsStrongestEcho) {
  const mapping::SensorGeometry sensor;
  const std::vector<mapping::Beam> beams = TwoSweeps(sensor, [](int b, int k) -> std::uint8_t {
    if (k < 40) return 230;
    return k == 170 ? static_cast<std::uint8_t>(100 + b % 100) : 10;
  });
  const auto report = sim::CompareWithLog(beams, beams, sensor, 1.6);
  EXPECT_EQ(report.sim.wall_peak, (std::array<double, 3>{110.0, 150.0, 190.0}));
  EXPECT_EQ(report.real.wall_peak, report.sim.wall_peak);
  // Per head angle, the median over its two sweeps' beams b and b + 200: 100 + b mod 100 both.
  ASSERT_EQ(report.sim.wall_peak_by_angle.size(), 200u);
  for (std::size_t a = 0; a < 200; ++a) {
    ASSERT_TRUE(report.sim.wall_peak_by_angle[a].has_value());
    EXPECT_EQ(*report.sim.wall_peak_by_angle[a], 100.0 + static_cast<double>(a % 100));
  }
  // Aligned on the wall (bin 170), the profile is 10 everywhere but at offset 0, the peaks'
  // mean 149.5 (its offsets reach back to bin 130, clear of the first 40 bins' 230).
  ASSERT_EQ(report.sim.wall_profile.size(), 161u);
  for (std::size_t i = 0; i < report.sim.wall_profile.size(); ++i) {
    const double expected = i == 40 ? 149.5 : 10.0;
    EXPECT_DOUBLE_EQ(report.sim.wall_profile[i], expected) << "offset " << i - 40.0;
  }
  EXPECT_EQ(report.wall_tail_mean_abs_difference, 0.0);
  // A real log 5 brighter everywhere past the wall's first 16 bins differs by 5 in the tail.
  std::vector<mapping::Beam> brighter = beams;
  for (auto& beam : brighter) {
    for (std::size_t k = 170 + 16; k < beam.intensities.size(); ++k) beam.intensities[k] += 5;
  }
  EXPECT_DOUBLE_EQ(sim::CompareWithLog(beams, brighter, sensor, 1.6).wall_tail_mean_abs_difference,
                   5.0);
}

// Behind the walls by the angle off the sides' normals: every beam's wall (200) at bin 170, and
// 10-69 bins behind it a value by the beam's head angle past the last multiple of 90° (1.8°
// steps): 60 at 0-19.8° and 40 at 70.2-88.2° (within 20° of a normal, one side or the other: 12
// and 11 beams a quadrant, a mean of 1160 / 23), 100 at 30.6-43.2° and 80 at 46.8-59.4° (30-45°
// off: 8 beams a quadrant each), 90 at 45° (a beam either side may count, or neither: the mean
// is 90 with it or without it), and 150 between, which neither band holds; 10 elsewhere.
TEST(Fidelity, BehindWallsSplitsTheBeamsByTheirAngleOffTheSidesNormals) {
  const mapping::SensorGeometry sensor;
  const std::vector<mapping::Beam> beams = TwoSweeps(sensor, [](int b, int k) -> std::uint8_t {
    if (k == 170) return 200;
    if (k < 180 || k > 239) return 10;
    const int tenths = (b * 18) % 900;  // the head angle past the last multiple of 90°, in 0.1°
    if (tenths <= 200) return 60;
    if (tenths >= 700) return 40;
    if (tenths == 450) return 90;
    if (tenths >= 300 && tenths < 450) return 100;
    if (tenths > 450 && tenths <= 600) return 80;
    return 150;
  });
  const auto report = sim::CompareWithLog(beams, beams, sensor, 1.6);
  EXPECT_NEAR(report.sim.behind_walls[0], 1160.0 / 23.0, 1e-12);
  EXPECT_NEAR(report.sim.behind_walls[1], 90.0, 1e-12);
  EXPECT_EQ(report.real.behind_walls, report.sim.behind_walls);
}

// The sweep-to-sweep spread by range band: every beam 50, but in the second sweep each bin of band
// b (its centre in FidelityReport::kRangeBandsM[b]) 2(b + 1) higher, so each of its cells holds
// two values that far apart, whose standard deviation is 2(b + 1)/√2; the bins past the bands and
// before the usable ones are the same in both sweeps.
TEST(Fidelity, SweepSpreadIsMeasuredBandByBand) {
  const mapping::SensorGeometry sensor;
  const auto& bands = sim::FidelityReport::kRangeBandsM;
  const auto band_of = [&](int k) {
    const double centre = (k + 0.5) * sensor.bin_size_m;
    for (std::size_t b = 0; b < bands.size(); ++b) {
      if (centre >= bands[b][0] && centre < bands[b][1]) return static_cast<int>(b);
    }
    return -1;
  };
  const std::vector<mapping::Beam> beams = TwoSweeps(sensor, [&](int b, int k) -> std::uint8_t {
    const int band = band_of(k);
    const bool second = b >= sensor.BeamsPerSweep();
    return static_cast<std::uint8_t>(50 + (second && band >= 0 ? 2 * (band + 1) : 0));
  });
  const auto report = sim::CompareWithLog(beams, beams, sensor, 1.6);
  for (std::size_t b = 0; b < bands.size(); ++b) {
    ASSERT_TRUE(report.sim.sweep_spread_by_band[b].has_value()) << bands[b][0] << " m";
    // To rounding: the variance comes from sums of squares near 5000.
    EXPECT_NEAR(*report.sim.sweep_spread_by_band[b], 2.0 * (b + 1.0) / std::sqrt(2.0), 1e-9)
        << bands[b][0] << " m";
  }
  EXPECT_EQ(report.real.sweep_spread_by_band, report.sim.sweep_spread_by_band);
}

// Behind the walls met squarely, side by side: every beam's wall (200) at bin 170, and 10-69
// bins behind it 30, 50, 70 and 90 for the beams within 20° of head angle 0°, 90°, 180° and 270°
// (23 a side in each sweep, the second sweep's angles past 360°), 10 elsewhere. Each side reads
// its own value, and all four together their mean.
TEST(Fidelity, BehindWallsMetSquarelyIsMeasuredSideBySide) {
  const mapping::SensorGeometry sensor;
  const std::vector<mapping::Beam> beams = TwoSweeps(sensor, [](int b, int k) -> std::uint8_t {
    if (k == 170) return 200;
    if (k < 180 || k > 239) return 10;
    const int tenths = (b * 18) % 3600;  // the head angle in [0°, 360°), in 0.1°
    const int side = ((tenths + 450) / 900) % 4;
    const int off = std::abs(tenths - side * 900 - (side == 0 && tenths > 1800 ? 3600 : 0));
    return off <= 200 ? static_cast<std::uint8_t>(30 + 20 * side) : 10;
  });
  const auto report = sim::CompareWithLog(beams, beams, sensor, 1.6);
  const std::array<double, 4> expected = {30.0, 50.0, 70.0, 90.0};
  for (std::size_t side = 0; side < 4; ++side) {
    EXPECT_NEAR(report.sim.behind_walls_by_side[side], expected[side], 1e-12)
        << side * 90 << " deg";
  }
  EXPECT_NEAR(report.sim.behind_walls[0], 60.0, 1e-12);
  EXPECT_EQ(report.real.behind_walls_by_side, report.sim.behind_walls_by_side);
}

// The direct wall profile: the simulated walls (200) are at bin 170 at every head angle; the
// real log's too, with a front of 60 over the 5 bins before them, but every 4th of its beams
// also holds a ghost (230) at bin 250, its strongest echo. The all-beam profile aligns those on
// the ghost; the direct one leaves them out (300 of 400 real beams), so its front is 60 and its
// peak 200, and the front's mean |difference| is 5 bins x 50 over the 20 bins: 12.5. A real
// wall 8 bins from the simulated one is still the wall; 9 bins is not.
TEST(Fidelity, DirectWallProfileKeepsTheBeamsWhoseStrongestIsTheSimulatedWall) {
  const mapping::SensorGeometry sensor;
  const std::vector<mapping::Beam> sim =
      TwoSweeps(sensor, [](int, int k) -> std::uint8_t { return k == 170 ? 200 : 10; });
  const std::vector<mapping::Beam> real = TwoSweeps(sensor, [](int b, int k) -> std::uint8_t {
    if (k == 170) return 200;
    if (k >= 165 && k < 170) return 60;
    return b % 4 == 0 && k == 250 ? 230 : 10;
  });
  const auto report = sim::CompareWithLog(sim, real, sensor, 1.0);
  EXPECT_EQ(report.sim.direct_wall_beams, 400u);
  EXPECT_EQ(report.real.direct_wall_beams, 300u);
  ASSERT_EQ(report.real.direct_wall_profile.size(), 161u);
  EXPECT_DOUBLE_EQ(report.real.wall_profile[40], 207.5);  // 300 walls and 100 ghosts
  for (std::size_t i = 0; i < report.real.direct_wall_profile.size(); ++i) {
    const double expected = i == 40 ? 200.0 : (i >= 35 && i < 40 ? 60.0 : 10.0);
    EXPECT_DOUBLE_EQ(report.real.direct_wall_profile[i], expected) << "offset " << i - 40.0;
    EXPECT_DOUBLE_EQ(report.sim.direct_wall_profile[i], i == 40 ? 200.0 : 10.0);
  }
  EXPECT_DOUBLE_EQ(report.wall_front_mean_abs_difference, 12.5);
  const auto wall_at = [&](int bin) {
    return TwoSweeps(sensor, [&](int, int k) -> std::uint8_t { return k == bin ? 200 : 10; });
  };
  EXPECT_EQ(sim::CompareWithLog(sim, wall_at(178), sensor, 1.0).real.direct_wall_beams, 400u);
  EXPECT_EQ(sim::CompareWithLog(sim, wall_at(179), sensor, 1.0).real.direct_wall_beams, 0u);
  EXPECT_EQ(sim::CompareWithLog(sim, wall_at(162), sensor, 1.0).real.direct_wall_beams, 400u);
  EXPECT_EQ(sim::CompareWithLog(sim, wall_at(161), sensor, 1.0).real.direct_wall_beams, 0u);
}

// The second trip: beams whose strongest echo (200) is at bin 120 + b mod 10, on a background
// falling with range (120 - ⌊k/4⌋), and in the "real" copy a ring around twice the wall's bin:
// +3 at offsets -6..-2, 0, 2 and 4 (8 bins, 24 in all). The flanks are the same in both, so
// the excesses differ by the ring's 24 exactly, and the flanks' line leaves the background
// within its flooring (near 0). Beams whose window leaves the beam are skipped: every 20th
// beam's wall at bin 185 puts twice it past the last bin.
TEST(Fidelity, SecondTripExcessIsTheRingAboveItsFlanksLine) {
  const mapping::SensorGeometry sensor;
  const auto background = [](int k) { return static_cast<std::uint8_t>(120 - k / 4); };
  const std::vector<int> ring_offsets = {-6, -5, -4, -3, -2, 0, 2, 4};
  const auto beams_with = [&](int ring) {
    return TwoSweeps(sensor, [&](int b, int k) -> std::uint8_t {
      const int wall = b % 20 == 19 ? 185 : 120 + b % 10;
      if (k == wall) return 200;
      std::uint8_t v = background(k);
      for (const int o : ring_offsets) {
        if (k == 2 * wall + o) v = static_cast<std::uint8_t>(v + ring);
      }
      return v;
    });
  };
  const std::vector<mapping::Beam> flat = beams_with(0);
  const std::vector<mapping::Beam> ringing = beams_with(3);
  const auto report = sim::CompareWithLog(flat, ringing, sensor, 1.0);
  // background(k) = 120 - floor(k / 4) is a line only to within its flooring: the flanks' fit
  // leaves at most 1 per bin over the ring's 41 bins, about its mean 0.
  EXPECT_NEAR(report.sim.second_trip_excess, 0.0, 2.0);
  EXPECT_NEAR(report.real.second_trip_excess - report.sim.second_trip_excess, 24.0, 1e-9);
  EXPECT_EQ(report.sim.second_trip_beams, 2u * 200u * 19u / 20u);
  EXPECT_EQ(report.real.second_trip_beams, report.sim.second_trip_beams);
  ASSERT_EQ(report.real.second_trip_profile.size(), 81u);
  EXPECT_NEAR(report.real.second_trip_profile[40 - 6] - report.sim.second_trip_profile[40 - 6], 3.0,
              1e-9);
  EXPECT_NEAR(report.real.second_trip_profile[40 - 1] - report.sim.second_trip_profile[40 - 1], 0.0,
              1e-9);
  // The profiles differ by the ring's 3 at 8 of the window's 81 offsets.
  EXPECT_NEAR(report.second_trip_mean_abs_difference, 24.0 / 81.0, 1e-9);
}

// The texture along range: intensities alternating 50, 150 bin by bin are perfectly
// anti-correlated at odd lags and correlated at even ones (the far half, bins 213-398 of the
// default geometry, holds an even count, so each beam's mean is exactly 100).
TEST(Fidelity, RangeCorrelationIsTheAutocorrelationAlongEachBeam) {
  const mapping::SensorGeometry sensor;
  const std::vector<mapping::Beam> beams =
      TwoSweeps(sensor, [](int, int k) -> std::uint8_t { return k % 2 == 0 ? 50 : 150; });
  const auto report = sim::CompareWithLog(beams, beams, sensor, 1.6);
  ASSERT_EQ(report.sim.range_correlation.size(), 9u);
  for (std::size_t m = 0; m < report.sim.range_correlation.size(); ++m) {
    EXPECT_NEAR(report.sim.range_correlation[m], m % 2 == 0 ? 1.0 : -1.0, 1e-12) << "lag " << m;
  }
}

// The texture across beams: beam b's far-half bins alternate 50, 150, shifted by one bin on odd
// beams, so beams an odd number of head steps apart are perfectly anti-correlated and even ones
// correlated; a beam of the other sweep that is not m steps on is never paired.
TEST(Fidelity, BeamCorrelationPairsBeamsByHeadStep) {
  const mapping::SensorGeometry sensor;
  const std::vector<mapping::Beam> beams =
      TwoSweeps(sensor, [](int b, int k) -> std::uint8_t { return (k + b) % 2 == 0 ? 50 : 150; });
  const auto report = sim::CompareWithLog(beams, beams, sensor, 1.6);
  ASSERT_EQ(report.sim.beam_correlation.size(), 4u);
  for (std::size_t m = 0; m < report.sim.beam_correlation.size(); ++m) {
    EXPECT_NEAR(report.sim.beam_correlation[m], m % 2 == 0 ? 1.0 : -1.0, 1e-12) << "step " << m;
  }
}

// The fine texture: the same alternating 50, 150 less each bin's mean over the bins within 15
// of it. A window of n bins (31 inside the beam, 16-30 at its end) holds one more bin of one
// value than of the other, or as many, so every deviation is ±50 (1 ± 1/n) or ±50, within
// 50 · [15/16, 17/16], its sign alternating bin by bin: lag-m correlations are at least
// (15/17)² in size, negative at odd m, and the contrast (rms over the mean, 100) lies in
// 0.5 · [15/16, 17/16]. Shifted by one bin on odd beams, odd head steps anti-correlate alike.
TEST(Fidelity, FineTextureIsTheDeviationFromTheLocalMean) {
  const mapping::SensorGeometry sensor;
  const double bound = (15.0 / 17.0) * (15.0 / 17.0);
  const std::vector<mapping::Beam> along =
      TwoSweeps(sensor, [](int, int k) -> std::uint8_t { return k % 2 == 0 ? 50 : 150; });
  const auto report = sim::CompareWithLog(along, along, sensor, 1.6);
  ASSERT_EQ(report.sim.local_range_correlation.size(), 9u);
  for (std::size_t m = 1; m < report.sim.local_range_correlation.size(); ++m) {
    const double c = report.sim.local_range_correlation[m];
    if (m % 2 == 1) {
      EXPECT_LT(c, -bound) << "lag " << m;
    } else {
      EXPECT_GT(c, bound) << "lag " << m;
    }
  }
  EXPECT_GE(report.sim.local_contrast, 0.5 * 15.0 / 16.0);
  EXPECT_LE(report.sim.local_contrast, 0.5 * 17.0 / 16.0);
  EXPECT_EQ(report.real.local_contrast, report.sim.local_contrast);

  const std::vector<mapping::Beam> across =
      TwoSweeps(sensor, [](int b, int k) -> std::uint8_t { return (k + b) % 2 == 0 ? 50 : 150; });
  const auto shifted = sim::CompareWithLog(across, across, sensor, 1.6);
  ASSERT_EQ(shifted.sim.local_beam_correlation.size(), 4u);
  EXPECT_LT(shifted.sim.local_beam_correlation[1], -bound);
  EXPECT_GT(shifted.sim.local_beam_correlation[2], bound);
  EXPECT_LT(shifted.sim.local_beam_correlation[3], -bound);
}

// The sweep-to-sweep spread: two identical sweeps spread 0; a second sweep brighter by d in
// every bin spreads d/√2 in every cell (the sample standard deviation of {v, v + d}).
TEST(Fidelity, SweepSpreadIsTheStandardDeviationAcrossSweepsPerAngleAndBin) {
  const mapping::SensorGeometry sensor;
  std::vector<mapping::Beam> two_sweeps = TwoSweeps(sensor, [&sensor](int b, int k) {
    return static_cast<std::uint8_t>((k * 7 + b % sensor.BeamsPerSweep()) % 200);
  });
  EXPECT_EQ(sim::CompareWithLog(two_sweeps, two_sweeps, sensor, 1.6).sim.sweep_spread, 0.0);
  for (std::size_t b = static_cast<std::size_t>(sensor.BeamsPerSweep()); b < two_sweeps.size();
       ++b) {
    for (auto& v : two_sweeps[b].intensities) v = static_cast<std::uint8_t>(v + 6);
  }
  const auto report = sim::CompareWithLog(two_sweeps, two_sweeps, sensor, 1.6);
  EXPECT_NEAR(report.sim.sweep_spread, 6.0 / std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(report.real.sweep_spread, 6.0 / std::sqrt(2.0), 1e-9);
}

// The self-reflection's statistics over its bins: the real log's mean is 0 but in bins 5-22
// (before the usable bins from 28), where it is 100 + 10 at even head steps and - 10 at odd
// ones, 3 lower in the first sweep and 3 higher in the second; plus a step of 60 at bin 4 in the
// simulated run alone (not a ringing bin: the bins are the real log's). So bins 5-22, mean 100
// (real; the simulated one too, bin 4 left out), from ping to ping the two sweeps' standard
// deviation 6/√2, across head angles the ±10's, 10 √(200/199), and neighbouring head steps, or
// five apart, correlating by -1.
TEST(Fidelity, SelfReflectionIsMeasuredOverItsBinsPerHeadAngleAndSweep) {
  const mapping::SensorGeometry sensor;
  const int steps = sensor.BeamsPerSweep();
  const auto ringing = [steps](int b, int k) -> std::uint8_t {
    if (k < 5 || k > 22) return 0;
    return static_cast<std::uint8_t>(100 + (b % 2 == 0 ? 10 : -10) + (b < steps ? -3 : 3));
  };
  const std::vector<mapping::Beam> real = TwoSweeps(sensor, ringing);
  const std::vector<mapping::Beam> sim =
      TwoSweeps(sensor, [&](int b, int k) -> std::uint8_t { return k == 4 ? 60 : ringing(b, k); });
  const auto report = sim::CompareWithLog(sim, real, sensor, 1.6);
  for (const auto* r : {&report.sim.ringing, &report.real.ringing}) {
    EXPECT_EQ(r->first_bin, 5u);
    EXPECT_EQ(r->last_bin, 22u);
    EXPECT_DOUBLE_EQ(r->mean, 100.0);
    EXPECT_NEAR(r->ping_spread, 6.0 / std::sqrt(2.0), 1e-9);
    EXPECT_NEAR(r->angle_spread, 10.0 * std::sqrt(200.0 / 199.0), 1e-9);
    EXPECT_NEAR(r->angle_correlation[0], -1.0, 1e-9);
    EXPECT_NEAR(r->angle_correlation[1], -1.0, 1e-9);
  }
}

// The near range past the self-reflection (bins 28-63 of the Micron's 0.0125 m, centres within
// 0.8 m): beams at head steps 0-99 hear 60 there (a vehicle's part), the rest 20, both sweeps
// alike, and 0 elsewhere but a ringing at 100 in bins 5-22 (so the ringing bins are those):
// per head angle 60 or 20, mean 40, no spread from ping to ping, and across head angles the
// standard deviation of a hundred 60s and a hundred 20s. Its per-head-angle means go to
// by_head_angle.csv.
TEST(Fidelity, NearRangeIsMeasuredPerHeadAngle) {
  const mapping::SensorGeometry sensor;
  const int steps = sensor.BeamsPerSweep();
  const std::vector<mapping::Beam> beams = TwoSweeps(sensor, [steps](int b, int k) -> std::uint8_t {
    if (k >= 5 && k <= 22) return 100;
    if (k >= 28 && k <= 63) return b % steps < 100 ? 60 : 20;
    return 0;
  });
  const auto report = sim::CompareWithLog(beams, beams, sensor, 1.6);
  const sim::FidelityReport::HeadAngleCells& near = report.real.near_range;
  EXPECT_EQ(near.first_bin, 28u);
  EXPECT_EQ(near.last_bin, 63u);
  EXPECT_DOUBLE_EQ(near.mean, 40.0);
  EXPECT_DOUBLE_EQ(near.ping_spread, 0.0);
  EXPECT_NEAR(near.angle_spread, 20.0 * std::sqrt(200.0 / 199.0), 1e-9);
  ASSERT_EQ(near.by_head_angle.size(), static_cast<std::size_t>(steps));
  EXPECT_EQ(near.by_head_angle[0], 60.0);
  EXPECT_EQ(near.by_head_angle[99], 60.0);
  EXPECT_EQ(near.by_head_angle[100], 20.0);
  EXPECT_EQ(report.real.ringing.by_head_angle[150], 100.0);

  test::TempDir dir;
  sim::WriteFidelityOutputs(dir.path().string(), report, beams, beams, sensor, "scene.yaml",
                            "log.mat");
  std::ifstream csv(dir.path() / "by_head_angle.csv");
  std::string header;
  std::string first;
  std::getline(csv, header);
  std::getline(csv, first);
  EXPECT_EQ(header,
            "head_angle_deg,sim_self_reflection,real_self_reflection,sim_near_range,"
            "real_near_range");
  EXPECT_EQ(first, "0,100.000000,100.000000,60.000000,60.000000");
}

}  // namespace
}  // namespace sonarbench
