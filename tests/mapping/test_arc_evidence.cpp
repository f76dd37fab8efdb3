#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "arc_evidence.hpp"
#include "key_set.hpp"
#include "mapping_grid.hpp"
#include "sonarbench/mapping/mapper.hpp"

namespace sonarbench::mapping {
namespace {

// Cells are 5 cm; the Micron's wedge is 35° high, its two-way pattern -3 dB at ±17.5°.
using test::kResolution;
constexpr double kWidthV = 35.0 * kDegToRad;
const double kPatternK = 4.0 * std::log(2.0) / (kWidthV * kWidthV);

std::uint64_t KeyAt(const octomap::OcTree& tree, double x, double y, double z) {
  return PackKey(tree.coordToKey(x, y, z));
}

double ShareOf(std::uint64_t update) {
  return static_cast<double>(update & kShareLevelMax) / static_cast<double>(kShareLevelMax);
}

// An arc of cells at 2 m straight ahead, from the axis to the wedge's upper edge: the axis cell
// takes the whole echo, the edge cell half (the -3 dB point), to within what one cell's height
// (0.05 m at 2 m: 1.4°) moves the pattern: 0.006 on the axis, 2.27 / rad · 0.0125 rad = 0.03 at
// the edge; and the level's rounding (1/255).
TEST(ArcEvidence, AShellCellsShareFollowsTheVerticalPattern) {
  const octomap::OcTree tree(kResolution);
  const double range = 2.0;
  const double edge = kWidthV / 2;
  const std::vector<std::uint64_t> keys{
      KeyAt(tree, range, 0.0, 0.0),
      KeyAt(tree, range * std::cos(edge / 2), 0.0, range * std::sin(edge / 2)),
      KeyAt(tree, range * std::cos(edge), 0.0, range * std::sin(edge))};
  ArcShareScratch scratch;
  std::vector<std::uint64_t> out;
  const ArcEvidence evidence{kPatternK};
  const std::vector<double> ranges{range};
  AppendArcShares(tree, evidence, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), ranges, keys,
                  scratch, out);
  ASSERT_EQ(out.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(out[i] >> kShareBits, keys[i]);
  EXPECT_EQ(ShareOf(out[0]), 1.0);  // the shell's strongest is the reference
  EXPECT_NEAR(ShareOf(out[1]), std::pow(0.5, 0.25), 0.02);
  EXPECT_NEAR(ShareOf(out[2]), 0.5, 0.03 + 1.0 / 255);
}

// What the map already holds weighs in: a cell it knows is free (occupancy 0.4 after one miss)
// gets 0.4 / 0.5 of the share an unknown cell in its place would get; two detections' shells
// are normalised each on its own.
TEST(ArcEvidence, KnownFreeCellsGetLessAndEachShellIsItsOwn) {
  octomap::OcTree tree(kResolution);
  tree.setProbMiss(0.4);
  const double up = 0.2;  // 5.7° up at 2 m
  tree.updateNode(octomap::point3d(2.0F, 0.0F, static_cast<float>(up)), false);
  const std::vector<std::uint64_t> keys{KeyAt(tree, 2.0, 0.0, 0.0), KeyAt(tree, 2.0, 0.0, up),
                                        KeyAt(tree, 3.5, 0.0, 0.0), KeyAt(tree, 3.5, 0.0, up)};
  ArcShareScratch scratch;
  std::vector<std::uint64_t> out;
  const std::vector<double> ranges{2.0, 3.5};
  AppendArcShares(tree, ArcEvidence{kPatternK}, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(),
                  ranges, keys, scratch, out);
  ASSERT_EQ(out.size(), 4u);
  // Cell centres: (2.025, 0.025, 0.025) and (2.025, 0.025, 0.225), likewise at 3.525.
  auto pattern = [](double x, double z) {
    const double e = std::atan2(z, std::hypot(x, 0.025));
    return std::exp(-kPatternK * e * e);
  };
  const double near_ratio = pattern(2.025, 0.225) / pattern(2.025, 0.025);
  const double far_ratio = pattern(3.525, 0.225) / pattern(3.525, 0.025);
  EXPECT_EQ(ShareOf(out[0]), 1.0);
  EXPECT_NEAR(ShareOf(out[1]), near_ratio * 0.4 / 0.5, 1.0 / 255);
  EXPECT_EQ(ShareOf(out[2]), 1.0);
  EXPECT_NEAR(ShareOf(out[3]), far_ratio, 1.0 / 255);
}

// A share's update lies between nothing and the full hit, and the full share is the hit itself.
TEST(ArcEvidence, AShareUpdatesByItsPartOfTheHit) {
  const float hit = octomap::logodds(0.7);
  EXPECT_EQ(ShareLogOdds(0.7, hit, kShareLevelMax), hit);
  EXPECT_NEAR(ShareLogOdds(0.7, hit, (kShareLevelMax + 1) / 2), std::log(0.6004 / 0.3996), 1e-3);
  EXPECT_GT(ShareLogOdds(0.7, hit, 1), 0.0F);
  EXPECT_LT(ShareLogOdds(0.7, hit, 1), 0.01F);
}

MapperConfig Config(Occupancy occupancy, int threads, Integration integration) {
  MapperConfig config;
  config.integration = integration;
  config.resolution_m = kResolution;
  config.threads = threads;
  config.occupancy = occupancy;
  return config;
}

Beam AxisBeam(const SensorGeometry& sensor, const Eigen::Vector3d& position, double head_deg) {
  Beam beam;
  beam.head_angle_rad = head_deg * kDegToRad;
  beam.bin_size_m = sensor.bin_size_m;
  beam.intensities.assign(static_cast<std::size_t>(sensor.num_bins), 0);
  beam.T_world_sonar = PoseFromXyzRpy(position, Eigen::Vector3d::Zero());
  return beam;
}

struct WallMap {
  int ghosts = 0;      // occupied, more than one cell in front of the wall, 0.3-0.9 m up
  int wall_cells = 0;  // occupied cells of the wall's face, y 0-0.05 m, 0.3-0.9 m up
};

// A wall across x = 3.0 heard from heights 0 and 0.6 m in turn, a sweep from each, by five
// beams 1.8° apart around the one straight at it (first echo 3.0 m; further out in the others'
// wedges). A view's arc lies sqrt(9 - dz²) from it, dz up or down: the low view's arc is more
// than a cell in front of the wall (x < 2.9) 0.77-0.9 m up, where the high view's beam crosses
// the water before its echo (those cells' far corners are under 2.93 m from it). Each such cell
// gets a hit and a miss per round: arc marking gains logodds(0.7) + logodds(0.4) = +0.44, arc
// evidence loses once its share falls under about half. The wall's cells (x 2.95-3.0) lie on
// the high view's arc over 0.06-1.14 m and in no view's water.
WallMap MapWallFromTwoHeights(Occupancy occupancy, int threads, std::string* bytes = nullptr,
                              Integration integration = Integration::kExact,
                              KeySetKind key_set = MapperConfig{}.key_set) {
  const SensorGeometry sensor;
  MapperConfig config = Config(occupancy, threads, integration);
  config.key_set = key_set;
  Mapper mapper(config, sensor);
  std::vector<std::vector<double>> echoes;
  for (int k = -2; k <= 2; ++k) {
    const double off_deg = std::max(0.0, std::abs(1.8 * k) - 1.5);
    echoes.push_back({3.0 / std::cos(off_deg * kDegToRad)});
  }
  for (int sweep = 0; sweep < 12; ++sweep) {
    std::vector<Beam> beams;
    for (int k = -2; k <= 2; ++k) {
      beams.push_back(AxisBeam(sensor, {0.0, 0.0, 0.6 * (sweep % 2)}, 1.8 * k));
    }
    mapper.Integrate(beams, echoes);
  }
  const octomap::OcTree& tree = mapper.tree();
  WallMap result;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    if (!tree.isNodeOccupied(*it) || it.getZ() < 0.3 || it.getZ() > 0.9) continue;
    if (it.getX() < 3.0 - 1.5 * kResolution) ++result.ghosts;
    if (std::abs(it.getX() - 2.975) < 1e-6 && std::abs(it.getY() - 0.025) < 1e-6) {
      ++result.wall_cells;
    }
  }
  if (bytes != nullptr) {
    std::ostringstream out;
    WriteOctomapBinary(tree, out);
    *bytes = out.str();
  }
  return result;
}

TEST(ArcEvidence, ViewsFromAnotherHeightCarveTheArcDownToTheWall) {
  const WallMap marking = MapWallFromTwoHeights(Occupancy::kArcMarking, 1);
  const WallMap evidence = MapWallFromTwoHeights(Occupancy::kArcEvidence, 1);
  EXPECT_GT(marking.ghosts, 0);   // the seed's arcs stay where each view put them
  EXPECT_EQ(evidence.ghosts, 0);  // the other view's water wins
  // The wall's face, 0.3-0.9 m: 12 cells high, all occupied either way.
  EXPECT_EQ(marking.wall_cells, 12);
  EXPECT_EQ(evidence.wall_cells, 12);
}

// The ray casts (32 × 64) carve the same way: their occupied cells hold the rays' end points on
// the shell, their free cells are those the rays cross before it.
TEST(ArcEvidence, TheRayCastsCarveToo) {
  const WallMap marking =
      MapWallFromTwoHeights(Occupancy::kArcMarking, 1, nullptr, Integration::kRays);
  const WallMap evidence =
      MapWallFromTwoHeights(Occupancy::kArcEvidence, 1, nullptr, Integration::kRays);
  EXPECT_GT(marking.ghosts, 0);
  EXPECT_EQ(evidence.ghosts, 0);
  EXPECT_EQ(marking.wall_cells, 12);
  EXPECT_EQ(evidence.wall_cells, 12);
}

// Shares and free cells merge alike whatever collects them: any thread count, any key set, both
// integrations.
TEST(ArcEvidence, TheMapIsTheSameOnAnyThreadCountAndKeySet) {
  for (const Integration integration : {Integration::kExact, Integration::kRays}) {
    std::string one;
    (void)MapWallFromTwoHeights(Occupancy::kArcEvidence, 1, &one, integration);
    for (const KeySetKind set :
         {KeySetKind::kBlocks, KeySetKind::kOpenAddressing, KeySetKind::kStd}) {
      std::string two;
      (void)MapWallFromTwoHeights(Occupancy::kArcEvidence, 2, &two, integration, set);
      EXPECT_EQ(one, two) << static_cast<int>(set);
    }
  }
}

}  // namespace
}  // namespace sonarbench::mapping
