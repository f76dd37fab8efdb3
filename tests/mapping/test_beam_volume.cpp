#include <gtest/gtest.h>

#include <cmath>

#include "beam_volume.hpp"
#include "integrate.hpp"
#include "mapping_grid.hpp"

namespace sonarbench::mapping {
namespace {

using test::kResolution;

// Half the diagonal of a cell: no point of a cell is farther than this from its centre.
const double kHalfDiagonal = 0.5 * std::sqrt(3.0) * kResolution;

TEST(BeamRayDirections, SpanTheNominalWedgeEdgeToEdge) {
  const SensorGeometry sensor;
  const auto directions = BeamRayDirections(sensor, 32, 64);
  ASSERT_EQ(directions.size(), 32u * 64u);
  double azimuth[2] = {0.0, 0.0};  // the least and the greatest
  double elevation[2] = {0.0, 0.0};
  for (const auto& d : directions) {
    EXPECT_NEAR(d.norm(), 1.0, 1e-12);
    azimuth[0] = std::min(azimuth[0], std::atan2(d.y(), d.x()));
    azimuth[1] = std::max(azimuth[1], std::atan2(d.y(), d.x()));
    elevation[0] = std::min(elevation[0], std::asin(d.z()));
    elevation[1] = std::max(elevation[1], std::asin(d.z()));
  }
  EXPECT_NEAR(azimuth[0], -sensor.beam_width_horizontal_rad / 2, 1e-12);
  EXPECT_NEAR(azimuth[1], sensor.beam_width_horizontal_rad / 2, 1e-12);
  EXPECT_NEAR(elevation[0], -sensor.beam_width_vertical_rad / 2, 1e-12);
  EXPECT_NEAR(elevation[1], sensor.beam_width_vertical_rad / 2, 1e-12);
  // Evenly spaced: the elevations of the first column, 35° / 63 apart.
  for (int j = 1; j < 64; ++j) {
    EXPECT_NEAR(std::asin(directions[32 * j].z()) - std::asin(directions[32 * (j - 1)].z()),
                sensor.beam_width_vertical_rad / 63, 1e-12);
  }
  const auto axis = BeamRayDirections(sensor, 1, 1);
  ASSERT_EQ(axis.size(), 1u);
  EXPECT_NEAR((axis[0] - Eigen::Vector3d::UnitX()).norm(), 0.0, 1e-12);
}

// Every cell a beam marks must be one that its wedge passes through: the cell centre lies within
// half a cell diagonal of a point inside the wedge, so its angles from the beam axis exceed the
// half-widths by at most asin(half_diagonal / range) and its range the obstacle's by at most
// half a diagonal.
TEST(CastBeam, KeysStayInsideTheWedge) {
  const SensorGeometry sensor;
  octomap::OcTree tree(kResolution);
  Beam beam;
  beam.head_angle_rad = 0.7;
  beam.bin_size_m = sensor.bin_size_m;
  beam.T_world_sonar = PoseFromXyzRpy({0.113, -0.271, 0.452}, {0.05, -0.1, 0.3});
  const double obstacle = 2.0;
  const auto directions = BeamRayDirections(sensor, 32, 64);
  BeamCells cells;
  const std::vector<double> ranges{obstacle};
  CastBeam(tree, beam, directions, ranges, 0.0, cells);
  ASSERT_FALSE(cells.free.empty());
  ASSERT_FALSE(cells.occupied.empty());

  const Eigen::Matrix3d R =
      beam.T_world_sonar.linear() *
      Eigen::AngleAxisd(beam.head_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d origin = beam.T_world_sonar.translation();
  auto check = [&](const octomap::OcTreeKey& key, bool occupied) {
    const octomap::point3d c = tree.keyToCoord(key);
    const Eigen::Vector3d v = R.transpose() * (Eigen::Vector3d(c.x(), c.y(), c.z()) - origin);
    const double range = v.norm();
    EXPECT_LE(range, obstacle + kHalfDiagonal);
    if (occupied) {
      EXPECT_GE(range, obstacle - kHalfDiagonal);
    }
    if (range <= kHalfDiagonal) return;  // the sonar's own cell: every direction passes it
    const double slack = std::asin(std::min(1.0, kHalfDiagonal / range));
    const double elevation = std::asin(v.z() / range);
    EXPECT_LE(std::abs(elevation), sensor.beam_width_vertical_rad / 2 + slack);
    // Near the wedge's top and bottom an azimuth step is shorter by cos(elevation).
    const double azimuth = std::atan2(v.y(), v.x());
    const double cos_el = std::cos(std::min(std::abs(elevation), 1.5));
    EXPECT_LE(std::abs(azimuth), sensor.beam_width_horizontal_rad / 2 + slack / cos_el);
  };
  for (const auto& key : cells.free) check(key, false);
  for (const auto& key : cells.occupied) check(key, true);
}

TEST(CastBeam, WithoutObstacleClearsToTheFreeRangeAndMarksNothingOccupied) {
  const SensorGeometry sensor;
  octomap::OcTree tree(kResolution);
  Beam beam;
  const auto directions = BeamRayDirections(sensor, 4, 8);
  BeamCells none;
  CastBeam(tree, beam, directions, {}, 0.0, none);
  EXPECT_TRUE(none.free.empty());
  EXPECT_TRUE(none.occupied.empty());
  BeamCells cleared;
  CastBeam(tree, beam, directions, {}, 1.0, cleared);
  EXPECT_TRUE(cleared.occupied.empty());
  // The on-axis row of cells from the origin to 1 m must all be free: 1.0 / 0.05 = 20 cells,
  // less the end point's own cell which computeRayKeys leaves out.
  int on_axis = 0;
  for (const auto& key : cleared.free) {
    const auto c = tree.keyToCoord(key);
    if (std::abs(c.y()) < kResolution && std::abs(c.z()) < kResolution && c.x() > 0) ++on_axis;
  }
  EXPECT_GE(on_axis, 19);
}

}  // namespace
}  // namespace sonarbench::mapping
