#include <gtest/gtest.h>

#include "sonarbench/mapping/error.hpp"
#include "sonarbench/sim/ground_truth.hpp"
#include "sonarbench/sim/mesh.hpp"
#include "sonarbench/sim/score.hpp"

namespace sonarbench::sim {
namespace {

using Eigen::Vector3d;

// A 0.98 m square plane at z = 0.012 m, centred over the origin.
TriangleMesh SmallPlane() {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kPlane;
  spec.size_m = {0.98, 0.98, 0.0};
  spec.T_world_mesh.translation() = Vector3d(0, 0, 0.012);
  return BuildMesh(spec, 0);
}

TEST(TriangleBoxOverlap, AnalyticCases) {
  const Vector3d centre(0, 0, 0);
  const Vector3d half(0.5, 0.5, 0.5);
  // Inside, crossing, far away.
  EXPECT_TRUE(TriangleBoxOverlap(centre, half, {-0.1, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}));
  EXPECT_TRUE(TriangleBoxOverlap(centre, half, {-5, -5, 0}, {5, -5, 0}, {0, 5, 0}));
  EXPECT_FALSE(TriangleBoxOverlap(centre, half, {2, 2, 2}, {3, 2, 2}, {2, 3, 2}));
  // Touching a face counts.
  EXPECT_TRUE(TriangleBoxOverlap(centre, half, {0.5, -1, -1}, {0.5, 1, -1}, {0.5, 0, 1}));
  EXPECT_FALSE(TriangleBoxOverlap(centre, half, {0.5001, -1, -1}, {0.5001, 1, -1}, {0.5001, 0, 1}));
  // Bounding boxes overlap but the triangle passes beside the corner: only an edge cross-product
  // axis separates them. The plane x + y = 1.2 misses the box (its corner has x + y = 1).
  EXPECT_FALSE(TriangleBoxOverlap(centre, half, {1.2, 0, -1}, {0, 1.2, -1}, {0.6, 0.6, 1}));
  EXPECT_TRUE(TriangleBoxOverlap(centre, half, {0.9, 0, -1}, {0, 0.9, -1}, {0.45, 0.45, 1}));
}

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

octomap::OcTree MapWith(const mapping::KeySet& occupied, const mapping::KeySet& free) {
  octomap::OcTree tree(0.05);
  for (const auto& k : occupied) tree.updateNode(k, true);
  for (const auto& k : free) tree.updateNode(k, false);
  return tree;
}

mapping::KeySet Row(int from, int to) {
  mapping::KeySet cells;
  for (int x = from; x < to; ++x)
    cells.insert(octomap::OcTreeKey(static_cast<octomap::key_type>(32768 + x), 32768, 32768));
  return cells;
}

TEST(ScoreMap, IdenticalMapAndTruthScoreOne) {
  const mapping::KeySet truth = Row(0, 10);
  const MapMetrics m = ScoreMap(MapWith(truth, {}), truth, truth);
  EXPECT_EQ(m.occupied_precision, 1.0);
  EXPECT_EQ(m.occupied_recall, 1.0);
  EXPECT_EQ(m.occupied_f1, 1.0);
  EXPECT_EQ(m.coverage, 1.0);
}

TEST(ScoreMap, SwappingMapAndTruthSwapsPrecisionAndRecall) {
  const mapping::KeySet a = Row(0, 10);
  const mapping::KeySet b = Row(4, 20);
  const MapMetrics ab = ScoreMap(MapWith(a, {}), b, b);
  const MapMetrics ba = ScoreMap(MapWith(b, {}), a, a);
  EXPECT_DOUBLE_EQ(ab.occupied_precision, 6.0 / 10.0);
  EXPECT_DOUBLE_EQ(ab.occupied_recall, 6.0 / 16.0);
  EXPECT_DOUBLE_EQ(ab.occupied_precision, ba.occupied_recall);
  EXPECT_DOUBLE_EQ(ab.occupied_recall, ba.occupied_precision);
}

TEST(ScoreMap, FreeCellsCountForCoverageNotRecall) {
  const mapping::KeySet truth = Row(0, 10);
  const MapMetrics m = ScoreMap(MapWith(Row(0, 2), Row(2, 6)), truth, truth);
  EXPECT_DOUBLE_EQ(m.occupied_recall, 0.2);
  EXPECT_DOUBLE_EQ(m.coverage, 0.6);
  EXPECT_EQ(m.free_cells, 4u);
}

TEST(ScoreMap, EmptyInputsGiveZerosNotNaN) {
  const MapMetrics m = ScoreMap(octomap::OcTree(0.05), {}, {});
  EXPECT_EQ(m.occupied_precision, 0.0);
  EXPECT_EQ(m.occupied_recall, 0.0);
  EXPECT_EQ(m.occupied_f1, 0.0);
  EXPECT_EQ(m.coverage, 0.0);
}

TEST(CollectMapCells, PrunedNodesExpandToTheirLeafCells) {
  octomap::OcTree tree(0.05);
  // Eight sibling cells with equal values are pruned into one parent node.
  for (int x = 0; x < 2; ++x)
    for (int y = 0; y < 2; ++y)
      for (int z = 0; z < 2; ++z)
        tree.updateNode(octomap::OcTreeKey(static_cast<octomap::key_type>(32768 + x),
                                           static_cast<octomap::key_type>(32768 + y),
                                           static_cast<octomap::key_type>(32768 + z)),
                        true);
  tree.prune();
  ASSERT_EQ(tree.getNumLeafNodes(), 1u);
  EXPECT_EQ(CollectMapCells(tree).occupied.size(), 8u);
}

TEST(PointTriangleDistance, AnalyticCases) {
  const Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_DOUBLE_EQ(PointTriangleDistance({0.2, 0.2, 0.5}, a, b, c), 0.5);  // above the face
  EXPECT_DOUBLE_EQ(PointTriangleDistance({-3, -4, 0}, a, b, c), 5.0);      // nearest a vertex
  EXPECT_DOUBLE_EQ(PointTriangleDistance({0.5, -2, 0}, a, b, c), 2.0);     // nearest an edge
  EXPECT_NEAR(PointTriangleDistance({1, 1, 0}, a, b, c), std::sqrt(0.5), 1e-12);  // hypotenuse
}

// A plane at z = 0.012 m and occupied cells in the layers k = 0, 1, 3 above it (centres at
// 0.025 + 0.05 k): each cell's distance to the mesh is its centre's height above the plane,
// exactly; the surface cells' distance back to the nearest occupied cell is 0 where the map
// holds them.
TEST(ScoreMap, SurfaceDistancesOfKnownOffsets) {
  const std::vector<TriangleMesh> meshes{SmallPlane()};
  const octomap::OcTree key_space(0.05);
  const mapping::KeySet truth = VoxelizeMeshes(meshes, key_space);
  mapping::KeySet occupied;
  const octomap::key_type z0 = key_space.coordToKey(0.012);
  for (const int layer : {0, 1, 3}) {
    occupied.insert(octomap::OcTreeKey(32768, 32768, static_cast<octomap::key_type>(z0 + layer)));
  }
  const MapMetrics m = ScoreMap(MapWith(occupied, {}), truth, truth, meshes);
  ASSERT_EQ(m.map_to_mesh.count, 3u);
  EXPECT_NEAR(m.map_to_mesh.max_m, 0.025 + 0.15 - 0.012, 1e-6);
  EXPECT_NEAR(m.map_to_mesh.mean_m, (0.013 + 0.063 + 0.163) / 3.0, 1e-6);
  ASSERT_EQ(m.mesh_to_map.count, truth.size());
  // The farthest surface cell is a corner of the 20 × 20 layer, 10 and 9 or 10 cells away in x
  // and y from the one occupied column (at keys 32768 = cells [0, 0.05)).
  EXPECT_NEAR(m.mesh_to_map.max_m, 0.05 * std::hypot(10.0, 10.0), 1e-6);
}

// A mesh that is not truth (a water surface) adds no cells, no per-mesh recall, and is not a
// surface that occupied cells are measured to: the test above, with a second plane right on the
// occupied cells, gives the same distances.
TEST(ScoreMap, MeshesThatAreNotTruthAreLeftOut) {
  TriangleMesh surface = SmallPlane();
  for (Eigen::Vector3f& v : surface.vertices) v.z() += 0.15f;
  surface.truth = false;
  const std::vector<TriangleMesh> meshes{SmallPlane(), surface};
  const octomap::OcTree key_space(0.05);
  const mapping::KeySet truth = VoxelizeMeshes(meshes, key_space);
  EXPECT_EQ(truth.size(), 400u);
  mapping::KeySet occupied;
  const octomap::key_type z0 = key_space.coordToKey(0.012);
  for (const int layer : {0, 1, 3}) {
    occupied.insert(octomap::OcTreeKey(32768, 32768, static_cast<octomap::key_type>(z0 + layer)));
  }
  const MapMetrics m = ScoreMap(MapWith(occupied, {}), truth, truth, meshes);
  ASSERT_EQ(m.per_mesh.size(), 1u);
  ASSERT_EQ(m.map_to_mesh.count, 3u);
  EXPECT_NEAR(m.map_to_mesh.max_m, 0.025 + 0.15 - 0.012, 1e-6);
}

TEST(ScoreMap, FreeCellsOnTheSurfaceLowerFreeAccuracy) {
  const mapping::KeySet truth = Row(0, 10);
  const MapMetrics m = ScoreMap(MapWith({}, Row(5, 25)), truth, truth);
  EXPECT_EQ(m.free_on_surface_cells, 5u);
  EXPECT_DOUBLE_EQ(m.free_accuracy, 1.0 - 5.0 / 20.0);
  EXPECT_DOUBLE_EQ(m.coverage_absolute, 0.5);
  EXPECT_EQ(m.mesh_to_map.count, 0u);  // no occupied cell: no distance, and no NaN
}

}  // namespace
}  // namespace sonarbench::sim

namespace sonarbench::sim {
namespace {

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

TEST(BuildSceneMeshes, FillingAnOpenMeshIsRefused) {
  Scene scene;
  scene.file = "s.yaml";
  scene.materials.push_back({});
  MeshSpec tank;
  tank.name = "tank";
  tank.type = MeshSpec::Type::kTank;
  tank.size_m = {4, 4, 1.5};
  tank.fill = true;
  scene.meshes.push_back(tank);
  try {
    (void)BuildSceneMeshes(scene);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.yaml: mesh 'tank': 'fill' needs a closed mesh, but it "
                                         "has 4 open"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace sonarbench::sim
