#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "sonarbench/base/error.hpp"
#include "sonarbench/mapping/beam_cells.hpp"
#include "sonarbench/sim/app/divisions_study.hpp"
#include "sonarbench/sim/eval/beam_coverage.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

using Eigen::Vector3d;

mapping::Beam BeamAt(const Vector3d& origin, double head_angle_rad, const Vector3d& rpy) {
  mapping::Beam beam;
  beam.T_world_sonar = mapping::PoseFromXyzRpy(origin, rpy);
  beam.head_angle_rad = head_angle_rad;
  beam.bin_size_m = 0.01;
  return beam;
}

// A needle-thin beam along +x from a cell centre, 0.5 m long at 5 cm cells: it runs through the
// centres of cells 0..10 of one row (its end, 0.525 m, lies in cell 10), and at 0.5 m its
// half-width is 0.5·tan(0.05°) = 0.4 mm, far from any other row: exactly 11 cells.
TEST(ExactWedgeCells, ANeedleBeamCrossesCountableCells) {
  const octomap::OcTree key_space(0.05);
  mapping::SensorGeometry needle;
  needle.beam_width_horizontal_rad = 0.1 * mapping::kDegToRad;
  needle.beam_width_vertical_rad = 0.1 * mapping::kDegToRad;
  const auto beam = BeamAt({0.025, 0.025, 0.025}, 0.0, Vector3d::Zero());
  const WedgeCells cells = ExactWedgeCells(beam, needle, 0.5, key_space);
  EXPECT_EQ(cells.inside.size(), 11u);
  EXPECT_EQ(cells.undecided.size(), 0u);
  for (const auto& key : cells.inside) {
    EXPECT_EQ(key[1], key_space.coordToKey(0.025, 0.025, 0.025)[1]);
    EXPECT_EQ(key[2], key_space.coordToKey(0.025, 0.025, 0.025)[2]);
  }
}

// Every point of the wedge lies in a cell of the exact set (no cell is missed), for a beam
// turned by its head angle on a tilted sonar; and few cells are left undecided.
TEST(ExactWedgeCells, HoldsEveryPointOfTheWedge) {
  const octomap::OcTree key_space(0.05);
  const mapping::SensorGeometry micron;
  const auto beam = BeamAt({0.31, -0.12, 0.45}, 0.7, {0.1, -0.2, 0.3});
  const double range = 1.5;
  const WedgeCells cells = ExactWedgeCells(beam, micron, range, key_space);
  const Eigen::Matrix3d R =
      beam.T_world_sonar.linear() *
      Eigen::AngleAxisd(beam.head_angle_rad, Vector3d::UnitZ()).toRotationMatrix();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double a = 0.5 * micron.beam_width_horizontal_rad;
  const double e = 0.5 * micron.beam_width_vertical_rad;
  std::size_t missed = 0;
  for (int i = 0; i < 200000; ++i) {
    // Uniform in volume: r ∝ cbrt(u); directions uniform in azimuth and sin(elevation).
    const double r = range * std::cbrt(unit(rng));
    const double az = a * (2 * unit(rng) - 1);
    const double el = std::asin(std::sin(e) * (2 * unit(rng) - 1));
    const Vector3d p =
        beam.T_world_sonar.translation() + r * (R * mapping::SonarRayDirection(az, el));
    const auto key = key_space.coordToKey(p.x(), p.y(), p.z());
    missed += cells.inside.contains(key) || cells.undecided.contains(key) ? 0 : 1;
  }
  EXPECT_EQ(missed, 0u);
  EXPECT_GT(cells.inside.size(), 0u);
  // The two bracketing cones differ by 1/cos(1.5°) - 1 = 0.034% in slope: at most a thin layer
  // of the cells along the two elevation faces can be undecided.
  EXPECT_LT(cells.undecided.size(), cells.inside.size() / 20) << cells.undecided.size();
}

// The mapper's ray casts stay inside the beam, and more rays cover more of it.
TEST(MeasureBeamCoverage, RaysStayInsideAndMoreRaysCoverMore) {
  const octomap::OcTree key_space(0.05);
  const mapping::SensorGeometry micron;
  const auto beam = BeamAt({0.1, 0.48, 0.45}, 37 * mapping::kDegToRad, Vector3d::Zero());
  const BeamCoverage sparse = MeasureBeamCoverage(beam, micron, 2.2, 4, 8, key_space);
  const BeamCoverage paper = MeasureBeamCoverage(beam, micron, 2.2, 32, 64, key_space);
  const BeamCoverage dense = MeasureBeamCoverage(beam, micron, 2.2, 64, 256, key_space);
  for (const auto* c : {&sparse, &paper, &dense}) {
    EXPECT_EQ(c->visited_outside, 0u);
    EXPECT_LE(c->coverage_lower, c->coverage);
    EXPECT_GE(c->coverage_upper, c->coverage);
    EXPECT_EQ(c->wedge_cells, paper.wedge_cells);
  }
  EXPECT_LT(sparse.coverage, paper.coverage);
  EXPECT_LE(paper.coverage, dense.coverage);
  EXPECT_GT(paper.visits_per_cell, sparse.visits_per_cell);
  std::printf("coverage 4x8 %.3f, 32x64 %.3f, 64x256 %.3f of %zu cells (%zu undecided)\n",
              sparse.coverage, paper.coverage, dense.coverage, paper.wedge_cells,
              paper.undecided_cells);
}

// The mapper's exact mode marks, for a beam with a detection at range r, the cells ExactWedgeCells
// decides are in the wedge within r: every `inside` cell, and no cell outside; of the `undecided`
// band (between the inner and the outer polyhedral cone) it takes every cell, its cone being the
// outer one. Random poses, head angles and ranges.
TEST(ExactWedgeCells, AreTheCellsOfTheMappersExactMode) {
  const octomap::OcTree key_space(0.05);
  const mapping::SensorGeometry micron;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::size_t undecided = 0;
  for (int trial = 0; trial < 16; ++trial) {
    const auto beam =
        BeamAt({unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5}, 6.283 * unit(rng),
               trial % 4 == 0 ? Vector3d::Zero()
                              : Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, 3.0 * unit(rng)));
    const double range = 0.3 + 2.2 * unit(rng);
    SCOPED_TRACE("trial " + std::to_string(trial));
    const WedgeCells wedge = ExactWedgeCells(beam, micron, range, key_space);
    const double obstacle[] = {range};
    mapping::BeamKeys keys = mapping::ExactBeamKeys(key_space, micron, beam, obstacle, 0.0);
    mapping::KeySet& exact = keys.free;
    exact.insert(keys.occupied.begin(), keys.occupied.end());
    for (const auto& key : wedge.inside) EXPECT_TRUE(exact.contains(key));
    for (const auto& key : wedge.undecided) EXPECT_TRUE(exact.contains(key));
    std::size_t outside = 0;
    for (const auto& key : exact) {
      outside += wedge.inside.contains(key) || wedge.undecided.contains(key) ? 0 : 1;
    }
    EXPECT_EQ(outside, 0u);
    EXPECT_EQ(exact.size(), wedge.inside.size() + wedge.undecided.size());
    undecided += wedge.undecided.size();
  }
  std::printf("undecided cells over all trials: %zu\n", undecided);
}

}  // namespace
}  // namespace sonarbench::sim
