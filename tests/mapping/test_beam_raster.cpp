#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <random>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include "beam_raster.hpp"
#include "beam_volume.hpp"
#include "integrate.hpp"
#include "map_tree.hpp"
#include "ray_keys.hpp"
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
// Traces `ends` from `origin`: the raster must fall back to one ray at a time and give the
// reference's cells and visits. Returns the number of distinct cells.
std::size_t ExpectFallbackWithTheSameCells(const octomap::OcTree& tree,
                                           const octomap::point3d& origin,
                                           const std::vector<octomap::point3d>& ends) {
  std::size_t expected_visits = 0;
  const auto expected = ReferenceCells(tree, origin, ends, expected_visits);
  BeamRaster raster;
  std::vector<std::uint64_t> cells;
  EXPECT_EQ(raster.Trace(tree, origin, ends, cells), expected_visits);
  EXPECT_TRUE(raster.used_fallback());
  std::sort(cells.begin(), cells.end());
  EXPECT_EQ(cells, expected);
  return expected.size();
}

TEST(BeamRaster, LargeBoxFallsBackToAHashSetWithTheSameCells) {
  octomap::OcTree tree(0.005);
  std::mt19937_64 rng(5);
  const octomap::point3d origin(0.1f, -0.2f, 0.3f);
  auto ends = RandomBeam(rng, origin, 40);
  std::erase_if(ends, [&](const octomap::point3d& e) { return (e - origin).norm() > 100.0; });
  ExpectFallbackWithTheSameCells(tree, origin, ends);
}

// A beam at the edge of the key range (±1638.4 m at 5 cm): the bitmap's box would reach past the
// last key, so the cells are collected one ray at a time; the same cells either way.
TEST(BeamRaster, ABeamAtTheEdgeOfTheKeyRangeFallsBackWithTheSameCells) {
  octomap::OcTree tree(0.05);
  std::mt19937_64 rng(6);
  const octomap::point3d origin(1636.0f, -1636.5f, 0.3f);
  auto ends = RandomBeam(rng, origin, 40);
  EXPECT_GT(ExpectFallbackWithTheSameCells(tree, origin, ends), 40u);
}

}  // namespace
}  // namespace sonarbench::mapping
