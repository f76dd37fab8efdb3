#include <gtest/gtest.h>

#include "sim_fixtures.hpp"
#include "sonarbench/mapping/error.hpp"
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

}  // namespace
}  // namespace sonarbench::sim
