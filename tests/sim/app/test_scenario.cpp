#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cli_util.hpp"
#include "sonarbench/sim/app/scenario.hpp"
#include "sonarbench/sim/report/report.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

using mapping::kDegToRad;

// The default tank scenario, run once for the whole suite (≈ 15 s on 2 cores); ctest runs this
// executable as one test so that the run is shared. Multipath, the tank's reverberation, its second
// trip, its pulse's skirts and the back lobe (which hears the wall behind the sonar) are switched
// off here, so that "nothing echoes from beyond a wall" holds exactly and a wall's echo starts at
// the wall, and so is its scattering's correlation across azimuth (its texture in long arcs leaves
// whole sectors of floor unmapped), and so are the sidelobes and the walls' glint (which map a
// strong echo onto every bearing within ±20° of it); BeamSynthesis tests them on their own. The
// scene's floor is fitted as faint as the real log's and its threshold (110) set against the
// reverberation, so it maps little floor. These tests are about where echoes land, so the walls
// here are bright (reflectivity 0.5, where the fitted 0.012 matches the real log's moderate wall
// echoes), the floor brighter (0.2, cos^0.5: 12 times the fitted floor's 0.03 cos¹ where the fan
// meets it, at 72.5° incidence) and, with no ghosts to reject, the threshold 90: the floor's echo
// is a run of its own before the wall's in nearly every beam. (A floor as bright as the walls
// merges with their echo into one run at the floor's range: with the threshold 60, 34-75 of a
// wall's 88-90 columns mapped.)
class TankScenario : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new Scene(LoadScene(test::SourcePath("scenes/cras-tank.yaml")));
    MaterialNamed("tank_wall").reflectivity = 0.5;
    MaterialNamed("tank_wall").glint = 0.0;
    scene_->sensor.acoustics.pattern.sidelobe_extent_deg = 0.0;
    Material& floor = MaterialNamed("tank_floor");
    floor.reflectivity = 0.2;
    floor.backscatter_exponent = 0.5;
    for (Material& m : scene_->materials) m.specular = 0.0;
    scene_->sensor.acoustics.tail.reverberation_length_m = 0.0;
    scene_->sensor.acoustics.tail.second_trip_db = -100.0;
    scene_->sensor.acoustics.pulse.skirt_length_m = 0.0;
    scene_->sensor.acoustics.pattern.back_lobe_width_deg = 0.0;
    scene_->sensor.acoustics.speckle.angular_correlation_deg = 0.0;
    scene_->mapping.detection.threshold = 90;
    // The floor's ring, detected here, reads as walls to the wall rule (docs/mapper.md): kept.
    scene_->mapping.detection.behind_walls = mapping::DetectionConfig::BehindWalls::kKeep;
    result_ = new ScenarioResult(RunScenario(*scene_, RunOptions{}));
    cells_ = new MapCells(CollectMapCells(result_->mapper->tree()));
  }
  static void TearDownTestSuite() {
    delete cells_;
    delete result_;
    delete scene_;
  }
  static Material& MaterialNamed(const std::string& name) {
    for (Material& m : scene_->materials) {
      if (m.name == name) return m;
    }
    throw std::runtime_error("scenes/cras-tank.yaml has no material " + name);
  }
  static octomap::point3d Centre(const octomap::OcTreeKey& key) {
    return result_->mapper->tree().keyToCoord(key);
  }
  // Half the tank's inner size along x (0) or y (1), and the sonar's position.
  static double HalfSide(int axis) {
    return 0.5 * scene_->meshes.front().size_m[static_cast<std::size_t>(axis)];
  }
  static Eigen::Vector3d Sonar() { return scene_->trajectory.waypoints.front().position_m; }
  static Scene* scene_;
  static ScenarioResult* result_;
  static MapCells* cells_;
};

Scene* TankScenario::scene_ = nullptr;

ScenarioResult* TankScenario::result_ = nullptr;

MapCells* TankScenario::cells_ = nullptr;

std::string MapBytes(const ScenarioResult& result) {
  std::ostringstream out;
  result.mapper->tree().writeBinaryConst(out);
  return out.str();
}

// Nothing lies beyond the walls (and multipath is off), so no echo starts beyond a wall. An
// occupied end point can still pass the wall: a later run may start inside the wall's echo, up
// to a pulse length L behind the axis range d, and the mapper puts it on every ray, while
// off-axis rays reach the wall up to d·(1/cos(w_v/2) - 1) later; add the cell's half diagonal,
// with d the farthest wall point (the far corner). Every occupied cell must lie inside.
TEST_F(TankScenario, NoOccupiedCellBeyondTheWalls) {
  const auto& g = scene_->sensor.geometry;
  const double corner =
      std::hypot(HalfSide(0) + std::abs(Sonar().x()), HalfSide(1) + std::abs(Sonar().y()));
  const double slack = scene_->sensor.acoustics.pulse.length_m +
                       corner * (1.0 / std::cos(g.beam_width_vertical_rad / 2) - 1.0) +
                       0.5 * std::sqrt(3.0) * scene_->mapping.resolution_m;
  std::size_t outside = 0;
  for (const auto& key : cells_->occupied) {
    const auto c = Centre(key);
    const bool beyond =
        std::abs(c.x()) > HalfSide(0) + slack || std::abs(c.y()) > HalfSide(1) + slack;
    outside += beyond ? 1 : 0;
  }
  EXPECT_EQ(outside, 0u) << "of " << cells_->occupied.size() << " occupied cells";
  EXPECT_GT(cells_->occupied.size(), 0u);
}

