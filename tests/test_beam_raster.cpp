// BeamRaster and MapTree::UpdateLeavesInOrder are the mapper's fast paths; each must give what
// OctoMap's own calls give, exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <random>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include "sonarbench/mapping/detail/beam_raster.hpp"
#include "sonarbench/mapping/detail/beam_volume.hpp"
#include "sonarbench/mapping/detail/integrate.hpp"
#include "sonarbench/mapping/detail/map_tree.hpp"
#include "sonarbench/mapping/detail/ray_keys.hpp"
#include "sonarbench/mapping/mapper.hpp"

namespace sonarbench::mapping {
namespace {

using Reference = std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash>;

// The union of ForEachRayKey's cells over the segments, sorted, and the visits, repeats included.
std::vector<std::uint64_t> ReferenceCells(const octomap::OcTree& tree,
                                          const octomap::point3d& origin,
                                          const std::vector<octomap::point3d>& ends,
                                          std::size_t& visits) {
  std::vector<std::uint64_t> cells;
  visits = 0;
  for (const auto& end : ends) {
    ForEachRayKey(tree, origin, end, [&](std::uint64_t packed) {
      cells.push_back(packed);
      ++visits;
    });
  }
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  return cells;
}

// One "beam" of rays from a random origin: a fan of neighbouring directions (where walks share
// cells and step in lockstep), with some rays along an axis (ties and zero steps), some inside
// the origin's cell and some leaving the key range.
std::vector<octomap::point3d> RandomBeam(std::mt19937_64& rng, const octomap::point3d& origin,
                                         int rays) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> range(0.0, 4.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
  std::vector<octomap::point3d> ends;
  for (int i = 0; i < rays; ++i) {
    Eigen::Vector3d d =
        (axis + 0.3 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng))).normalized();
    if (i % 17 == 0) d = Eigen::Vector3d::UnitZ() * (unit(rng) < 0 ? -1.0 : 1.0);
    // Diagonals: from a cell's centre (see ExpectSameCellsAsOneRayAtATime) two axes' crossings
    // tie at every step, which picks the axis a walk steps along first.
    if (i % 7 == 0) d = Eigen::Vector3d(1.0, unit(rng) < 0 ? -1.0 : 1.0, 0.0).normalized();
    if (i % 11 == 0) d = Eigen::Vector3d(0.0, 1.0, unit(rng) < 0 ? -1.0 : 1.0).normalized();
    double r = range(rng);
    if (i % 23 == 0) r = 0.01;    // ends in the origin's cell
    if (i % 29 == 0) r = 4000.0;  // leaves the key range at 5 cm (±1638 m)
    const Eigen::Vector3d e = Eigen::Vector3d(origin.x(), origin.y(), origin.z()) + r * d;
    ends.emplace_back(static_cast<float>(e.x()), static_cast<float>(e.y()),
                      static_cast<float>(e.z()));
  }
  return ends;
}

void ExpectSameCellsAsOneRayAtATime(BeamRaster::Kernel kernel) {
  octomap::OcTree tree(0.05);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> coordinate(-3.0f, 3.0f);
  BeamRaster raster(kernel);
  for (int beam = 0; beam < 200; ++beam) {
    octomap::point3d origin(coordinate(rng), coordinate(rng), coordinate(rng));
    if (beam % 3 == 0) origin = tree.keyToCoord(tree.coordToKey(origin));  // a cell's centre
    const auto ends = RandomBeam(rng, origin, 1 + beam % 97);
    std::size_t expected_visits = 0;
    const auto expected = ReferenceCells(tree, origin, ends, expected_visits);
    std::vector<std::uint64_t> cells;
    const std::size_t visits = raster.Trace(tree, origin, ends, cells);
    ASSERT_FALSE(raster.used_fallback());
    EXPECT_EQ(visits, expected_visits) << "beam " << beam;
    std::vector<std::uint64_t> sorted = cells;
    std::sort(sorted.begin(), sorted.end());
    ASSERT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end())
        << "a cell reported twice, beam " << beam;
    ASSERT_EQ(sorted, expected) << "beam " << beam;
  }
}

TEST(BeamRaster, PortableKernelGivesOneRayAtATimesCells) {
  ExpectSameCellsAsOneRayAtATime(BeamRaster::Kernel::kPortable);
}

TEST(BeamRaster, VectorKernelGivesOneRayAtATimesCells) {
  if (!BeamRaster::HasVectorKernel()) GTEST_SKIP() << "this processor has no AVX-512";
  ExpectSameCellsAsOneRayAtATime(BeamRaster::Kernel::kFastest);
}

TEST(BeamRaster, Avx2KernelGivesOneRayAtATimesCells) {
  if (!BeamRaster::HasAvx2Kernel()) GTEST_SKIP() << "this processor has no AVX2";
  ExpectSameCellsAsOneRayAtATime(BeamRaster::Kernel::kAvx2);
}

