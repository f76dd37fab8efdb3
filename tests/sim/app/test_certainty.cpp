#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/app/certainty.hpp"

namespace sonarbench::sim {
namespace {

// Three sweeps of a static sonar in a round room of radius 2 m: every beam's echo at the wall.
std::vector<mapping::Beam> RoomSweeps(const mapping::SensorGeometry& sensor) {
  std::vector<mapping::Beam> beams;
  for (int b = 0; b < 3 * sensor.BeamsPerSweep(); ++b) {
    mapping::Beam beam;
    beam.time_s = b / sensor.beams_per_second;
    beam.head_angle_rad = std::fmod(b * sensor.step_angle_rad, 2 * std::numbers::pi);
    beam.bin_size_m = sensor.bin_size_m;
    beam.intensities.assign(static_cast<std::size_t>(sensor.num_bins), 5);
    const auto wall = static_cast<std::size_t>(2.0 / sensor.bin_size_m);
    for (std::size_t k = wall; k < wall + 4; ++k) beam.intensities[k] = 220;
    beams.push_back(beam);
  }
  return beams;
}

// The curve's last point is the final map's own probabilities; the cells split by the truth; a
// wall seen in every sweep grows more certain, sweep by sweep.
TEST(SweepCertainty, EndsAtTheFinalMapAndGrowsOnAWallSeenEverySweep) {
  const mapping::SensorGeometry sensor;
  mapping::MapperConfig config;
  const std::vector<mapping::Beam> beams = RoomSweeps(sensor);
  mapping::Mapper mapper(config, sensor);
  (void)mapper.IntegrateSweeps(beams);
  const octomap::OcTree& map = mapper.tree();
  // The truth: the occupied cells with z >= 0 (half of the arc's cells, on either side).
  mapping::KeySet truth;
  double true_sum = 0.0;
  double false_sum = 0.0;
  std::size_t occupied = 0;
  for (auto it = map.begin_leafs(); it != map.end_leafs(); ++it) {
    if (!map.isNodeOccupied(*it)) continue;
    ++occupied;
    if (it.getZ() >= 0.0) {
      truth.insert(it.getKey());
      true_sum += it->getOccupancy();
    } else {
      false_sum += it->getOccupancy();
    }
  }
  ASSERT_GT(truth.size(), 0U);
  ASSERT_LT(truth.size(), occupied);
  const CertaintyCurve curve = SweepCertainty(beams, sensor, config, map, truth);
  ASSERT_EQ(curve.true_mean.size(), 3U);
  ASSERT_EQ(curve.false_mean.size(), 3U);
  EXPECT_EQ(curve.true_cells, truth.size());
  EXPECT_EQ(curve.true_cells + curve.false_cells, occupied);
  EXPECT_NEAR(curve.true_mean.back(), true_sum / static_cast<double>(curve.true_cells), 1e-6);
  EXPECT_NEAR(curve.false_mean.back(), false_sum / static_cast<double>(curve.false_cells), 1e-6);
  EXPECT_LT(curve.true_mean[0], curve.true_mean[1]);
  EXPECT_LE(curve.true_mean[1], curve.true_mean[2]);
  EXPECT_GT(curve.true_mean[0], 0.5);
  EXPECT_EQ(CertaintyCsv(curve).substr(0, 6), "sweep,");
}

}  // namespace
}  // namespace sonarbench::sim
