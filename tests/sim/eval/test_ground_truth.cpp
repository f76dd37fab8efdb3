#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim_fixtures.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/world/mesh.hpp"

namespace sonarbench::sim {
namespace {

using Eigen::Vector3d;

// A 0.98 m square plane at z = 0.012 m lies inside the cell layer [0, 0.05) and, spanning
// (-0.49, 0.49), inside the 20 cells [-0.5, 0.5) per side, touching none of their faces:
// exactly 20 × 20 cells.
TEST(VoxelizeMeshes, PlaneCellsCanBeCounted) {
  const std::vector<TriangleMesh> meshes{SmallPlane()};
  const octomap::OcTree key_space(0.05);
  const mapping::KeySet cells = VoxelizeMeshes(meshes, key_space);
  EXPECT_EQ(cells.size(), 400u);
  for (const auto& key : cells) {
    const auto c = key_space.keyToCoord(key);
    EXPECT_NEAR(c.z(), 0.025, 1e-6);
    EXPECT_LT(std::abs(c.x()), 0.5);
    EXPECT_LT(std::abs(c.y()), 0.5);
  }
}

// The same plane lying exactly on the cell face z = 0: cells are half-open like OctoMap's keys
// (coordToKey(0) is the cell [0, 0.05)), so it belongs to that layer alone, 400 cells, and not
// to the layer below nor to none (float cell centres once lost it from both).
TEST(VoxelizeMeshes, SurfaceOnACellFaceBelongsToTheUpperCellOnly) {
  TriangleMesh plane = SmallPlane();
  for (auto& v : plane.vertices) v.z() = 0.0f;
  const octomap::OcTree key_space(0.05);
  const mapping::KeySet cells = VoxelizeMeshes(std::vector<TriangleMesh>{plane}, key_space);
  EXPECT_EQ(cells.size(), 400u);
  for (const auto& key : cells) {
    EXPECT_EQ(key, key_space.coordToKey(key_space.keyToCoord(key)));
    EXPECT_EQ(key[2], key_space.coordToKey(0.0, 0.0, 0.0)[2]);
  }
}

// A box 0.3 m on a side, centred in a cell block, has 6 faces of 6 × 6 cells; the shell of a
// 6 × 6 × 6 block is 6³ - 4³ = 152 cells.
TEST(VoxelizeMeshes, BoxShellCellsCanBeCounted) {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kBox;
  spec.size_m = {0.29, 0.29, 0.29};
  spec.T_world_mesh.translation() = Vector3d(0.15, 0.15, 0.15);
  const std::vector<TriangleMesh> meshes{BuildMesh(spec, 0)};
  const octomap::OcTree key_space(0.05);
  EXPECT_EQ(VoxelizeMeshes(meshes, key_space).size(), 152u);
}

// The 0.29 m box of BoxShellCellsCanBeCounted, filled: its shell (152 cells) and the 4³ = 64
// cells inside it, the whole 6 × 6 × 6 block.
TEST(VoxelizeMeshes, AFilledBoxIsItsWholeBlock) {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kBox;
  spec.size_m = {0.29, 0.29, 0.29};
  spec.T_world_mesh.translation() = Eigen::Vector3d(0.15, 0.15, 0.15);
  TriangleMesh box = BuildMesh(spec, 0);
  box.fill = true;
  const octomap::OcTree key_space(0.05);
  EXPECT_EQ(VoxelizeMeshes(std::vector<TriangleMesh>{box}, key_space).size(), 216u);
}

// For a box turned 30° about z: the filled cells cover the box (every cell meeting it either
// crosses the surface or lies wholly inside), so at least volume / cell volume of them; and
// beyond the shell only cells wholly inside are added, so at most that plus the shell.
TEST(VoxelizeMeshes, AFilledTurnedBoxHoldsItsVolume) {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kBox;
  spec.size_m = {1.0, 0.6, 0.4};
  spec.T_world_mesh = mapping::PoseFromXyzRpy({0.013, -0.021, 0.007}, {0, 0, 0.5236});
  TriangleMesh box = BuildMesh(spec, 0);
  const octomap::OcTree key_space(0.05);
  const auto shell = VoxelizeMeshes(std::vector<TriangleMesh>{box}, key_space);
  box.fill = true;
  const auto solid = VoxelizeMeshes(std::vector<TriangleMesh>{box}, key_space);
  const double volume_cells = 1.0 * 0.6 * 0.4 / (0.05 * 0.05 * 0.05);  // 1920
  EXPECT_GE(static_cast<double>(solid.size()), volume_cells);
  EXPECT_LE(static_cast<double>(solid.size()), volume_cells + static_cast<double>(shell.size()));
  for (const auto& key : shell) EXPECT_TRUE(solid.contains(key));
}

// A level sonar 0.5 m over a wide floor (the shipped Micron: 3° × 35°, 5 m), one beam looking
// along +x, given three times. Its rays meet the floor directly from the aperture's lower edge,
// h / sin 17.5° = 1.663 m, to the last range: an echo anywhere there lies on the arc of a direct
// echo, and nothing nearer answers. The tolerance is a cell's half-diagonal plus one bin.
struct FloorRing {
  static constexpr double kHeight = 0.5;
  octomap::OcTree key_space{0.05};
  mapping::SensorGeometry sensor;
  std::vector<TriangleMesh> meshes;
  DirectEchoes direct;
  mapping::KeySet observable;

