#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>

#include "rectangle_tank.hpp"
#include "sonarbench/mapping/detection.hpp"
#include "sonarbench/mapping/mapper.hpp"

namespace sonarbench::mapping {
namespace {

Beam MakeBeam(const SensorGeometry& sensor) {
  Beam beam;
  beam.bin_size_m = sensor.bin_size_m;
  beam.intensities.assign(static_cast<std::size_t>(sensor.num_bins), 0);
  return beam;
}

void Fill(Beam& beam, int from, int to, std::uint8_t value) {
  for (int k = from; k < to; ++k) beam.intensities[static_cast<std::size_t>(k)] = value;
}

TEST(DetectThreshold, UnsmoothedStepIsFoundAtItsFirstBin) {
  const SensorGeometry sensor;
  Beam beam = MakeBeam(sensor);
  Fill(beam, 150, 156, 200);
  DetectionConfig config;
  config.smoothing_bins = 1;
  const auto ranges = DetectThreshold(beam, sensor, config);
  ASSERT_EQ(ranges.size(), 1u);
  EXPECT_DOUBLE_EQ(ranges[0], beam.BinCentreRange(150));
}

// A bin is above the threshold when its (smoothed) intensity reaches it: equal counts, one less
// does not.
TEST(DetectThreshold, AnIntensityEqualToTheThresholdIsAbove) {
  const SensorGeometry sensor;
  DetectionConfig config;
  config.smoothing_bins = 1;
  config.min_run_bins = 1;
  config.threshold = 90;
  Beam beam = MakeBeam(sensor);
  Fill(beam, 150, 153, 90);
  const auto ranges = DetectThreshold(beam, sensor, config);
  ASSERT_EQ(ranges.size(), 1u);
  EXPECT_DOUBLE_EQ(ranges[0], beam.BinCentreRange(150));
  Fill(beam, 150, 153, 89);
  EXPECT_TRUE(DetectThreshold(beam, sensor, config).empty());
}

// A moving average of half-width h can pull a step's leading edge at most h bins nearer.
TEST(DetectThreshold, SmoothingMovesTheEdgeAtMostHalfAWindow) {
  const SensorGeometry sensor;
  Beam beam = MakeBeam(sensor);
  Fill(beam, 150, 160, 200);
  for (int window : {3, 5, 7}) {
    DetectionConfig config;
    config.smoothing_bins = window;
    config.threshold = 45;
    const auto ranges = DetectThreshold(beam, sensor, config);
    ASSERT_EQ(ranges.size(), 1u) << window;
    EXPECT_LE(ranges[0], beam.BinCentreRange(150));
    EXPECT_GE(ranges[0], beam.BinCentreRange(150 - window / 2));
  }
}

TEST(DetectThreshold, SelfReflectionBinsAreIgnored) {
  const SensorGeometry sensor;
  Beam beam = MakeBeam(sensor);
  Fill(beam, 0, sensor.FirstUsableBin(), 255);
  EXPECT_TRUE(DetectThreshold(beam, sensor, DetectionConfig{}).empty());
}

// The smoothing window averages usable bins only: a bright self-reflection just before the first
// usable bin never lifts it over the threshold, even for a run of one bin.
TEST(DetectThreshold, TheWindowNeverReachesIntoTheSelfReflection) {
  const SensorGeometry sensor;
  const int first = sensor.FirstUsableBin();
  Beam beam = MakeBeam(sensor);
  Fill(beam, 0, first, 255);
  DetectionConfig config;
  config.min_run_bins = 1;
  for (int window : {3, 5, 7}) {
    config.smoothing_bins = window;
    EXPECT_TRUE(DetectThreshold(beam, sensor, config).empty()) << window;
  }
}

TEST(DetectThreshold, ShortSpikesAreNotObstacles) {
  const SensorGeometry sensor;
  Beam beam = MakeBeam(sensor);
  Fill(beam, 100, 101, 255);
  DetectionConfig config;
  config.smoothing_bins = 1;
  config.min_run_bins = 2;
  EXPECT_TRUE(DetectThreshold(beam, sensor, config).empty());
}

// A run is an obstacle when it holds at least min_run_bins bins above the threshold: exactly
// that many is one, one fewer is none (unsmoothed, so a run's length is the bins filled).
TEST(DetectThreshold, ARunOfExactlyTheMinimumLengthIsAnObstacle) {
  const SensorGeometry sensor;
  for (int min_run : {1, 2, 3, 5}) {
    DetectionConfig config;
    config.smoothing_bins = 1;
    config.min_run_bins = min_run;
    Beam exact = MakeBeam(sensor);
    Fill(exact, 100, 100 + min_run, 200);
    EXPECT_EQ(DetectThreshold(exact, sensor, config),
              std::vector<double>{exact.BinCentreRange(100)})
        << "min_run_bins " << min_run;
    Beam shorter = MakeBeam(sensor);
    Fill(shorter, 100, 100 + min_run - 1, 200);
    EXPECT_TRUE(DetectThreshold(shorter, sensor, config).empty()) << "min_run_bins " << min_run;
  }
}

// The first usable bin is the first that begins at or past the self-reflection range: a bin that
// begins inside it is ignored even when the range ends inside the bin (rounded up, not down),
// and a range that ends exactly on a bin's edge leaves that bin usable.
TEST(DetectThreshold, TheSelfReflectionRangeIsRoundedUpToWholeBins) {
  SensorGeometry sensor;
  sensor.self_reflection_range_m = 0.35;  // 27.93 bins of 0.012531 m
  EXPECT_EQ(sensor.FirstUsableBin(), 28);
  DetectionConfig config;
  config.smoothing_bins = 1;
  config.min_run_bins = 1;
  Beam beam = MakeBeam(sensor);
  Fill(beam, 27, 28, 255);  // begins at 0.338 m, inside the range
  EXPECT_TRUE(DetectThreshold(beam, sensor, config).empty());
  Fill(beam, 28, 29, 255);  // begins at 0.351 m, past it
  EXPECT_EQ(DetectThreshold(beam, sensor, config), std::vector<double>{beam.BinCentreRange(28)});
  sensor.self_reflection_range_m = 10 * sensor.bin_size_m;  // on bin 10's edge
  EXPECT_EQ(sensor.FirstUsableBin(), 10);
}

TEST(DetectThreshold, FirstThenStrongestRuns) {
  const SensorGeometry sensor;
  Beam beam = MakeBeam(sensor);
  Fill(beam, 50, 55, 60);
  Fill(beam, 150, 155, 100);
  Fill(beam, 250, 255, 200);
  DetectionConfig config;
  config.smoothing_bins = 1;
  config.threshold = 50;
  config.max_obstacles = 1;
  EXPECT_EQ(DetectThreshold(beam, sensor, config), std::vector<double>{beam.BinCentreRange(50)});
  config.max_obstacles = 2;
  EXPECT_EQ(DetectThreshold(beam, sensor, config),
            (std::vector<double>{beam.BinCentreRange(50), beam.BinCentreRange(250)}));
  config.max_obstacles = 5;
  EXPECT_EQ(DetectThreshold(beam, sensor, config).size(), 3u);
}

TEST(DetectThreshold, RunReachingTheLastBinCounts) {
  const SensorGeometry sensor;
  Beam beam = MakeBeam(sensor);
  Fill(beam, sensor.num_bins - 4, sensor.num_bins, 200);
  DetectionConfig config;
  config.smoothing_bins = 1;
  EXPECT_EQ(DetectThreshold(beam, sensor, config).size(), 1u);
}

TEST(DetectThreshold, TruncatedBeamIsSafe) {
  const SensorGeometry sensor;
  Beam beam = MakeBeam(sensor);
  beam.intensities.resize(10);  // shorter than the self-reflection range
  EXPECT_TRUE(DetectThreshold(beam, sensor, DetectionConfig{}).empty());
}

// A sweep whose every beam steps from 0 to 200 at bin `edge`, with a box from `box` to `box + 10`.
std::vector<Beam> SyntheticSweep(const SensorGeometry& sensor, int edge, int box) {
  std::vector<Beam> sweep;
  for (int b = 0; b < 50; ++b) {
    Beam beam = MakeBeam(sensor);
    Fill(beam, box, box + 10, 120);
    Fill(beam, edge, sensor.num_bins, 200);
    sweep.push_back(beam);
  }
  return sweep;
}

// Canny on a 5×5-blurred step: non-maximum suppression keeps the pixel of steepest rise, within
// the blur's reach (2 bins) of the step. Only rising edges are echoes: the box's far side is not.
TEST(DetectCanny, FindsRisingEdgesWithinTheBlurRadius) {
  const SensorGeometry sensor;
  const std::vector<Beam> sweep = SyntheticSweep(sensor, 250, 120);
  for (const auto method : {DetectionConfig::Method::kCanny, DetectionConfig::Method::kAutoCanny}) {
    DetectionConfig config;
    config.method = method;
    config.max_obstacles = 5;
    const auto ranges = DetectObstacles(sweep, sensor, config);
    ASSERT_EQ(ranges.size(), sweep.size());
    for (std::size_t b = 0; b < ranges.size(); ++b) {
      ASSERT_EQ(ranges[b].size(), 2u) << "beam " << b;
      EXPECT_NEAR(ranges[b][0], sweep[b].BinCentreRange(120), 2 * sensor.bin_size_m);
      EXPECT_NEAR(ranges[b][1], sweep[b].BinCentreRange(250), 2 * sensor.bin_size_m);
    }
  }
}

// An echo is a rise along the range: an edge between beams where each is flat along its range
// (no gradient along range), or where the intensity falls with range, is none.
TEST(DetectCanny, AnEdgeBetweenBeamsIsNoEcho) {
  const SensorGeometry sensor;
  std::vector<Beam> sweep(12, MakeBeam(sensor));
  for (std::size_t b = 0; b < sweep.size(); ++b) {
    Fill(sweep[b], 0, sensor.num_bins, 200);
    if (b >= 6) Fill(sweep[b], 200, sensor.num_bins, 100);
  }
  for (const auto method : {DetectionConfig::Method::kCanny, DetectionConfig::Method::kAutoCanny}) {
    DetectionConfig config;
    config.method = method;
    const auto ranges = DetectObstacles(sweep, sensor, config);
    for (std::size_t b = 0; b < ranges.size(); ++b) {
      EXPECT_TRUE(ranges[b].empty())
          << "beam " << b << ": " << ranges[b].size() << " echoes, first at "
          << (ranges[b].empty() ? 0.0 : ranges[b][0]) << " m";
    }
  }
}

// An edge pixel one bin after an echo's is the same edge; any further one is an echo of its own. A
// comb of one-bin spikes every 3 bins (bins 100-199), under low thresholds (20, 40: the blurred
// comb's gradient swings by about 50), has a rising edge every 3 bins.
TEST(DetectCanny, RisingEdgesTwoOrMoreBinsApartAreEchoesOfTheirOwn) {
  const SensorGeometry sensor;
  std::vector<Beam> sweep(12, MakeBeam(sensor));
  for (Beam& beam : sweep) {
    for (int k = 102; k < 200; k += 3) beam.intensities[static_cast<std::size_t>(k)] = 255;
  }
  DetectionConfig config;
  config.method = DetectionConfig::Method::kCanny;
  config.canny_low = 20.0;
  config.canny_high = 40.0;
  config.max_obstacles = 100;
  const auto ranges = DetectObstacles(sweep, sensor, config);
  const auto& middle = ranges[6];
  ASSERT_GE(middle.size(), 30u);
  for (std::size_t i = 2; i < middle.size(); ++i) {
    EXPECT_NEAR(middle[i] - middle[i - 1], 3 * sensor.bin_size_m, 1e-9) << "echo " << i;
  }
}

// Automatic Canny's hysteresis thresholds are (1 ∓ 0.33) × the median, here 100: 67 and 133. A step
// of height s, blurred (5 taps, σ 1.4: its two middle taps sum to 0.543) and differentiated by the
// 3×3 Sobel (4 × the central difference), has a gradient of 2.17 s. Steps of 80 (174, strong), 40
// (87, weak but joined to the strong ones) and 20 (43, under the low threshold), in bands of beams.
TEST(DetectCanny, AutomaticThresholdsAreAFractionOfTheMedian) {
  const SensorGeometry sensor;
  std::vector<Beam> sweep(28, MakeBeam(sensor));
  for (std::size_t b = 0; b < sweep.size(); ++b) {
    const int step = b < 8 ? 80 : (b < 16 ? 40 : 20);
    Fill(sweep[b], 0, 300, 100);
    Fill(sweep[b], 300, sensor.num_bins, static_cast<std::uint8_t>(100 + step));
  }
  DetectionConfig config;
  config.method = DetectionConfig::Method::kAutoCanny;
  const auto ranges = DetectObstacles(sweep, sensor, config);
  // Beams within the blur's and Sobel's reach (3 rows) of a band's edge mix two bands.
  for (std::size_t b : {0u, 4u, 7u, 11u, 12u, 19u, 23u, 27u}) {
    if (b < 16) {
      ASSERT_EQ(ranges[b].size(), 1u) << "beam " << b;
      EXPECT_NEAR(ranges[b][0], sweep[b].BinCentreRange(300), 2 * sensor.bin_size_m);
    } else {
      EXPECT_TRUE(ranges[b].empty()) << "beam " << b << ": an echo at " << ranges[b][0] << " m";
    }
  }
}

// DetectObstacles runs the configured method: a slow ramp (1 per bin from bin 100, to 255) crosses
// the threshold 70 at bin 170 (a moving average leaves a ramp as it is), and its gradient (Sobel: 8
// per pixel) stays under Canny's thresholds.
TEST(DetectObstacles, RunsTheConfiguredMethod) {
  const SensorGeometry sensor;
  std::vector<Beam> sweep(10, MakeBeam(sensor));
  for (Beam& beam : sweep) {
    for (int k = 100; k < sensor.num_bins; ++k) {
      beam.intensities[static_cast<std::size_t>(k)] =
          static_cast<std::uint8_t>(std::min(k - 100, 255));
    }
  }
  DetectionConfig config;
  config.max_obstacles = 1;
  for (const auto& ranges : DetectObstacles(sweep, sensor, config)) {
    ASSERT_EQ(ranges.size(), 1u);
    EXPECT_DOUBLE_EQ(ranges[0], sweep[0].BinCentreRange(170));
  }
  config.method = DetectionConfig::Method::kCanny;
  for (const auto& ranges : DetectObstacles(sweep, sensor, config)) EXPECT_TRUE(ranges.empty());
}

TEST(DetectCanny, FlatSweepHasNoEchoes) {
  const SensorGeometry sensor;
  std::vector<Beam> sweep(10, MakeBeam(sensor));
  DetectionConfig config;
  config.method = DetectionConfig::Method::kCanny;
  for (const auto& r : DetectObstacles(sweep, sensor, config)) EXPECT_TRUE(r.empty());
}

// A full revolution, one beam every step: every beam hears a wall at bin `wall` and an echo at
// twice its range (a round trip); beam `shadowed` hears a box at bin 60 first.
std::vector<Beam> WallSweep(const SensorGeometry& sensor, int wall, std::size_t shadowed) {
  std::vector<Beam> sweep;
  for (int b = 0; b < sensor.BeamsPerSweep(); ++b) {
    Beam beam = MakeBeam(sensor);
    beam.head_angle_rad = b * sensor.step_angle_rad;
    Fill(beam, wall, wall + 5, 150);
    Fill(beam, 2 * wall, 2 * wall + 5, 200);
    if (static_cast<std::size_t>(b) == shadowed) Fill(beam, 60, 65, 120);
    sweep.push_back(beam);
  }
  return sweep;
}

// Supported later echoes: the wall behind the box is kept (its neighbours hear the wall first);
// the round trip, which no beam hears first, is dropped. The paper's rule keeps the strongest.
TEST(DetectObstacles, ALaterEchoNeedsANeighbourThatHearsItFirst) {
  const SensorGeometry sensor;
  const std::vector<Beam> sweep = WallSweep(sensor, 150, 7);
  DetectionConfig config;
  config.smoothing_bins = 1;
  config.threshold = 100;
  config.max_obstacles = 2;
  auto strongest = DetectObstacles(sweep, sensor, config);
  config.later_echoes = DetectionConfig::LaterEchoes::kSupported;
  auto supported = DetectObstacles(sweep, sensor, config);
  const Beam& beam = sweep[7];
  EXPECT_EQ(strongest[7], (std::vector<double>{beam.BinCentreRange(60), beam.BinCentreRange(300)}));
  EXPECT_EQ(supported[7], (std::vector<double>{beam.BinCentreRange(60), beam.BinCentreRange(150)}));
  for (std::size_t b : {0u, 6u, 8u, 199u}) {
    EXPECT_EQ(strongest[b],
              (std::vector<double>{beam.BinCentreRange(150), beam.BinCentreRange(300)}));
    EXPECT_EQ(supported[b], std::vector<double>{beam.BinCentreRange(150)}) << "beam " << b;
  }
  config.method = DetectionConfig::Method::kCanny;  // the rule follows either detector
  for (const auto& ranges : DetectObstacles(sweep, sensor, config)) EXPECT_EQ(ranges.size(), 1u);
}

// The window is in head angle, across 0 and 2π: a beam whose only support is k steps away, 8 bins
// further, keeps its later echo exactly when the window reaches k steps and the tolerance 8 bins.
TEST(DetectObstacles, SupportComesFromWithinTheWindowAndTolerance) {
  const SensorGeometry sensor;
  const double step_deg = sensor.step_angle_rad * 180.0 / std::numbers::pi;
  for (const std::size_t beam_at : {0u, 100u}) {
    for (int steps = 1; steps <= 4; ++steps) {
      std::vector<Beam> sweep;
      for (int b = 0; b < sensor.BeamsPerSweep(); ++b) {
        Beam beam = MakeBeam(sensor);
        beam.head_angle_rad = b * sensor.step_angle_rad;
        sweep.push_back(beam);
      }
      Fill(sweep[beam_at], 60, 65, 120);
      Fill(sweep[beam_at], 150, 155, 150);
      const std::size_t n = sweep.size();
      Fill(sweep[(beam_at + n - static_cast<std::size_t>(steps)) % n], 158, 163, 150);
      DetectionConfig config;
      config.smoothing_bins = 1;
      config.threshold = 100;
      config.later_echoes = DetectionConfig::LaterEchoes::kSupported;
      config.support_range_m = 8.25 * sensor.bin_size_m;
      config.support_window_deg = (steps - 0.5) * step_deg;
      EXPECT_EQ(DetectObstacles(sweep, sensor, config)[beam_at].size(), 1u) << beam_at << steps;
      config.support_window_deg = (steps + 0.5) * step_deg;
      EXPECT_EQ(DetectObstacles(sweep, sensor, config)[beam_at].size(), 2u) << beam_at << steps;
      config.support_range_m = 7.75 * sensor.bin_size_m;
      EXPECT_EQ(DetectObstacles(sweep, sensor, config)[beam_at].size(), 1u) << beam_at << steps;
    }
  }
}

// In test::RectangleWallRange's tank every beam hears its wall and, 0.6 m behind it, a mirror path;
// the beams at 10.8° to 16.2° hear the mirror path only (the wall too weak there). Beam `inside`
// hears a second echo `by` [m] within the wall's margin, beam `inside` + 1 the same beyond it.
// With `R_world_sonar`, each beam hears the wall at the range the tank gives its axis's bearing
// seen from above, so that its echoes, laid top-down along that bearing, outline the rectangle.
std::vector<Beam> TankSweep(const SensorGeometry& sensor, std::size_t inside, double by,
                            const Eigen::Matrix3d& R_world_sonar = Eigen::Matrix3d::Identity()) {
  std::vector<Beam> sweep;
  const double margin_per_m = 1.0 / std::cos(sensor.beam_width_vertical_rad / 2.0) - 1.0;
  for (int b = 0; b < sensor.BeamsPerSweep(); ++b) {
    Beam beam = MakeBeam(sensor);
    beam.head_angle_rad = b * sensor.step_angle_rad;
    beam.T_world_sonar.linear() = R_world_sonar;
    const Eigen::Vector3d axis = R_world_sonar * SonarRayDirection(beam.head_angle_rad, 0.0);
    const double wall = test::RectangleWallRange(std::atan2(axis.y(), axis.x()));
    const auto bin = [&](double range) { return static_cast<int>(range / sensor.bin_size_m); };
    if (b < 6 || b > 9) Fill(beam, bin(wall), bin(wall) + 5, 150);
    Fill(beam, bin(wall + 0.6), bin(wall + 0.6) + 5, 200);
    const double limit = wall * (1.0 + margin_per_m) + 0.05 + sensor.bin_size_m;
    if (static_cast<std::size_t>(b) == inside)
      Fill(beam, bin(limit - by), bin(limit - by) + 5, 220);
    if (static_cast<std::size_t>(b) == inside + 1)
      Fill(beam, bin(limit + by), bin(limit + by) + 5, 220);
    sweep.push_back(beam);
  }
  return sweep;
}

// TankSweep's detection: every bin as it is, its echoes over 100, up to three a beam.
DetectionConfig TankDetection(DetectionConfig::BehindWalls walls) {
  DetectionConfig config;
  config.smoothing_bins = 1;
  config.threshold = 100;
  config.max_obstacles = 3;
  config.behind_walls = walls;
  return config;
}

// Nothing heard through a wall: the walls the first echoes outline refuse every echo beyond the
// margin their own echoes can reach, and a beam that heard only through one is marked; echoes
// within the margin stay. Two bins either side of the margin (the fitted wall lies within one).
TEST(DetectObstacles, EchoesBehindTheWallsAreRefused) {
  const SensorGeometry sensor;
  const double two_bins = 2.0 * sensor.bin_size_m;
  const std::vector<Beam> sweep = TankSweep(sensor, 50, two_bins);
  DetectionConfig config = TankDetection(DetectionConfig::BehindWalls::kKeep);
  std::vector<bool> through;
  const auto kept = DetectObstacles(sweep, sensor, config, &through);
  EXPECT_EQ(kept[0].size(), 2u);  // the wall and its mirror path
  EXPECT_EQ(kept[8].size(), 1u);  // the mirror path
  EXPECT_EQ(std::count(through.begin(), through.end(), true), 0);

  config.behind_walls = DetectionConfig::BehindWalls::kRefuse;
  const auto refused = DetectObstacles(sweep, sensor, config, &through);
  ASSERT_EQ(through.size(), sweep.size());
  for (std::size_t b = 0; b < sweep.size(); ++b) {
    const bool gap = b >= 6 && b <= 9;
    EXPECT_EQ(through[b], gap) << b;
    const std::size_t expected = gap ? 0u : b == 50 ? 2u : 1u;
    ASSERT_EQ(refused[b].size(), expected) << b;
    if (!gap) {
      EXPECT_NEAR(refused[b][0], test::RectangleWallRange(sweep[b].head_angle_rad),
                  sensor.bin_size_m)
          << b;
    }
  }
  config.max_obstacles = 1;  // the first echo alone is refused as well
  EXPECT_TRUE(DetectObstacles(sweep, sensor, config)[8].empty());
}

// Top-down bearings and ranges outline vertical walls only when the fan stands near vertical: the
// tank's echoes laid out along a rolled sonar's bearings are refused behind its walls at 10° of
// roll, as upright, and not at 30° (past kMaxWallFanTilt), though they outline the same walls.
TEST(DetectObstacles, OnlyAFanNearVerticalRefusesBehindWalls) {
  const SensorGeometry sensor;
  const DetectionConfig config = TankDetection(DetectionConfig::BehindWalls::kRefuse);
  for (const double roll_deg : {10.0, 30.0}) {
    const std::vector<Beam> sweep =
        TankSweep(sensor, 50, 0.0,
                  Eigen::AngleAxisd(roll_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitX())
                      .toRotationMatrix());
    std::vector<bool> through;
    const auto kept = DetectObstacles(sweep, sensor, config, &through);
    const auto refused = std::count(through.begin(), through.end(), true);
    if (roll_deg < 20.0) {
      EXPECT_EQ(refused, 4) << roll_deg;  // the beams at 10.8-16.2° hear only the mirror path
      EXPECT_EQ(kept[0].size(), 1u) << roll_deg;
    } else {  // as if kept: even the mirror paths 0.6 m behind the 1 m wall stay
      DetectionConfig keep = config;
      keep.behind_walls = DetectionConfig::BehindWalls::kKeep;
      EXPECT_EQ(refused, 0) << roll_deg;
      EXPECT_EQ(kept, DetectObstacles(sweep, sensor, keep)) << roll_deg;
    }
  }
}

// The mapper sets aside a beam that heard only through a wall: it neither marks the echo behind
// the wall nor, left without one, clears the water through the wall to the free range. Cells are
// 5 cm; at 12.6° the gap's beam is 2° (7 cm at 3.7 m) from its neighbours' edges.
TEST(DetectObstacles, TheMapperSetsAsideABeamHeardOnlyThroughAWall) {
  const SensorGeometry sensor;
  const std::vector<Beam> sweep = TankSweep(sensor, 50, 0.0);
  MapperConfig config;
  config.resolution_m = 0.05;
  config.threads = 1;
  config.detection.smoothing_bins = 1;
  config.detection.threshold = 100;
  config.detection.max_obstacles = 2;
  const double theta = sweep[7].head_angle_rad;
  const Eigen::Vector3d bearing(std::cos(theta), std::sin(theta), 0.0);
  const Eigen::Vector3d ghost = (test::RectangleWallRange(theta) + 0.62) * bearing;
  const Eigen::Vector3d water = 1.5 * bearing;
  auto node = [](const Mapper& m, const Eigen::Vector3d& p) {
    return m.tree().search(p.x(), p.y(), p.z());
  };
  Mapper keep(config, sensor);
  keep.Integrate(sweep);
  ASSERT_NE(node(keep, ghost), nullptr);
  EXPECT_TRUE(keep.tree().isNodeOccupied(node(keep, ghost)));
  config.detection.behind_walls = DetectionConfig::BehindWalls::kRefuse;
  Mapper refuse(config, sensor);
  refuse.Integrate(sweep);
  EXPECT_EQ(node(refuse, ghost), nullptr);
  EXPECT_EQ(node(refuse, ghost + 0.3 * bearing), nullptr);
  EXPECT_EQ(node(refuse, water), nullptr);
  ASSERT_NE(node(refuse, Eigen::Vector3d(3.02, 0.0, 0.0)), nullptr);  // the wall, heard
  EXPECT_TRUE(refuse.tree().isNodeOccupied(node(refuse, Eigen::Vector3d(3.02, 0.0, 0.0))));
}

}  // namespace
}  // namespace sonarbench::mapping
