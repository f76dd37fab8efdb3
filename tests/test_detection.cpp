#include <gtest/gtest.h>

#include "sonarbench/mapping/detection.hpp"

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

TEST(DetectThreshold, ShortSpikesAreNotObstacles) {
  const SensorGeometry sensor;
  Beam beam = MakeBeam(sensor);
  Fill(beam, 100, 101, 255);
  DetectionConfig config;
  config.smoothing_bins = 1;
  config.min_run_bins = 2;
  EXPECT_TRUE(DetectThreshold(beam, sensor, config).empty());
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

}  // namespace
}  // namespace sonarbench::mapping
