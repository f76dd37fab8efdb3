#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <utility>

#include "sim_fixtures.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/world/mesh.hpp"

namespace sonarbench::sim {
namespace {

using Eigen::Vector3d;

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

// `cells` moved by (dx, dy, dz) cells.
mapping::KeySet Shifted(const mapping::KeySet& cells, int dx, int dy, int dz) {
  mapping::KeySet out;
  for (const auto& k : cells) {
    out.insert(octomap::OcTreeKey(static_cast<octomap::key_type>(k[0] + dx),
                                  static_cast<octomap::key_type>(k[1] + dy),
                                  static_cast<octomap::key_type>(k[2] + dz)));
  }
  return out;
}

// A wall mapped one cell off its surface misses at no tolerance and hits at one cell or more;
// three cells off, it is all ghosts.
TEST(ScoreMap, ToleranceCountsCellsWithinKCellsOfTheSurface) {
  const mapping::KeySet truth = Row(0, 10);
  for (const auto& [dy, dz] : {std::pair{1, 0}, std::pair{1, 1}, std::pair{0, -1}}) {
    const MapMetrics m = ScoreMap(MapWith(Shifted(truth, 0, dy, dz), {}), truth, truth);
    EXPECT_EQ(m.precision_within[0], 0.0);
    EXPECT_EQ(m.precision_within[1], 1.0);
    EXPECT_EQ(m.recall_within[0], 0.0);
    EXPECT_EQ(m.recall_within[1], 1.0);
    EXPECT_EQ(m.f1_within[2], 1.0);
    EXPECT_EQ(m.ghost_share, 0.0);
  }
  const MapMetrics two = ScoreMap(MapWith(Shifted(truth, 0, 2, 0), {}), truth, truth);
  EXPECT_EQ(two.precision_within[1], 0.0);
  EXPECT_EQ(two.precision_within[2], 1.0);
  const MapMetrics far = ScoreMap(MapWith(Shifted(truth, 0, 0, 3), {}), truth, truth);
  EXPECT_EQ(far.precision_within[2], 0.0);
  EXPECT_EQ(far.ghost_share, 1.0);
  // Half the map on the wall, half three cells off: half are ghosts, and the wall's cells 5 and 6
  // are within 1 and 2 cells of its cell 4.
  mapping::KeySet half = Row(0, 5);
  for (const auto& k : Shifted(Row(5, 10), 0, 0, 3)) half.insert(k);
  const MapMetrics mixed = ScoreMap(MapWith(half, {}), truth, truth);
  EXPECT_EQ(mixed.ghost_share, 0.5);
  EXPECT_EQ(mixed.recall_within[0], 0.5);
  EXPECT_EQ(mixed.recall_within[1], 0.6);
  EXPECT_EQ(mixed.recall_within[2], 0.7);
}

// On random maps the tolerant figures never fall as the tolerance grows, index 0 is the exact
// figure, and the ghosts' share is what the 2-cell precision leaves.
TEST(ScoreMap, ToleranceFiguresGrowWithTheToleranceOnRandomMaps) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> offset(-6, 6);
  for (int trial = 0; trial < 20; ++trial) {
    mapping::KeySet truth, map;
    const auto key = [&] {
      return octomap::OcTreeKey(static_cast<octomap::key_type>(32768 + offset(rng)),
                                static_cast<octomap::key_type>(32768 + offset(rng)),
                                static_cast<octomap::key_type>(32768 + offset(rng)));
    };
    for (int i = 0; i < 40; ++i) truth.insert(key());
    for (int i = 0; i < 40; ++i) map.insert(key());
    const MapMetrics m = ScoreMap(MapWith(map, {}), truth, truth);
    EXPECT_EQ(m.precision_within[0], m.occupied_precision);
    EXPECT_EQ(m.recall_within[0], m.occupied_recall);
    for (int k = 1; k < 3; ++k) {
      EXPECT_GE(m.precision_within[k], m.precision_within[k - 1]);
      EXPECT_GE(m.recall_within[k], m.recall_within[k - 1]);
    }
    EXPECT_DOUBLE_EQ(m.ghost_share, 1.0 - m.precision_within[2]);
  }
}

// Top down, a wall's arc mapped five cells above its true cells is right column by column.
TEST(ScoreMap, ColumnsJudgeTheMapTopDown) {
  const mapping::KeySet truth = Row(0, 10);
  const MapMetrics m = ScoreMap(MapWith(Shifted(Row(0, 5), 0, 0, 5), {}), truth, truth);
  EXPECT_EQ(m.occupied_precision, 0.0);
  EXPECT_EQ(m.ghost_share, 1.0);
  EXPECT_EQ(m.column_precision, 1.0);
  EXPECT_EQ(m.column_recall, 0.5);
  // A cell beside the wall's columns is wrong top down too.
  const MapMetrics beside = ScoreMap(MapWith(Shifted(Row(0, 5), 0, 1, 5), {}), truth, truth);
  EXPECT_EQ(beside.column_precision, 0.0);
  EXPECT_EQ(beside.column_recall, 0.0);
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

// Each observable surface cell's distance to the map is to its nearest occupied cell's centre,
// however the search over blocks of cells finds it: random cells against a brute-force search, the
// 95th percentile the smallest distance that at least 95% of the cells are within.
TEST(ScoreMap, SurfaceToMapDistancesAreToTheNearestOccupiedCell) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> coordinate(32768 - 40, 32768 + 40);
  auto random_cells = [&](int count) {
    mapping::KeySet cells;
    while (static_cast<int>(cells.size()) < count) {
      cells.insert(octomap::OcTreeKey(static_cast<octomap::key_type>(coordinate(rng)),
                                      static_cast<octomap::key_type>(coordinate(rng)),
                                      static_cast<octomap::key_type>(coordinate(rng))));
    }
    return cells;
  };
  const mapping::KeySet occupied = random_cells(40);
  const mapping::KeySet truth = random_cells(500);
  const octomap::OcTree map = MapWith(occupied, {});
  std::vector<double> expected;
  for (const auto& t : truth) {
    double nearest = 1e9;
    for (const auto& o : occupied) {
      const octomap::point3d a = map.keyToCoord(t), b = map.keyToCoord(o);
      nearest = std::min(nearest, static_cast<double>((a - b).norm()));
    }
    expected.push_back(nearest);
  }
  std::sort(expected.begin(), expected.end());
  const MapMetrics m = ScoreMap(map, truth, truth);
  ASSERT_EQ(m.mesh_to_map.count, truth.size());
  double sum = 0.0;
  for (const double d : expected) sum += d;
  EXPECT_NEAR(m.mesh_to_map.mean_m, sum / static_cast<double>(expected.size()), 1e-6);
  EXPECT_NEAR(m.mesh_to_map.max_m, expected.back(), 1e-6);
  EXPECT_NEAR(m.mesh_to_map.p95_m, expected[474], 1e-6);  // 475 of 500 are within it
  EXPECT_GT(expected[474], expected[449] + 1e-3);         // and the 90th percentile is less
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
