#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_util.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

using test::RunCli;

// `fidelity` takes a dataset directory as its log, as `map` does, and with --maps compares the
// maps of two settings over the whole sweep and each half: a dataset simulated from the scene
// itself agrees exactly (Spearman 1, no difference), so the verdict says the scene predicts it,
// in report.html first, in fidelity.json, maps.csv and on the terminal.
TEST(FidelityCli, ADatasetOfTheSceneItselfPredictsItsMapsExactly) {
  test::TempDir dir;
  const std::string scene = test::WriteFile(
      dir, "tank.yaml",
      "name: cras-tank\nextends: " + test::SourcePath("scenes/cras-tank.yaml") + "\nsweeps: 1\n");
  const auto dataset = dir.path() / "dataset";
  const auto out = dir.path() / "fidelity";
  std::string output;
  ASSERT_EQ(RunCli("simulate " + scene + " --out " + dataset.string(), &output), 0) << output;
  ASSERT_EQ(
      RunCli("fidelity " + scene + " " + dataset.string() + " --maps 6,8 --out " + out.string(),
             &output),
      0)
      << output;
  EXPECT_NE(output.find("The simulated scene predicts the log's maps"), std::string::npos)
      << output;
  EXPECT_LT(std::count(output.begin(), output.end(), '\n'), 16) << output;
  const auto report = nlohmann::json::parse(test::ReadFile(out / "fidelity.json"));
  const auto& maps = report.at("maps");
  ASSERT_EQ(maps.at("parts").size(), 3u);
  EXPECT_EQ(maps.at("parts")[1].at("heads_deg"), nlohmann::json::array({0.0, 180.0}));
  EXPECT_EQ(maps.at("settings").size(), 2u);
  for (const auto& part : maps.at("parts")) {
    for (const auto& [figure, f] : part.at("agreement").at("figures").items()) {
      EXPECT_DOUBLE_EQ(f.at("spearman").get<double>(), 1.0) << figure;
      EXPECT_EQ(f.at("max_abs_difference").get<double>(), 0.0) << figure;
    }
  }
  EXPECT_TRUE(maps.at("meets").get<bool>());
  const std::string html = test::ReadFile(out / "report.html");
  const auto verdict = html.find("class=\"verdict pass\"");
  ASSERT_NE(verdict, std::string::npos);
  EXPECT_LT(verdict, html.find("<h2>"));
  const std::string csv = test::ReadFile(out / "maps.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 3 * 2);  // header, 3 parts × 2
}

// --maps names all, none, or two or more of the study's 21 settings; anything else is refused
// before any work, naming the option.
TEST(FidelityCli, MapsNamesTheStudysSettings) {
  const std::string scene = test::SourcePath("scenes/cras-tank.yaml");
  for (const std::string maps : {"21", "6", "6,x", "", "some"}) {
    std::string output;
    EXPECT_EQ(RunCli("fidelity " + scene + " " + test::RealLogPath() + " --maps '" + maps +
                         "' --out /nonexistent-sonarbench-dir/x",
                     &output),
              2)
        << maps;
    EXPECT_NE(output.find("--maps"), std::string::npos) << output;
  }
}

// detectors --heads takes FROM < TO within 0-360 degrees.
TEST(FidelityCli, DetectorsHeadsIsAnIntervalOfHeadAngles) {
  const std::string scene = test::SourcePath("scenes/cras-tank.yaml");
  for (const std::string heads : {"180 90", "-10 90", "0 400", "90 90"}) {
    std::string output;
    EXPECT_EQ(RunCli("detectors " + scene + " --heads " + heads, &output), 2) << heads;
    EXPECT_NE(output.find("--heads"), std::string::npos) << output;
  }
}

// --seeds judges the log against the scene's own runs: each figure of each part at the scene's
// mapping, with the runs, the bound and how far outside, in fidelity.json, spread.csv, report.html
// (a strip per figure) and on the terminal. A scene 20 dB louder than the one that made the log
// hears far more of the tank: its runs leave the log outside on recall, named with its part.
TEST(FidelityCli, SeedsJudgeTheLogAgainstTheScenesOwnSpread) {
  test::TempDir dir;
  const std::string base =
      "extends: " + test::SourcePath("scenes/cras-tank.yaml") + "\nsweeps: 1\n";
  const std::string scene = test::WriteFile(dir, "tank.yaml", "name: cras-tank\n" + base);
  const std::string louder = test::WriteFile(
      dir, "louder.yaml", "name: cras-tank\n" + base + "sonar_acoustics:\n  gain_db: 26.0\n");
  const auto dataset = dir.path() / "dataset";
  const auto out = dir.path() / "fidelity";
  std::string output;
  ASSERT_EQ(RunCli("simulate " + scene + " --seed 99 --out " + dataset.string(), &output), 0)
      << output;
  ASSERT_EQ(RunCli("fidelity " + louder + " " + dataset.string() +
                       " --seeds 4 --maps none --no-progress --out " + out.string(),
                   &output),
            0)
      << output;
  EXPECT_NE(output.find("The log lies outside the simulator's own spread (4 seeds, 15 judgements"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("outside: recall_1 (all head angles) at the scene's mapping"),
            std::string::npos)
      << output;
  const auto report = nlohmann::json::parse(test::ReadFile(out / "fidelity.json"));
  const auto& spread = report.at("spread");
  EXPECT_EQ(spread.at("seeds"), nlohmann::json::array({1, 2, 3, 4}));
  EXPECT_FALSE(spread.at("within").get<bool>());
  EXPECT_LE(spread.at("size").at("seeds_within").get<int>(), 4);
  ASSERT_EQ(spread.at("parts").size(), 3u);
  const auto& recall = spread.at("parts")[0].at("figures").at("recall_1").at("scene_mapping");
  EXPECT_EQ(recall.at("runs").size(), 4u);
  EXPECT_EQ(recall.at("left_out").size(), 4u);
  EXPECT_FALSE(recall.at("within").get<bool>());
  EXPECT_NEAR(recall.at("excess").get<double>(),
              std::abs(recall.at("statistic").get<double>()) - recall.at("bound").get<double>(),
              1e-12);
  const std::string csv = test::ReadFile(out / "spread.csv");
  EXPECT_EQ(csv.rfind("part,figure,judgement,statistic,bound,excess,within\n", 0), 0u);
  const std::string html = test::ReadFile(out / "report.html");
  EXPECT_NE(html.find("class=\"verdict fail\">The log lies outside"), std::string::npos);
  EXPECT_NE(html.find("<svg"), std::string::npos);
  // Fewer than four seeds leave too few runs to judge a run left out: refused, naming --seeds.
  EXPECT_EQ(RunCli("fidelity " + scene + " " + dataset.string() + " --seeds 3 --out " +
                       (dir.path() / "three").string(),
                   &output),
            2);
  EXPECT_NE(output.find("--seeds"), std::string::npos) << output;
}

}  // namespace
}  // namespace sonarbench
