#include <gtest/gtest.h>
#include <matio.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <numbers>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "cli_util.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/app/map_log.hpp"
#include "sonarbench/sim/app/scenario.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/report/fidelity_report.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/scene.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

using test::RealLogPath;

using mapping::kDegToRad;

// A straight wall: the wall points of one side lie on a line. Fitted by total least squares to
// the points within ±2 cells of a RANSAC line (so a few beams that stopped at something in front
// of the wall do not bend it).
struct LineFit {
  Eigen::Vector2d point;
  Eigen::Vector2d direction;
  double rms_m = 0.0;
  double inlier_fraction = 0.0;
};

LineFit FitWall(const std::vector<Eigen::Vector2d>& points, double band_m,
                const Eigen::Vector2d& expected_normal, double max_tilt_rad) {
  LineFit best;
  std::size_t best_inliers = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t j = i + 1; j < points.size(); j += 3) {
      const Eigen::Vector2d d = (points[j] - points[i]).normalized();
      const Eigen::Vector2d n(-d.y(), d.x());
      if (std::abs(n.dot(expected_normal)) < std::cos(max_tilt_rad)) continue;
      std::size_t inliers = 0;
      for (const auto& p : points) inliers += std::abs(n.dot(p - points[i])) <= band_m ? 1 : 0;
      if (inliers > best_inliers) {
        best_inliers = inliers;
        best.point = points[i];
        best.direction = d;
      }
    }
  }
  const Eigen::Vector2d n(-best.direction.y(), best.direction.x());
  std::vector<Eigen::Vector2d> in;
  for (const auto& p : points) {
    if (std::abs(n.dot(p - best.point)) <= band_m) in.push_back(p);
  }
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : in) mean += p;
  mean /= static_cast<double>(in.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const auto& p : in) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
  best.point = mean;
  best.direction = eig.eigenvectors().col(1);
  best.rms_m = std::sqrt(eig.eigenvalues()(0) / static_cast<double>(in.size()));
  best.inlier_fraction = static_cast<double>(in.size()) / static_cast<double>(points.size());
  return best;
}

// `sonarbench map` takes the real log's folder as well as the file: a directory that is not a
// dataset and holds one .mat log means that log; two are refused, naming both.
TEST(RealLogMap, FolderHoldingOneLogMeansThatLog) {
  REQUIRE_REAL_LOG();
  const std::filesystem::path log(RealLogPath());
  EXPECT_EQ(std::filesystem::path(sim::MatLogInDirectory(log.parent_path().string())), log);
  EXPECT_EQ(sim::MatLogInDirectory(log.string()), "");  // a file is read as it is
  test::TempDir dir;
  EXPECT_EQ(sim::MatLogInDirectory(dir.path().string()), "");  // left to the dataset reader
  std::filesystem::create_symlink(log, dir.path() / "a.mat");
  EXPECT_EQ(sim::MatLogInDirectory(dir.path().string()), (dir.path() / "a.mat").string());
  std::filesystem::create_symlink(log, dir.path() / "b.mat");
  try {
    (void)sim::MatLogInDirectory(dir.path().string());
    ADD_FAILURE() << "two logs accepted";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("2 .mat logs"), std::string::npos) << message;
    EXPECT_NE(message.find("b.mat"), std::string::npos) << message;
  }
  std::ofstream(dir.path() / "manifest.json") << "{}";
  EXPECT_EQ(sim::MatLogInDirectory(dir.path().string()), "");  // a dataset stays a dataset
}

