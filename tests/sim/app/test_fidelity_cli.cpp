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

}  // namespace
}  // namespace sonarbench