// The vector set-up of the walks gives StartRayWalkFromKey's values bit for bit (an ulp off
// would change a cell only at a rare tie, which the cell comparisons above could miss).
TEST(BeamRaster, VectorWalkSetUpIsStartRayWalksBitForBit) {
  if (!BeamRaster::HasVectorKernel()) GTEST_SKIP() << "this processor has no AVX-512";
  for (const double resolution : {0.05, 0.1, 0.0137}) {
    octomap::OcTree tree(resolution);
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<float> coordinate(-3.0f, 3.0f);
    for (int beam = 0; beam < 100; ++beam) {
      const octomap::point3d origin(coordinate(rng), coordinate(rng), coordinate(rng));
      const auto ends = RandomBeam(rng, origin, 1 + beam % 61);
      std::vector<RayWalk> scalar;
      std::vector<RayWalk> vector;
      StartRayWalks(tree, origin, ends, false, scalar);
      StartRayWalks(tree, origin, ends, true, vector);
      ASSERT_EQ(vector.size(), scalar.size()) << "beam " << beam;
      for (std::size_t w = 0; w < scalar.size(); ++w) {
        const RayWalk& a = scalar[w];
        const RayWalk& b = vector[w];
        EXPECT_TRUE(a.origin_key == b.origin_key && a.end_key == b.end_key);
        EXPECT_EQ(std::bit_cast<std::uint64_t>(a.length), std::bit_cast<std::uint64_t>(b.length));
        for (unsigned i = 0; i < 3; ++i) {
          EXPECT_EQ(a.step[i], b.step[i]);
          EXPECT_EQ(std::bit_cast<std::uint64_t>(a.t_max[i]),
                    std::bit_cast<std::uint64_t>(b.t_max[i]))
              << "beam " << beam << " walk " << w << " axis " << i;
          EXPECT_EQ(std::bit_cast<std::uint64_t>(a.t_delta[i]),
                    std::bit_cast<std::uint64_t>(b.t_delta[i]));
        }
      }
    }
  }
}

// A box too large for the marks (5 mm cells, 4 m rays: 1600^2 x 800 cells) is walked into a
// hash set instead, with the same cells.
TEST(BeamRaster, LargeBoxFallsBackToAHashSetWithTheSameCells) {
  octomap::OcTree tree(0.005);
  std::mt19937_64 rng(5);
  const octomap::point3d origin(0.1f, -0.2f, 0.3f);
  auto ends = RandomBeam(rng, origin, 40);
  std::erase_if(ends, [&](const octomap::point3d& e) { return (e - origin).norm() > 100.0; });
  std::size_t expected_visits = 0;
  const auto expected = ReferenceCells(tree, origin, ends, expected_visits);
  BeamRaster raster;
  std::vector<std::uint64_t> cells;
  EXPECT_EQ(raster.Trace(tree, origin, ends, cells), expected_visits);
  EXPECT_TRUE(raster.used_fallback());
  std::sort(cells.begin(), cells.end());
  EXPECT_EQ(cells, expected);
}

// Updating leaves in octree order along shared paths builds the tree OctoMap's updateNode builds,
// byte for byte, including clamping at the thresholds (keys updated many times over batches).
TEST(MapTree, UpdateLeavesInOrderBuildsUpdateNodesTree) {
  MapTree ours(0.05);
  octomap::OcTree octomaps(0.05);
  std::mt19937_64 rng(8);
  // Few keys (25^3) across the root's octants, so most are updated again and many reach a clamp.
  std::uniform_int_distribution<int> near(32768 - 12, 32768 + 12);
  std::bernoulli_distribution hit(0.3);
  for (int batch = 0; batch < 30; ++batch) {
    std::vector<std::pair<std::uint64_t, octomap::OcTreeKey>> updates;
    std::vector<std::uint64_t> seen;
    for (int i = 0; i < 3000; ++i) {
      const octomap::OcTreeKey key(static_cast<octomap::key_type>(near(rng)),
                                   static_cast<octomap::key_type>(near(rng)),
                                   static_cast<octomap::key_type>(near(rng)));
      if (std::find(seen.begin(), seen.end(), PackKey(key)) != seen.end()) continue;
      seen.push_back(PackKey(key));
      updates.emplace_back((MortonCode(key) << 1) | (hit(rng) ? 1 : 0), key);
    }
    for (const auto& [code, key] : updates) octomaps.updateNode(key, (code & 1) != 0, true);
    std::sort(updates.begin(), updates.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    const float log_odds[2] = {ours.getProbMissLog(), ours.getProbHitLog()};
    ours.UpdateLeavesInOrder(
        updates.size(), [&](std::size_t i) { return updates[i].second; },
        [&](std::size_t i) { return log_odds[updates[i].first & 1]; });
  }
  FinishUpdates(ours);
  octomaps.updateInnerOccupancy();
  std::ostringstream a;
  std::ostringstream b;
  WriteOctomapBinary(ours, a);
  WriteOctomapBinary(octomaps, b);
  EXPECT_EQ(ours.size(), octomaps.size());
  EXPECT_TRUE(a.str() == b.str());
}

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

}  // namespace
}  // namespace sonarbench::mapping
