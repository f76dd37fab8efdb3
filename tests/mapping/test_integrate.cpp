#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include "beam_raster.hpp"
#include "beam_volume.hpp"
#include "block_set.hpp"
#include "integrate.hpp"
#include "map_tree.hpp"
#include "mapping_grid.hpp"
#include "ray_keys.hpp"
#include "sonarbench/mapping/mapper.hpp"

namespace sonarbench::mapping {
namespace {

using test::kResolution;

using Reference = std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash>;

// A batch through IntegrateBatch (marks, key sets, octants in parallel, shared paths) builds the
// map that OctoMap builds from the same cells one updateNode at a time: free cells are the rays'
// computeRayKeys cells, occupied the end points' cells, occupied winning, each updated once per
// batch. Three batches, one and two threads, beams around the sonar in every octant.
TEST(IntegrateBatch, BuildsTheMapOfOneUpdateNodePerCell) {
  const SensorGeometry sensor;
  const auto directions = BeamRayDirections(sensor, 8, 16);
  std::vector<Beam> beams;
  std::vector<std::vector<double>> obstacles;
  for (int b = 0; b < 60; ++b) {
    Beam beam;
    beam.head_angle_rad = 0.11 * b;
    beam.T_world_sonar.translation() = Eigen::Vector3d(0.02 * b - 0.6, 0.013 * b - 0.4, 0.01);
    beam.T_world_sonar.linear() =
        Eigen::AngleAxisd(b % 2 == 0 ? 0.0 : 3.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
    beams.push_back(beam);
    obstacles.push_back(b % 5 == 0 ? std::vector<double>{} : std::vector<double>{1.0 + 0.03 * b});
  }
  const double free_range_m = 2.5;
  octomap::OcTree reference(0.05);
  for (int batch = 0; batch < 3; ++batch) {
    Reference free_cells;
    Reference occupied_cells;
    for (std::size_t b = 0; b < beams.size(); ++b) {
      const Eigen::Matrix3d R =
          beams[b].T_world_sonar.linear() *
          Eigen::AngleAxisd(beams[b].head_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      const Eigen::Vector3d o = beams[b].T_world_sonar.translation();
      const double free_end = obstacles[b].empty() ? free_range_m : obstacles[b].front();
      auto point = [](const Eigen::Vector3d& v) {
        return octomap::point3d(static_cast<float>(v.x()), static_cast<float>(v.y()),
                                static_cast<float>(v.z()));
      };
      for (const auto& d : directions) {
        ForEachRayKey(reference, point(o), point(o + free_end * (R * d)),
                      [&](std::uint64_t packed) { free_cells.insert(UnpackKey(packed)); });
        for (const double r : obstacles[b])
          occupied_cells.insert(reference.coordToKey(point(o + r * (R * d))));
      }
    }
    for (const auto& key : occupied_cells) free_cells.erase(key);
    for (const auto& key : free_cells) reference.updateNode(key, false, true);
    for (const auto& key : occupied_cells) reference.updateNode(key, true, true);
  }
  reference.updateInnerOccupancy();
  std::ostringstream expected;
  WriteOctomapBinary(reference, expected);
  auto check = [&](const MapTree& ours, const std::string& what) {
    std::ostringstream actual;
    WriteOctomapBinary(ours, actual);
    EXPECT_EQ(ours.size(), reference.size()) << what;
    EXPECT_TRUE(actual.str() == expected.str()) << what;
  };
  for (const int threads : {1, 2}) {
    MapTree ours(0.05);
    for (int batch = 0; batch < 3; ++batch) {
      IntegrateBatch<KeyOpenSet>(ours, beams, obstacles, directions, free_range_m, threads);
    }
    FinishUpdates(ours);
    check(ours, std::to_string(threads) + " threads");
  }
  // As a Mapper runs it: one workspace kept from batch to batch (its sets and recent-key
  // filters must start each batch empty), whatever the thread count of each batch.
  MapTree ours(0.05);
  BatchWorkspace<KeyOpenSet> workspace;
  for (int batch = 0; batch < 3; ++batch) {
    IntegrateBatch(ours, beams, obstacles, directions, free_range_m, 2 - batch % 2, workspace);
  }
  FinishUpdates(ours);
  check(ours, "one workspace");
  MapTree ours_std(0.05);
  BatchWorkspace<KeySet> std_workspace;
  for (int batch = 0; batch < 3; ++batch) {
    IntegrateBatch(ours_std, beams, obstacles, directions, free_range_m, 1 + batch % 2,
                   std_workspace);
  }
  FinishUpdates(ours_std);
  check(ours_std, "one workspace, std::unordered_set");
  MapTree ours_blocks(0.05);
  BatchWorkspace<BlockKeySet> block_workspace;
  for (int batch = 0; batch < 3; ++batch) {
    IntegrateBatch(ours_blocks, beams, obstacles, directions, free_range_m, 2 - batch % 2,
                   block_workspace);
  }
  FinishUpdates(ours_blocks);
  check(ours_blocks, "one workspace, BlockKeySet");
}

// The radix sort sorts as std::sort does: random codes, codes that share their high bits (one
// region of space), all equal, and the Morton code round trip it relies on.
TEST(IntegrateBatch, RadixSortSortsAndMortonCodesRoundTrip) {
  std::mt19937_64 rng(21);
  std::vector<std::uint64_t> scratch;
  for (const std::uint64_t mask : {~std::uint64_t{0}, std::uint64_t{0xfffff}, std::uint64_t{0}}) {
    for (const std::size_t n : {0u, 1u, 2u, 1000u, 70000u}) {
      std::vector<std::uint64_t> values(n);
      for (auto& v : values) v = (0x5a5a00000000ULL | (rng() & mask));
      std::vector<std::uint64_t> expected = values;
      std::sort(expected.begin(), expected.end());
      RadixSort(values, scratch);
      ASSERT_EQ(values, expected) << "n " << n << " mask " << mask;
    }
  }
  for (int i = 0; i < 10000; ++i) {
    const octomap::OcTreeKey key(static_cast<octomap::key_type>(rng()),
                                 static_cast<octomap::key_type>(rng()),
                                 static_cast<octomap::key_type>(rng()));
    ASSERT_TRUE(KeyFromMortonCode(MortonCode(key)) == key);
  }
}

TEST(IntegrateBatch, OccupiedWinsOverFreeWithinABatch) {
  const SensorGeometry sensor;
  const auto directions = BeamRayDirections(sensor, 1, 1);
  const std::vector<Beam> beams(2);
  const std::vector<std::vector<double>> obstacles{{1.02}, {2.02}};
  for (const int threads : {1, 2}) {
    MapTree tree(kResolution);
    const BatchStats stats =
        IntegrateBatch<KeySet>(tree, beams, obstacles, directions, 0.0, threads);
    EXPECT_EQ(stats.beams, 2u);
    EXPECT_EQ(stats.beams_with_obstacle, 2u);
    EXPECT_EQ(stats.ray_casts, 2u);
    EXPECT_EQ(stats.occupied_cells, 2u);  // 1.02 m occupied by one beam, free in the other
    FinishUpdates(tree);
    const octomap::OcTreeNode* near = tree.search(1.02, 0.0, 0.0);
    ASSERT_NE(near, nullptr);
    EXPECT_FLOAT_EQ(near->getLogOdds(), tree.getProbHitLog()) << threads << " threads";
    const octomap::OcTreeNode* between = tree.search(1.5, 0.0, 0.0);
    ASSERT_NE(between, nullptr);
    EXPECT_FLOAT_EQ(between->getLogOdds(), tree.getProbMissLog()) << threads << " threads";
  }
  // A beam without an obstacle counts as a beam, not as one with an obstacle.
  MapTree tree(kResolution);
  const std::vector<std::vector<double>> one{{1.02}, {}};
  const BatchStats stats = IntegrateBatch<KeySet>(tree, beams, one, directions, 0.0, 1);
  EXPECT_EQ(stats.beams, 2u);
  EXPECT_EQ(stats.beams_with_obstacle, 1u);
  EXPECT_EQ(stats.occupied_cells, 1u);
}

}  // namespace
}  // namespace sonarbench::mapping
