#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
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
  ASSERT_EQ(items.size(), 21u);  // 5 thresholds, Canny, automatic Canny; 3 echo rules each
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
  EXPECT_EQ(items.back().detection.method, Detection::Method::kAutoCanny);
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
}

}  // namespace
}  // namespace sonarbench::sim
