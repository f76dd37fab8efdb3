#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "key_set.hpp"
#include "mapping_grid.hpp"
#include "sonarbench/mapping/mapper.hpp"

namespace sonarbench::mapping {
namespace {

// Cells are 5 cm; a cell is named by its centre. The sonar sits at the origin looking along +x
// (head angle 0): at 1 m its 3° × 35° wedge spans ±0.026 m across and ±0.315 m up and down.
using test::kResolution;

const octomap::OcTreeNode* Cell(const Mapper& mapper, double x, double y, double z) {
  return mapper.tree().search(x, y, z);
}

bool IsFree(const Mapper& mapper, double x, double y, double z) {
  const auto* node = Cell(mapper, x, y, z);
  return node != nullptr && !mapper.tree().isNodeOccupied(node);
}

bool IsOccupied(const Mapper& mapper, double x, double y, double z) {
  const auto* node = Cell(mapper, x, y, z);
  return node != nullptr && mapper.tree().isNodeOccupied(node);
}

MapperConfig Config() {
  MapperConfig config;
  config.resolution_m = kResolution;
  config.threads = 1;
  return config;
}

Beam AxisBeam(const SensorGeometry& sensor, const Eigen::Vector3d& position = {0, 0, 0}) {
  Beam beam;
  beam.bin_size_m = sensor.bin_size_m;
  beam.intensities.assign(static_cast<std::size_t>(sensor.num_bins), 0);
  beam.T_world_sonar = PoseFromXyzRpy(position, Eigen::Vector3d::Zero());
  return beam;
}

// A wall at 2.52 m: the cells of the wedge before it are free, the cell it is in occupied, the
// cells behind it and outside the wedge untouched; each updated once, by the hit or miss log-odds.
TEST(Mapper, AnEchoIsOccupiedAtItsRangeAndFreeBeforeIt) {
  const SensorGeometry sensor;
  Mapper mapper(Config(), sensor);
  const std::vector<Beam> beams{AxisBeam(sensor)};
  const std::vector<std::vector<double>> echoes{{2.52}};
  mapper.Integrate(beams, echoes);
  const auto* wall = Cell(mapper, 2.525, 0.025, 0.025);
  ASSERT_NE(wall, nullptr);
  EXPECT_FLOAT_EQ(wall->getLogOdds(), octomap::logodds(0.7));
  const auto* water = Cell(mapper, 1.025, 0.025, 0.025);
  ASSERT_NE(water, nullptr);
  EXPECT_FLOAT_EQ(water->getLogOdds(), octomap::logodds(0.4));
  EXPECT_TRUE(IsFree(mapper, 1.025, 0.025, 0.225));        // 12.4° up: inside the 17.5°
  EXPECT_TRUE(IsFree(mapper, 2.475, -0.025, -0.025));      // the cell before the wall's
  EXPECT_EQ(Cell(mapper, 3.025, 0.025, 0.025), nullptr);   // behind the wall
  EXPECT_EQ(Cell(mapper, 1.025, 0.175, 0.025), nullptr);   // 8.5° across: outside the 1.5°
  EXPECT_EQ(Cell(mapper, 1.025, 0.025, 0.425), nullptr);   // 21° up: outside the 17.5°
  EXPECT_EQ(Cell(mapper, -1.025, 0.025, 0.025), nullptr);  // behind the sonar
}

// A wall 2.52 m away heard with a floor at z = -0.2 m and a surface at 0.3 m: its arc spans
// ±2.52 tan 17.5° = ±0.79 m, and only the cells whose box reaches the water, [-0.25, 0.35), stay
// occupied, each as without the water column, by both integrations; free space is the same.
TEST(Mapper, NoEchoComesFromBeyondTheWaterColumn) {
  const SensorGeometry sensor;
  const std::vector<Beam> beams{AxisBeam(sensor)};
  const std::vector<std::vector<double>> echoes{{2.52}};
  for (const Integration integration : {Integration::kExact, Integration::kRays}) {
    MapperConfig config = Config();
    config.integration = integration;
    Mapper open(config, sensor);
    open.Integrate(beams, echoes);
    config.water = {-0.2, 0.3};
    Mapper bounded(config, sensor);
    bounded.Integrate(beams, echoes);
    std::size_t kept = 0, dropped = 0;
    open.ForEachLeaf([&](const octomap::OcTreeKey& key, bool occupied) {
      const double z = open.tree().keyToCoord(key).z();
      const auto* node = bounded.tree().search(key);
      if (!occupied) {
        ASSERT_NE(node, nullptr) << z;
        EXPECT_FALSE(bounded.tree().isNodeOccupied(node)) << z;
        return;
      }
      const bool inside = z > -0.25 && z < 0.35;
      EXPECT_EQ(node != nullptr && bounded.tree().isNodeOccupied(node), inside) << z;
      (inside ? kept : dropped) += 1;
    });
    EXPECT_GT(kept, 0u);
    EXPECT_GT(dropped, kept);  // 0.6 m of the arc's 1.58 m lie in the water
    EXPECT_TRUE(IsOccupied(bounded, 2.525, 0.025, -0.225));  // the floor's own cell
    EXPECT_TRUE(IsOccupied(bounded, 2.525, 0.025, 0.325));   // the surface's
    EXPECT_EQ(Cell(bounded, 2.525, 0.025, -0.275), nullptr);
  }
}

// A beam without an echo clears the wedge to the sensor's maximum range (5.0 m), or to the
// configured free range, or nothing at all.
TEST(Mapper, ABeamWithoutAnEchoClearsAsConfigured) {
  const SensorGeometry sensor;
  const std::vector<Beam> beams{AxisBeam(sensor)};
  const std::vector<std::vector<double>> none{{}};
  Mapper to_max(Config(), sensor);
  to_max.Integrate(beams, none);
  EXPECT_TRUE(IsFree(to_max, 1.025, 0.025, 0.025));
  EXPECT_TRUE(IsFree(to_max, 4.925, 0.025, 0.025));
  EXPECT_EQ(Cell(to_max, 5.075, 0.025, 0.025), nullptr);
  MapperConfig config = Config();
  config.free_range_m = 2.0;
  Mapper to_two(config, sensor);
  to_two.Integrate(beams, none);
  EXPECT_TRUE(IsFree(to_two, 1.925, 0.025, 0.025));
  EXPECT_EQ(Cell(to_two, 2.075, 0.025, 0.025), nullptr);
  config.clear_without_obstacle = false;
  Mapper not_at_all(config, sensor);
  not_at_all.Integrate(beams, none);
  EXPECT_EQ(not_at_all.tree().size(), 0u);
}

// IntegrateSweeps detects and integrates a sweep (200 beams of 1.8°) at a time, a last partial
// sweep included: here 300 beams, the last 100 of them 10 m further along x, all empty.
TEST(Mapper, IntegrateSweepsIntegratesTheLastPartialSweep) {
  const SensorGeometry sensor;
  ASSERT_EQ(sensor.BeamsPerSweep(), 200);
  std::vector<Beam> beams(200, AxisBeam(sensor));
  beams.resize(300, AxisBeam(sensor, {10.0, 0.0, 0.0}));
  Mapper mapper(Config(), sensor);
  std::vector<std::pair<std::size_t, std::size_t>> progress;
  mapper.IntegrateSweeps(
      beams, [&](std::size_t done, std::size_t total) { progress.emplace_back(done, total); });
  EXPECT_EQ(progress, (std::vector<std::pair<std::size_t, std::size_t>>{{1, 2}, {2, 2}}));
  EXPECT_TRUE(IsFree(mapper, 1.025, 0.025, 0.025));
  EXPECT_TRUE(IsFree(mapper, 11.025, 0.025, 0.025));
  EXPECT_FALSE(IsOccupied(mapper, 11.025, 0.025, 0.025));
}

// The map's files and leaves come from the log-odds the batches left, without the tree: before
// tree() is ever asked for they are what the tree, once built, writes and holds.
TEST(Mapper, WritesAndListsTheMapAsItsTreeWithoutBuildingIt) {
  const SensorGeometry sensor;
  std::vector<Beam> beams;
  std::vector<std::vector<double>> echoes;
  for (int b = 0; b < 40; ++b) {
    beams.push_back(AxisBeam(sensor, {0.0, 0.0, 0.1 * (b % 3)}));
    beams.back().head_angle_rad = 0.05 * b;
    echoes.push_back(b % 5 == 0 ? std::vector<double>{} : std::vector<double>{1.0 + 0.03 * b});
  }
  MapperConfig config = Config();
  config.threads = 2;
  Mapper mapper(config, sensor);
  mapper.Integrate(std::span(beams).first(20), std::span(echoes).first(20));
  mapper.Integrate(std::span(beams).last(20), std::span(echoes).last(20));
  std::ostringstream written_bt, written_ot;
  mapper.WriteBinary(written_bt);
  mapper.WriteFull(written_ot);
  std::vector<std::pair<std::uint64_t, bool>> leaves;
  mapper.ForEachLeaf([&leaves](const octomap::OcTreeKey& key, bool occupied) {
    leaves.emplace_back(PackKey(key), occupied);
  });
  const octomap::OcTree& tree = mapper.tree();
  std::ostringstream bt, ot;
  WriteOctomapBinary(tree, bt);
  (void)tree.write(ot);
  EXPECT_GT(tree.size(), 1000u);
  EXPECT_TRUE(written_bt.str() == bt.str());
  EXPECT_TRUE(written_ot.str() == ot.str());
  std::vector<std::pair<std::uint64_t, bool>> tree_leaves;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    tree_leaves.emplace_back(PackKey(it.getKey()), tree.isNodeOccupied(*it));
  }
  std::sort(leaves.begin(), leaves.end());
  std::sort(tree_leaves.begin(), tree_leaves.end());
  EXPECT_EQ(leaves, tree_leaves);
  EXPECT_TRUE(std::any_of(leaves.begin(), leaves.end(), [](const auto& l) { return l.second; }));
}

// The mapper checks its own configuration (not only the YAML reader does): each field outside
// what it takes is refused by name; the defaults and the reader's bounds are taken.
TEST(Mapper, RefusesAConfigurationItCannotTakeNamingTheField) {
  const SensorGeometry sensor;
  EXPECT_NO_THROW(Mapper(MapperConfig{}, sensor));
  const auto refused = [&](const std::function<void(MapperConfig&)>& change) {
    MapperConfig c;
    change(c);
    try {
      Mapper mapper(c, sensor);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(refused([](MapperConfig& c) { c.resolution_m = 0.0; }).find("resolution_m"),
            std::string::npos);
  EXPECT_NE(refused([](MapperConfig& c) { c.rays_vertical = 0; }).find("rays_vertical"),
            std::string::npos);
  EXPECT_NE(refused([](MapperConfig& c) { c.detection.threshold = 256; }).find("threshold"),
            std::string::npos);
  EXPECT_NE(refused([](MapperConfig& c) { c.detection.smoothing_bins = 4; }).find("smoothing"),
            std::string::npos);
  EXPECT_NE(refused([](MapperConfig& c) { c.prob_hit = 0.4; }).find("prob_hit"), std::string::npos);
  EXPECT_NE(refused([](MapperConfig& c) {
              c.water = {1.0, 1.0};
            }).find("water.floor_z_m"),
            std::string::npos);
  EXPECT_EQ(refused([](MapperConfig& c) {
              c.detection.threshold = 255;
              c.prob_hit = 1.0;
              c.clamp_min = 0.5;
            }),
            "");
}

}  // namespace
}  // namespace sonarbench::mapping
