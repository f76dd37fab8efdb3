#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_util.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

using test::ReadFile;
using test::RunCli;

// A ROS 2 bag carries a dataset whole: the real log, imported, exported as a bag and imported
// again, maps and scores against the tank to the same bytes; so does a simulated dataset whose
// sonar moves (its poses from /tf and /tf_static), whose bag also carries the true pose.
TEST(Cli, ADatasetThroughARos2BagMapsToTheSameBytes) {
  REQUIRE_REAL_LOG();
  test::TempDir dir;
  const auto path = [&](const char* name) { return (dir.path() / name).string(); };
  std::string output;
  ASSERT_EQ(RunCli("import " + test::RealLogPath() + " --out " + path("ds"), &output), 0) << output;
  ASSERT_EQ(RunCli("export " + path("ds") + " --out " + path("real.mcap"), &output), 0) << output;
  EXPECT_NE(output.find("5604 beams on /sonar/image, /tf, /tf_static\n"), std::string::npos)
      << output;
  ASSERT_EQ(RunCli("import " + path("real.mcap") + " --out " + path("ds2"), &output), 0) << output;
  const std::string tank = test::SourcePath("scenes/cras-tank.yaml");
  for (const char* ds : {"ds", "ds2"}) {
    // Scored: 0 or 1, as the simulated tank's criteria judge the real log.
    const int status = RunCli(
        "map " + path(ds) + " --scene " + tank + " --score --out " + path(ds) + "-scored", &output);
    ASSERT_TRUE(status == 0 || status == 1) << output;
  }
  EXPECT_EQ(ReadFile(path("ds-scored/map.bt")), ReadFile(path("ds2-scored/map.bt")));
  const auto log = nlohmann::json::parse(ReadFile(path("ds2/manifest.json")))["log"];
  EXPECT_EQ(log["format"], "mcap");
  EXPECT_EQ(log["poses"], "tf, static");
  EXPECT_EQ(log["truncated_beams"], 1);

  const std::string harbour = test::SourcePath("scenes/harbour-wall.yaml");
  ASSERT_EQ(RunCli("simulate " + harbour + " --out " + path("sim"), &output), 0) << output;
  ASSERT_EQ(RunCli("export " + path("sim") + " --out " + path("sim.mcap"), &output), 0) << output;
  EXPECT_NE(output.find("/ground_truth/pose"), std::string::npos) << output;
  ASSERT_EQ(RunCli("import " + path("sim.mcap") + " --out " + path("sim2"), &output), 0) << output;
  EXPECT_EQ(ReadFile(path("sim/poses/sonar.tum")), ReadFile(path("sim2/poses/sonar.tum")));
  for (const char* ds : {"sim", "sim2"}) {
    ASSERT_EQ(RunCli("map " + path(ds) + " --out " + path(ds) + "-map", &output), 0) << output;
  }
  EXPECT_EQ(ReadFile(path("sim-map/map.bt")), ReadFile(path("sim2-map/map.bt")));
  EXPECT_EQ(nlohmann::json::parse(ReadFile(path("sim2/manifest.json")))["log"]["poses"],
            "tf, moving");
}

// export writes over a bag only with --force and only a bag sonarbench wrote; a damaged bag is
// refused naming it, and nothing is written.
TEST(Cli, ExportAndImportOfBagsKeepTheUsersFiles) {
  test::TempDir dir;
  const auto path = [&](const char* name) { return (dir.path() / name).string(); };
  std::string output;
  ASSERT_EQ(RunCli("simulate " + test::SourcePath("scenes/template.yaml") + " --out " + path("ds"),
                   &output),
            0)
      << output;
  const std::string mine = test::WriteFile(dir, "mine.mcap", "a user's notes\n");
  EXPECT_EQ(RunCli("export " + path("ds") + " --out " + mine + " --force", &output), 2);
  EXPECT_NE(output.find(mine + ": exists and is not an MCAP file sonarbench wrote"),
            std::string::npos)
      << output;
  EXPECT_EQ(ReadFile(mine), "a user's notes\n");
  ASSERT_EQ(RunCli("export " + path("ds") + " --out " + path("bag.mcap"), &output), 0) << output;
  EXPECT_EQ(RunCli("export " + path("ds") + " --out " + path("bag.mcap"), &output), 2);
  EXPECT_NE(output.find("pass --force"), std::string::npos) << output;
  EXPECT_EQ(RunCli("export " + path("ds") + " --out " + path("bag.mcap") + " --force", &output), 0)
      << output;

  const std::string bag = ReadFile(path("bag.mcap"));
  const std::string cut = test::WriteFile(dir, "cut.mcap", bag.substr(0, bag.size() / 3));
  EXPECT_EQ(RunCli("import " + cut + " --out " + path("out"), &output), 2);
  EXPECT_NE(output.find(cut + ": byte "), std::string::npos) << output;
  EXPECT_FALSE(std::filesystem::exists(path("out")));
  EXPECT_EQ(RunCli("import " + test::SourcePath("data/cras-tank-static/dataset_static.mat") +
                       " --topic /sonar --out " + path("out"),
                   &output),
            2);
  EXPECT_NE(output.find("--topic and --static apply to ROS 2 bags"), std::string::npos) << output;
  EXPECT_FALSE(std::filesystem::exists(path("out")));
}

}  // namespace
}  // namespace sonarbench::sim