  FloorRing() {
    MeshSpec floor;
    floor.type = MeshSpec::Type::kPlane;
    floor.size_m = {20.0, 20.0, 0.0};
    meshes.push_back(BuildMesh(floor, 0));
    BeamPose pose;
    pose.T_world_sonar.translation() = Vector3d(0.0, 0.0, kHeight);
    const std::vector<BeamPose> beams(3, pose);
    observable =
        ObservableSurfaceCells(RayTracer(meshes), beams, sensor, 8, 321, key_space, {}, &direct);
  }
  // The centre of the cell holding the point at `range` [m], azimuth and elevation [deg].
  Vector3d CellAt(double range, double azimuth_deg, double elevation_deg) const {
    const double a = azimuth_deg * std::numbers::pi / 180.0;
    const double e = elevation_deg * std::numbers::pi / 180.0;
    const Vector3d p =
        Vector3d(0.0, 0.0, kHeight) +
        range * Vector3d(std::cos(a) * std::cos(e), std::sin(a) * std::cos(e), std::sin(e));
    const octomap::point3d c = key_space.keyToCoord(key_space.coordToKey(p.x(), p.y(), p.z()));
    return {c.x(), c.y(), c.z()};
  }
  double HalfDiagonal() const { return 0.5 * std::sqrt(3.0) * key_space.getResolution(); }
};

TEST(DirectEchoes, AnEchoOnTheFloorsArcIsExplainedAndOneNearerThanTheFloorIsNot) {
  const FloorRing ring;
  ASSERT_EQ(ring.direct.beams.size(), 1u);  // the three alike traced once
  EXPECT_NEAR(ring.direct.tolerance_m, ring.HalfDiagonal() + ring.sensor.bin_size_m, 1e-12);
  const double nearest = FloorRing::kHeight / std::sin(17.5 * std::numbers::pi / 180.0);
  ASSERT_EQ(ring.direct.beams[0].ranges.size(), 1u);
  EXPECT_NEAR(ring.direct.beams[0].ranges[0].first, nearest - ring.direct.tolerance_m, 1e-5);
  // Cells along the beam's axis, in the water 10 cells over the floor: explained exactly from
  // the nearest direct range less the tolerance (cells within 5 mm of that edge left out).
  int explained = 0;
  int not_explained = 0;
  for (double range = 0.8; range < 3.0; range += 0.01) {
    const Vector3d centre = ring.CellAt(range, 0.0, 0.0);
    const double distance = (centre - Vector3d(0.0, 0.0, FloorRing::kHeight)).norm();
    const double edge = nearest - ring.direct.tolerance_m;
    if (std::abs(distance - edge) < 0.005) continue;
    const bool expected = distance > edge;
    EXPECT_EQ(ring.direct.Explains(centre, ring.HalfDiagonal()), expected) << distance;
    (expected ? explained : not_explained) += 1;
  }
  EXPECT_GT(explained, 50);
  EXPECT_GT(not_explained, 50);
  // At 2 m: inside the aperture widened by the cell's angular radius (asin(0.043 / 2) = 1.24°
  // past the 1.5° and 17.5° half-widths) the echo is explained; outside it, not.
  EXPECT_TRUE(ring.direct.Explains(ring.CellAt(2.0, 2.0, 0.0), ring.HalfDiagonal()));
  EXPECT_FALSE(ring.direct.Explains(ring.CellAt(2.0, 6.0, 0.0), ring.HalfDiagonal()));
  EXPECT_TRUE(ring.direct.Explains(ring.CellAt(2.0, 0.0, 17.0), ring.HalfDiagonal()));
  EXPECT_FALSE(ring.direct.Explains(ring.CellAt(2.0, 0.0, 22.0), ring.HalfDiagonal()));
  EXPECT_FALSE(ring.direct.Explains(ring.CellAt(2.0, 180.0, 0.0), ring.HalfDiagonal()));
}

// The score splits the ghosts by that test: four floor cells (truth), one ghost on the floor
// ring's arc, two that no direct echo explains (nearer than the floor; beside the beam).
TEST(DirectEchoes, TheScoreSplitsTheGhostsIntoArcAndEcho) {
  const FloorRing ring;
  const mapping::KeySet truth = VoxelizeMeshes(ring.meshes, ring.key_space);
  octomap::OcTree map(0.05);
  const auto occupy = [&map](const Vector3d& p) { map.updateNode(p.x(), p.y(), p.z(), true); };
  for (double x : {2.0, 2.1, 2.2, 2.3}) occupy(Vector3d(x, 0.0, 0.01));
  occupy(ring.CellAt(2.0, 0.0, 0.0));   // on the arc
  occupy(ring.CellAt(1.2, 0.0, 0.0));   // nearer than the floor's first direct echo
  occupy(ring.CellAt(2.0, 10.0, 0.0));  // beside the beam
  const MapMetrics m = ScoreMap(map, truth, ring.observable, {}, {}, &ring.direct);
  ASSERT_EQ(m.occupied_cells, 7u);
  EXPECT_DOUBLE_EQ(m.ghost_share, 3.0 / 7.0);
  ASSERT_TRUE(m.ghost_arc_share && m.ghost_echo_share);
  EXPECT_DOUBLE_EQ(*m.ghost_arc_share, 1.0 / 7.0);
  EXPECT_DOUBLE_EQ(*m.ghost_echo_share, 2.0 / 7.0);
  const MapMetrics without = ScoreMap(map, truth, ring.observable);
  EXPECT_FALSE(without.ghost_arc_share || without.ghost_echo_share);
}

}  // namespace
}  // namespace sonarbench::sim