// Each wall's columns at the sonar's height. Away from the corners a beam meets a wall at
// under 45° off its normal, where its echo per ray is still ≥ cos 45° of the normal one (-1.5 dB;
// the analytic wall test shows the normal echo detected with tens of counts to spare), so the
// axis of nearly every beam lands on the wall row. Beams are 1.8° apart (5-9 cm on the wall) and
// 3° wide, so they overlap: every column is inside some beam. The corners' oblique cells may be
// missed, and speckle may drop a few more: at least 90% per wall.
TEST_F(TankScenario, EveryWallIsMappedAtTheSonarsHeight) {
  const double res = scene_->mapping.resolution_m;
  for (int axis = 0; axis < 2; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      const double at = sign * HalfSide(axis);
      SCOPED_TRACE((axis == 0 ? "x = " : "y = ") + std::to_string(at));
      const int along = 1 - axis;
      std::set<int> truth_columns;
      std::set<int> mapped_columns;
      for (const auto& key : result_->score.truth) {
        const auto c = Centre(key);
        if (std::abs(c(axis) - at) < res && std::abs(c(along)) < HalfSide(along)) {
          truth_columns.insert(key[static_cast<unsigned>(along)]);
        }
      }
      for (const auto& key : cells_->occupied) {
        const auto c = Centre(key);
        if (std::abs(c(axis) - at) < 2 * res && std::abs(c.z() - Sonar().z()) < 2 * res) {
          mapped_columns.insert(key[static_cast<unsigned>(along)]);
        }
      }
      std::size_t hit = 0;
      for (int column : truth_columns) hit += mapped_columns.contains(column) ? 1 : 0;
      EXPECT_GE(truth_columns.size(), static_cast<std::size_t>(2 * HalfSide(along) / res) - 1);
      std::printf("wall %c%s: %zu of %zu columns mapped\n", axis == 0 ? 'x' : 'y',
                  sign > 0 ? "+" : "-", hit, truth_columns.size());
      EXPECT_GE(static_cast<double>(hit) / truth_columns.size(), 0.90)
          << hit << " of " << truth_columns.size() << " columns";
    }
  }
}

// The floor enters the 35° fan where the lowest ray meets it: slant range h / sin 17.5° = 1.53 m,
// horizontal radius h / tan 17.5° = 1.46 m for h = 0.46 m. The floor's echo is the first run of
// nearly every beam, so the floor layer holds occupied cells around that radius in every
// direction: at least 90% of 5° sectors, allowing for beams whose floor echo speckle hides or
// whose lowest rays a vehicle part stops (72 of 72 measured before the parts low in the fan at the
// real log's spots, 68 with them).
TEST_F(TankScenario, FloorRingAppearsWhereTheFanMeetsTheFloor) {
  const double h = Sonar().z();
  const double ring = h / std::tan(scene_->sensor.geometry.beam_width_vertical_rad / 2);
  const double res = scene_->mapping.resolution_m;
  std::set<int> sectors;
  for (const auto& key : cells_->occupied) {
    const auto c = Centre(key);
    const double dx = c.x() - Sonar().x();
    const double dy = c.y() - Sonar().y();
    if (c.z() < res && std::abs(std::hypot(dx, dy) - ring) < 3 * res) {
      sectors.insert(
          static_cast<int>(std::floor((std::atan2(dy, dx) + std::numbers::pi) / (5 * kDegToRad))));
    }
  }
  std::printf("floor ring: %zu of 72 sectors\n", sectors.size());
  EXPECT_GE(sectors.size(), static_cast<std::size_t>(0.9 * 72))
      << sectors.size() << " of 72 sectors";
}

TEST_F(TankScenario, MetricsAreConsistentWithTheirCounts) {
  const MapMetrics& m = result_->score.metrics;
  EXPECT_EQ(m.occupied_cells, cells_->occupied.size());
  EXPECT_LE(m.observable_cells, m.truth_cells);
  EXPECT_DOUBLE_EQ(m.occupied_precision,
                   static_cast<double>(m.true_positive_cells) / m.occupied_cells);
  EXPECT_DOUBLE_EQ(m.occupied_recall,
                   static_cast<double>(m.observed_occupied_cells) / m.observable_cells);
  EXPECT_DOUBLE_EQ(m.coverage, static_cast<double>(m.known_observable_cells) / m.observable_cells);
  EXPECT_EQ(result_->beams, 27u * 200u);
}

