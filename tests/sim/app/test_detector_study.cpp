#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <numeric>
#include <set>

#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/app/detector_study.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

using Detection = mapping::DetectionConfig;

TEST(DetectorStudy, ItemsAreEachDetectorWithEachEchoRule) {
  Detection base;
  base.smoothing_bins = 7;
  const std::vector<DetectorItem> items = DetectorStudyItems(base);
  // 5 thresholds, Canny, automatic Canny, CA- and OS-CFAR; 3 echo rules each; echoes behind
  // walls kept, then refused.
  ASSERT_EQ(items.size(), 54u);
  std::set<std::string> names;
  for (const DetectorItem& item : items) {
    names.insert(item.name);
    EXPECT_EQ(item.detection.smoothing_bins, 7) << item.name;
    EXPECT_TRUE(item.detection.max_obstacles == 1 || (item.detection.max_obstacles == 2))
        << item.name;
  }
  EXPECT_EQ(names.size(), items.size());
  EXPECT_EQ(items[6].name, "threshold 110, first echo");
  EXPECT_EQ(items[8].detection.later_echoes, Detection::LaterEchoes::kSupported);
  EXPECT_EQ(items[20].detection.method, Detection::Method::kAutoCanny);
  EXPECT_EQ(items[26].detection.method, Detection::Method::kOsCfar);
  for (std::size_t i = 0; i < 27; ++i) {
    EXPECT_EQ(items[i].detection.behind_walls, Detection::BehindWalls::kKeep) << items[i].name;
    const Detection& refused = items[i + 27].detection;
    EXPECT_EQ(refused.behind_walls, Detection::BehindWalls::kRefuse) << items[i + 27].name;
    Detection same = refused;
    same.behind_walls = Detection::BehindWalls::kKeep;
    EXPECT_EQ(same, items[i].detection) << items[i + 27].name;
  }
  EXPECT_EQ(items[33].name, "threshold 110, first echo, nothing behind walls");
}