// `sonarbench map`'s files are the same bytes on any number of threads: on two, the map's files
// and images and the first sweep's images are written side by side.
TEST(RealLogMap, OutputsAreTheSameOnOneThreadAsOnTwo) {
  REQUIRE_REAL_LOG();
  test::TempDir dir;
  for (const int threads : {1, 2}) {
    mapping::MapperConfig config;
    config.threads = threads;
    const sim::LogMapResult result = sim::MapLog(RealLogPath(), mapping::SensorGeometry{}, config);
    sim::WriteLogMapOutputs((dir.path() / std::to_string(threads)).string(), result, nullptr);
  }
  for (const char* file : {"map.bt", "map.ot", "map_top.png", "polar.png", "fan.png"}) {
    const std::string one = test::ReadFile(dir.path() / "1" / file);
    EXPECT_GT(one.size(), 1000u) << file;
    EXPECT_EQ(one, test::ReadFile(dir.path() / "2" / file)) << file;
  }
}

// The real tank through `sonarbench map`'s defaults: its walls must come out straight and the
// square closed. Wall candidates are the occupied cells at the sonar's height (|z| ≤ one cell)
// beyond 1.6 m (inside lie the floor ring and the vehicle's own echoes), binned by 1° of bearing.
// `import LOG --out DIR; map DIR --scene S --score` and `map LOG --scene S --score` map the same
// beams from the same pose (the scene's static sonar): the same metrics, field for field.
TEST(RealLogMap, AnImportedLogScoresAsTheMatLogDoes) {
  REQUIRE_REAL_LOG();
  test::TempDir dir;
  const sim::Scene scene = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  const std::string imported = (dir.path() / "imported").string();
  (void)sim::ImportLogDataset(RealLogPath(), sim::ImportedMatLog(io::ReadMatLog(RealLogPath())),
                              mapping::SensorGeometry{}, imported, false);
  const sim::LogMapResult from_mat =
      sim::MapLog(RealLogPath(), scene.sensor.geometry, scene.mapping, &scene);
  const sim::LogMapResult from_dataset =
      sim::MapLog(imported, scene.sensor.geometry, scene.mapping, &scene);
  const nlohmann::json a = sim::MetricsJson(sim::ScoreLogMap(from_mat, scene).metrics);
  const nlohmann::json b = sim::MetricsJson(sim::ScoreLogMap(from_dataset, scene).metrics);
  EXPECT_GT(a["counts"]["true_positive_cells"].get<std::size_t>(), 100u);
  EXPECT_EQ(a, b);
  // The ghosts' split is reported, its parts summing to the whole.
  EXPECT_NEAR(a["ghost_arc_share"].get<double>() + a["ghost_echo_share"].get<double>(),
              a["ghost_share"].get<double>(), 1e-12);
  EXPECT_GT(a["ghost_echo_share"].get<double>(), 0.0);
  // A dataset simulated from one scene is not scored against another.
  const sim::Scene harbour = sim::LoadScene(test::SourcePath("scenes/harbour-wall.yaml"));
  sim::Scene one_sweep = scene;
  one_sweep.sweeps = 1;
  const std::string simulated = (dir.path() / "simulated").string();
  (void)sim::SimulateDataset(one_sweep, simulated, {});
  const std::string error = test::InputErrorOf(
      [&] { (void)sim::MapLog(simulated, harbour.sensor.geometry, harbour.mapping, &harbour); });
  EXPECT_NE(error.find("a dataset of scene 'cras-tank' (manifest.json); it cannot be scored "
                       "against scene 'harbour-wall'"),
            std::string::npos)
      << error;
}