TEST_F(TankScenario, OutputsAreWrittenWithTheReportLast) {
  test::TempDir dir;
  WriteScenarioOutputs(dir.path().string(), *scene_, *result_);
  for (const char* file : {"report.json", "junit.xml", "report.html", "map.bt", "polar.png",
                           "fan.png", "map_top.png", "map_side.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir.path() / file)) << file;
  }
  std::ifstream in(dir.path() / "report.json");
  const auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report["seed"], scene_->seed);
  EXPECT_DOUBLE_EQ(report["metrics"]["occupied_precision"].get<double>(),
                   result_->score.metrics.occupied_precision);
  EXPECT_TRUE(report["timing"].contains("map_s"));
  EXPECT_EQ(report["parameters"]["mapping"]["rays_vertical"], 64);
  // The sensor's settings in force, the ones switched off too.
  const auto& acoustics = report["parameters"]["sensor"]["acoustics"];
  EXPECT_EQ(acoustics["gain_db"], scene_->sensor.acoustics.gain.gain_db);
  EXPECT_EQ(acoustics["sidelobe_extent_deg"], 0.0);
  EXPECT_EQ(acoustics["sidelobe_rays_vertical"], 10);
  EXPECT_EQ(acoustics["ad_knee"], 100.0);
  EXPECT_EQ(acoustics["ad_ceiling"], 191.0);
  // Every mesh's preflight, the vehicle's parts marked as such.
  std::size_t parts = 0;
  for (const auto& mesh : report["meshes"]) parts += mesh["vehicle_part"].get<bool>() ? 1 : 0;
  EXPECT_EQ(report["meshes"].size(), scene_->meshes.size() + scene_->vehicle.size());
  EXPECT_EQ(parts, scene_->vehicle.size());
  EXPECT_GT(parts, 0u);
  // The map file is a real OctoMap.
  octomap::OcTree reread(0.1);
  ASSERT_TRUE(reread.readBinary((dir.path() / "map.bt").string()));
  EXPECT_DOUBLE_EQ(reread.getResolution(), scene_->mapping.resolution_m);
  std::size_t left_over = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    left_over += entry.path().string().find(".tmp.") != std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(left_over, 0u);
}

TEST_F(TankScenario, BinaryMapIsByteForByteOctomapsOwn) {
  std::ostringstream ours;
  std::ostringstream octomaps;
  mapping::WriteOctomapBinary(result_->mapper->tree(), ours);
  ASSERT_TRUE(result_->mapper->tree().writeBinaryConst(octomaps));
  EXPECT_EQ(ours.str(), octomaps.str());
}

// The seabed survey: nothing lies above the seabed and its objects, so no occupied cell may
// either, beyond what the sonar's geometry explains. A beam meeting a flat bed h below the sonar
// marks its whole 35° arc at that range, whose ends rise h·(1 - cos 17.5°) above the bed
// whatever the head angle; detection may lead the echo by the smoothing half-window (2 bins); a
// cell centre sits up to half a cell from the point that marked it.
TEST(SeabedScenario, NothingOccupiedAboveTheSeabed) {
  const Scene scene = LoadScene(test::SourcePath("scenes/seabed.yaml"));
  const ScenarioResult result = RunScenario(scene, RunOptions{});
  const auto& tree = result.mapper->tree();
  double truth_top = -1e9;
  for (const auto& key : result.score.truth)
    truth_top = std::max<double>(truth_top, tree.keyToCoord(key).z());
  const double sonar_z = (scene.trajectory.waypoints.front().position_m +
                          scene.sensor.geometry.T_vehicle_sonar.translation())
                             .z();
  const double rise = sonar_z * (1.0 - std::cos(scene.sensor.geometry.beam_width_vertical_rad / 2));
  const double lead =
      (scene.mapping.detection.smoothing_bins / 2) * scene.sensor.geometry.bin_size_m;
  const double bound = truth_top + rise + lead + 0.5 * scene.mapping.resolution_m;
  const MapCells cells = CollectMapCells(tree);
  ASSERT_GT(cells.occupied.size(), 1000u);
  std::size_t above = 0;
  for (const auto& key : cells.occupied) above += tree.keyToCoord(key).z() > bound ? 1 : 0;
  EXPECT_EQ(above, 0u) << "occupied cells above z = " << bound << " m";
  EXPECT_GT(result.score.metrics.occupied_recall, 0.0);
}

// The map and the report's images too: on two threads the images are drawn side by side.
TEST(Scenario, MapIsIdenticalForOneAndTwoThreads) {
  Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  scene.sweeps = 2;
  test::TempDir dir;
  std::string map[2];
  for (const int threads : {1, 2}) {
    RunOptions options;
    options.threads = threads;
    const ScenarioResult result = RunScenario(scene, options);
    map[threads - 1] = MapBytes(result);
    WriteScenarioOutputs((dir.path() / std::to_string(threads)).string(), scene, result);
  }
  EXPECT_EQ(map[0], map[1]);
  for (const char* image : {"polar.png", "fan.png", "map_top.png", "map_side.png"}) {
    const std::string one = test::ReadFile(dir.path() / "1" / image);
    EXPECT_GT(one.size(), 1000u) << image;
    EXPECT_EQ(one, test::ReadFile(dir.path() / "2" / image)) << image;
  }
}

}  // namespace
}  // namespace sonarbench::sim