// A dataset simulated from the scene, given as the log, is mapped and scored as the scene itself:
// the log's rows are the scene's. And the echo rules order as they must on the tank: supported
// later echoes keep the two echoes' recall with fewer ghosts.
TEST(DetectorStudy, ADatasetOfTheSceneScoresAsTheScene) {
  test::TempDir dir;
  Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  scene.sweeps = 2;
  const auto dataset = dir.path() / "dataset";
  (void)SimulateDataset(scene, dataset.string(), DatasetOptions{});
  DetectorStudyOptions options;
  options.log = dataset.string();
  const std::vector<DetectorItem> all = DetectorStudyItems(scene.mapping.detection);
  options.items = {all[7], all[8]};  // threshold 110, two echoes: strongest, supported
  const std::vector<DetectorRow> rows = RunDetectorStudy(scene, options);
  ASSERT_EQ(rows.size(), 2u);
  for (const DetectorRow& row : rows) {
    ASSERT_TRUE(row.log.has_value());
    EXPECT_EQ(row.log->occupied_cells, row.scene.occupied_cells) << row.item.name;
    EXPECT_EQ(row.log->true_positive_cells, row.scene.true_positive_cells) << row.item.name;
    EXPECT_DOUBLE_EQ(row.log->recall_within[1], row.scene.recall_within[1]) << row.item.name;
    EXPECT_DOUBLE_EQ(row.log->ghost_share, row.scene.ghost_share) << row.item.name;
    // The ghosts split the same way from the dataset's poses, the two parts making the whole.
    ASSERT_TRUE(row.scene.ghost_arc_share && row.scene.ghost_echo_share &&
                row.log->ghost_arc_share);
    EXPECT_DOUBLE_EQ(*row.log->ghost_arc_share, *row.scene.ghost_arc_share) << row.item.name;
    EXPECT_NEAR(*row.scene.ghost_arc_share + *row.scene.ghost_echo_share, row.scene.ghost_share,
                1e-12);
  }
  EXPECT_LT(rows[1].scene.ghost_share, rows[0].scene.ghost_share);
  // What `supported` drops are the detector's ghosts, not the arc's.
  EXPECT_LT(*rows[1].scene.ghost_echo_share, *rows[0].scene.ghost_echo_share);
  EXPECT_LT(rows[1].scene.occupied_cells, rows[0].scene.occupied_cells);
  // By the simulator's truth: the rules differ in later echoes only; the tank's later echoes
  // are mostly mirror paths behind its walls, and `supported` drops a larger share of those
  // than of the direct ones.
  const auto count = [](const DetectorRow& row, bool later, EchoPath path) {
    return static_cast<double>(
        (later ? row.scene_paths.later : row.scene_paths.first)[static_cast<std::size_t>(path)]);
  };
  EXPECT_EQ(rows[0].scene_paths.first, rows[1].scene_paths.first);
  const std::size_t firsts = std::accumulate(rows[0].scene_paths.first.begin(),
                                             rows[0].scene_paths.first.end(), std::size_t{0});
  EXPECT_GT(firsts, 0u);
  EXPECT_LE(firsts, 2u * 200u);  // one first echo a beam at most
  const double multipath = count(rows[0], true, EchoPath::kMultipath);
  const double direct = count(rows[0], true, EchoPath::kDirect);
  EXPECT_GT(multipath, direct);
  const double multipath_dropped = 1.0 - count(rows[1], true, EchoPath::kMultipath) / multipath;
  const double direct_dropped =
      1.0 - count(rows[1], true, EchoPath::kDirect) / std::max(direct, 1.0);
  EXPECT_GT(multipath_dropped, direct_dropped);

  const auto out = dir.path() / "study";
  std::filesystem::create_directories(out);
  WriteDetectorStudy(out.string(), scene, options, rows);
  std::ifstream csv(out / "detectors.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find("log_ghost_share"), std::string::npos);
  EXPECT_NE(header.find("scene_ghost_arc_share,scene_ghost_echo_share"), std::string::npos);
  std::size_t lines = 0;
  for (std::string line; std::getline(csv, line);) ++lines;
  EXPECT_EQ(lines, 2u);
  EXPECT_TRUE(std::filesystem::exists(out / "precision_vs_recall_scene.png"));
  EXPECT_TRUE(std::filesystem::exists(out / "precision_vs_recall_log.png"));
  std::ifstream in(out / "study.json");
  const auto study = nlohmann::json::parse(in);
  EXPECT_EQ(study["items"][1]["later_echoes"], "supported");
  EXPECT_DOUBLE_EQ(study["items"][1]["scene"]["ghost_share"].get<double>(),
                   rows[1].scene.ghost_share);
  EXPECT_EQ(study["items"][0]["scene_echo_paths"]["later"]["multipath"].get<double>(), multipath);
}

// Spearman's rank correlation against cases worked by hand: the same order 1, the reverse -1,
// a tie taking the average of its ranks (ranks 0, 1.5, 1.5, 3 against 0, 1, 2, 3: 0.9487), a
// constant column none.
TEST(DetectorStudy, SpearmanRanksAsWorkedByHand) {
  EXPECT_DOUBLE_EQ(Spearman({0.1, 0.5, 0.3}, {1.0, 9.0, 4.0}), 1.0);
  EXPECT_DOUBLE_EQ(Spearman({0.1, 0.5, 0.3}, {9.0, 1.0, 4.0}), -1.0);
  EXPECT_NEAR(Spearman({1.0, 2.0, 2.0, 3.0}, {1.0, 2.0, 3.0, 4.0}), 3.0 / std::sqrt(10.0), 1e-12);
  EXPECT_TRUE(std::isnan(Spearman({1.0, 1.0, 1.0}, {1.0, 2.0, 3.0})));
}

// The agreement of three settings whose log differs from the scene by 0.02 in every figure but
// one, off by 0.1: that figure misses the goal on its largest difference; its ranks still agree.
TEST(DetectorStudy, AgreementMeetsTheGoalsOnlyWithinThem) {
  std::vector<DetectorRow> rows;
  for (int i = 0; i < 3; ++i) {
    MapMetrics scene;
    scene.precision_within = {0.0, 0.2 + 0.2 * i, 0.0};
    scene.recall_within = {0.0, 0.3 + 0.1 * i, 0.0};
    scene.f1_within = {0.0, 0.25 + 0.1 * i, 0.0};
    scene.ghost_arc_share = 0.1 * i;
    scene.ghost_echo_share = 0.5 - 0.1 * i;
    MapMetrics log = scene;
    log.precision_within[1] += 0.02;
    log.recall_within[1] += i == 2 ? 0.1 : 0.02;
    log.f1_within[1] += 0.02;
    *log.ghost_arc_share += 0.02;
    *log.ghost_echo_share -= 0.02;
    DetectorRow row;
    row.item.name = "setting " + std::to_string(i);
    row.scene = scene;
    row.log = log;
    rows.push_back(std::move(row));
  }
  const nlohmann::json a = AgreementJson(rows);
  EXPECT_TRUE(a["figures"]["precision_1"]["meets"].get<bool>());
  EXPECT_NEAR(a["figures"]["precision_1"]["mean_abs_difference"].get<double>(), 0.02, 1e-12);
  EXPECT_FALSE(a["figures"]["recall_1"]["meets"].get<bool>());
  EXPECT_NEAR(a["figures"]["recall_1"]["max_abs_difference"].get<double>(), 0.1, 1e-12);
  EXPECT_DOUBLE_EQ(a["figures"]["recall_1"]["spearman"].get<double>(), 1.0);
  EXPECT_EQ(a["best_f1_1"]["scene"], "setting 2");
  EXPECT_TRUE(a["best_f1_1"]["same"].get<bool>());
  EXPECT_FALSE(a["meets"].get<bool>());
  rows[2].log->recall_within[1] -= 0.08;  // back within the goals
  EXPECT_TRUE(AgreementJson(rows)["meets"].get<bool>());
}

// A head angle belongs to [from, to) degrees taken modulo 360: -10° is 350°, 360° is 0°.
TEST(DetectorStudy, HeadsAreHalfOpenAndWrapAround) {
  const auto rad = [](double deg) { return deg * std::numbers::pi / 180.0; };
  const std::pair<double, double> first{0.0, 180.0}, second{180.0, 360.0};
  EXPECT_TRUE(InHeads(rad(0.0), first));
  EXPECT_TRUE(InHeads(rad(179.9), first));
  EXPECT_FALSE(InHeads(rad(180.0), first));
  EXPECT_TRUE(InHeads(rad(180.0), second));
  EXPECT_TRUE(InHeads(rad(-10.0), second));
  EXPECT_TRUE(InHeads(rad(360.0), first));
  EXPECT_TRUE(InHeads(rad(725.0), first));
}

// One half of the sweep maps only its beams: the scene's first echoes at 110 then lie on that
// half's walls, none on the other's, and its dataset as the log still scores as the scene.
TEST(DetectorStudy, AHalfOfTheSweepMapsOnlyItsBeams) {
  test::TempDir dir;
  Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  scene.sweeps = 1;
  const auto dataset = dir.path() / "dataset";
  (void)SimulateDataset(scene, dataset.string(), DatasetOptions{});
  DetectorStudyOptions options;
  options.log = dataset.string();
  options.items = {DetectorStudyItems(scene.mapping.detection)[6]};  // threshold 110, first echo
  const MapMetrics whole = RunDetectorStudy(scene, options).front().scene;
  options.heads_deg = std::pair{0.0, 180.0};
  const DetectorRow half = RunDetectorStudy(scene, options).front();
  ASSERT_TRUE(half.log.has_value());
  EXPECT_EQ(half.log->occupied_cells, half.scene.occupied_cells);
  EXPECT_LT(half.scene.occupied_cells, whole.occupied_cells);
  EXPECT_GT(half.scene.occupied_cells, whole.occupied_cells / 4);
  EXPECT_LT(half.scene.observable_cells, whole.observable_cells);
}
}  // namespace
}  // namespace sonarbench::sim