TEST(RealLogMap, TankWallsAreStraightAndClosed) {
  REQUIRE_REAL_LOG();
  const auto result =
      sim::MapLog(RealLogPath(), mapping::SensorGeometry{}, mapping::MapperConfig{});
  const auto& tree = result.mapper->tree();
  const double res = tree.getResolution();
  const sim::MapCells cells = sim::CollectMapCells(tree);
  std::vector<std::vector<Eigen::Vector2d>> by_bearing(360);
  for (const auto& key : cells.occupied) {
    const auto c = tree.keyToCoord(key);
    const double range = std::hypot(c.x(), c.y());
    if (std::abs(c.z()) > res || range < 1.6 || range > 3.6) continue;  // 3.6 m: the far corner
    const int bearing =
        static_cast<int>(std::floor(std::atan2(c.y(), c.x()) / kDegToRad + 360.0)) % 360;
    by_bearing[static_cast<std::size_t>(bearing)].emplace_back(c.x(), c.y());
  }
  // Each side from the bearings within ±30° of its normal (the corners lie 37°-52° off the axes
  // in this log, whose walls face the head's 0°, 90°, 180° and 270°): a RANSAC line within 20° of
  // that orientation and a ±2-cell band, refined by total least squares over its inliers.
  // Straight: inlier RMS under 1.5 cells (a cell's own quantisation is 0.29 cells RMS, the
  // leading edge's scatter over the smoothing window about as much again, and an object standing
  // within the ±2-cell band adds to it). Closed: at least 80% of the sector's bearings hold a cell
  // on the line (the corners' oblique, weak echoes may fall under the threshold).
  std::vector<LineFit> sides;
  for (int axis = 0; axis < 360; axis += 90) {
    std::vector<Eigen::Vector2d> points;
    for (int b = axis - 30; b <= axis + 30; ++b) {
      const auto& at = by_bearing[static_cast<std::size_t>((b + 360) % 360)];
      points.insert(points.end(), at.begin(), at.end());
    }
    ASSERT_GE(points.size(), 61u) << "side at " << axis << "°";
    const Eigen::Vector2d normal(std::cos(axis * kDegToRad), std::sin(axis * kDegToRad));
    const LineFit fit = FitWall(points, 2 * res, normal, 20.0 * kDegToRad);
    const Eigen::Vector2d n(-fit.direction.y(), fit.direction.x());
    int supported = 0;
    for (int b = axis - 30; b <= axis + 30; ++b) {
      bool on_line = false;
      for (const auto& p : by_bearing[static_cast<std::size_t>((b + 360) % 360)]) {
        on_line |= std::abs(n.dot(p - fit.point)) <= 2 * res;
      }
      supported += on_line ? 1 : 0;
    }
    std::printf("side %3d°: %d of 61 bearings on the line, RMS %.3f m, %.2f m from the sonar\n",
                axis, supported, fit.rms_m, std::abs(n.dot(fit.point)));
    EXPECT_LE(fit.rms_m, 1.5 * res) << "side at " << axis << "°";
    EXPECT_GE(supported, 49) << "side at " << axis << "°";
    sides.push_back(fit);
  }
  // A square. Each side's direction is known to atan(2 cells / its 2.3 m span) ≈ 2.5°, so
  // neighbours are perpendicular within 5°. Opposite sides: ≈ 4.4 m (the data's README; the
  // strongest echoes here put them 4.44 m and 4.55 m apart), less up to 2 × 8 cm because the
  // mapper marks an echo's leading edge (two smoothing bins early, and the beam's nearest point,
  // up to 3 cm nearer than its axis at 30° incidence, plus half a cell): 4.4 ± 0.25 m.
  for (std::size_t s = 0; s < 4; ++s) {
    const double dot = std::abs(sides[s].direction.dot(sides[(s + 1) % 4].direction));
    std::printf("sides %zu-%zu: %.1f° from perpendicular\n", s, (s + 1) % 4,
                std::asin(dot) / kDegToRad);
    EXPECT_LE(dot, std::sin(5.0 * kDegToRad)) << "sides " << s << " and " << (s + 1) % 4;
  }
  for (std::size_t s = 0; s < 2; ++s) {
    const Eigen::Vector2d n(-sides[s].direction.y(), sides[s].direction.x());
    const double width = std::abs(n.dot(sides[s + 2].point - sides[s].point));
    std::printf("width across sides %zu-%zu: %.2f m\n", s, s + 2, width);
    EXPECT_NEAR(width, 4.4, 0.25);
  }
}

}  // namespace
}  // namespace sonarbench
