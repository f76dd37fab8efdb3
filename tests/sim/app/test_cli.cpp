#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <algorithm>
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

#include "cli_scenes.hpp"
#include "cli_util.hpp"
#include "sonarbench/sim/app/scenario.hpp"
#include "sonarbench/sim/report/report.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

using mapping::kDegToRad;

using test::ReadFile;
using test::RunCli;
using test::TankSceneWithCriteria;
using test::XmlLint;

TEST(Cli, MissedCriterionExitsOneAndSaysWhyEverywhere) {
  test::TempDir dir;
  const auto scene = TankSceneWithCriteria(
      dir.path(),
      "criteria:\n  metrics:\n    occupied_recall: {min: 0.99}\n    coverage: {min: 0.0}\n");
  const auto out = dir.path() / "out";
  std::string output;
  EXPECT_EQ(RunCli("run " + scene.string() + " --out " + out.string(), &output), 1);
  EXPECT_NE(output.find("FAIL cras-tank: 1/2 criteria met"), std::string::npos) << output;
  EXPECT_NE(output.find("occupied_recall = "), std::string::npos) << output;
  EXPECT_NE(output.find("expected >= 0.99"), std::string::npos) << output;

  const auto report = nlohmann::json::parse(ReadFile(out / "report.json"));
  EXPECT_EQ(report["schema_version"], kScenarioReportSchema);
  EXPECT_FALSE(report["verdict"]["passed"].get<bool>());
  const auto& recall = report["criteria"]["results"][0];
  EXPECT_EQ(recall["metric"], "occupied_recall");
  EXPECT_EQ(recall["status"], "fail");
  EXPECT_NEAR(recall["margin"].get<double>(), recall["actual"].get<double>() - 0.99, 1e-12);
  EXPECT_EQ(report["criteria"]["results"][1]["status"], "pass");

  const std::string junit = ReadFile(out / "junit.xml");
  EXPECT_NE(junit.find("tests=\"3\" failures=\"1\" errors=\"0\""), std::string::npos) << junit;
  EXPECT_NE(junit.find("<failure type=\"criterion\" message=\"occupied_recall = "),
            std::string::npos)
      << junit;
  EXPECT_NE(XmlLint(out / "junit.xml"), 1);  // 0 when well-formed, -1 without xmllint

  const std::string html = ReadFile(out / "report.html");
  EXPECT_NE(html.find("<title>sonarbench: cras-tank FAIL</title>"), std::string::npos);
  EXPECT_EQ(html.find("src=\"polar.png\""), std::string::npos) << "images must be embedded";
  std::size_t embedded = 0;
  for (auto at = html.find("data:image/png;base64,"); at != std::string::npos;
       at = html.find("data:image/png;base64,", at + 1))
    ++embedded;
  EXPECT_EQ(embedded, 4u);
}

TEST(Cli, ExpectFailPassesOnlyWhenACriterionFails) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  std::string output;
  const auto missing = TankSceneWithCriteria(
      dir.path(), "criteria:\n  expect: fail\n  metrics: {occupied_recall: {min: 0.99}}\n");
  EXPECT_EQ(RunCli("run " + missing.string() + " --out " + out.string(), &output), 0) << output;
  EXPECT_NE(output.find("PASS cras-tank"), std::string::npos) << output;
  EXPECT_NE(ReadFile(out / "junit.xml").find("failures=\"0\""), std::string::npos);

  const auto met = TankSceneWithCriteria(
      dir.path(), "criteria:\n  expect: fail\n  metrics: {occupied_recall: {min: 0.0}}\n");
  EXPECT_EQ(RunCli("run " + met.string() + " --out " + out.string(), &output), 1) << output;
  EXPECT_NE(output.find("expect: fail"), std::string::npos) << output;
  EXPECT_NE(ReadFile(out / "junit.xml").find("<failure type=\"expectation\""), std::string::npos);
}

TEST(Cli, BadSceneExitsTwoNamingTheKeyAndWritesOnlyAnErrorJunit) {
  test::TempDir dir;
  const auto scene = dir.path() / "bad.yaml";
  std::ofstream(scene) << "name: x\nsensor_model: "
                       << test::SourcePath("sensor-models/shad-micron.yaml")
                       << "\nsweeps: 1\nsweep: 2\nmaterials: [{name: a, reflectivity: 2}]\n"
                       << "meshes: [{name: m, type: plane, size_m: [1, 1, 0], material: a}]\n"
                       << "trajectory: {type: static, position_m: [0, 0, 0]}\n"
                       << "criteria: {metrics: {coverage: {min: 0.5}, coverage: {min: 0.6}}}\n";
  std::string output;
  const auto out = dir.path() / "out";
  EXPECT_EQ(RunCli("run " + scene.string() + " --out " + out.string(), &output), 2);
  EXPECT_NE(output.find("bad.yaml:4:1: key 'sweep': unknown key"), std::string::npos) << output;
  EXPECT_NE(output.find("'materials[0].reflectivity'"), std::string::npos) << output;
  EXPECT_NE(output.find("'criteria.metrics.coverage': duplicate key"), std::string::npos) << output;
  // The CI system still learns why: junit.xml holds one <error>, and no other output is written
  // (the directory's marker and lock are sonarbench's bookkeeping).
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    if (name != ".sonarbench-outputs.json" && name != ".sonarbench.lock") files.push_back(name);
  }
  EXPECT_EQ(files, std::vector<std::string>{"junit.xml"});
  const std::string junit = ReadFile(out / "junit.xml");
  EXPECT_NE(junit.find("<error type=\"input_error\" message=\""), std::string::npos) << junit;
  EXPECT_NE(junit.find(XmlEscape(scene.string()) + ":4:1: key &apos;sweep&apos;: unknown key"),
            std::string::npos)
      << junit;
  EXPECT_NE(XmlLint(out / "junit.xml"), 1);
}

TEST(Cli, BadMeshFilesExitTwoNamingSceneMeshAndFile) {
  test::TempDir dir;
  std::ofstream(dir.path() / "nan.obj") << "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n";
  // The file as a mesh of the scene's, or as a part of the vehicle's beside a plane bed.
  auto scene_with = [&](const std::string& file, bool as_vehicle_part = false) {
    const auto scene = dir.path() / "scene.yaml";
    const std::string from_file = std::string("{name: ") + (as_vehicle_part ? "fin" : "rock") +
                                  ", type: file, file: " + file + ", material: a}";
    std::ofstream(scene) << "name: x\nsensor_model: "
                         << test::SourcePath("sensor-models/shad-micron.yaml")
                         << "\nsweeps: 1\nmaterials: [{name: a, reflectivity: 0.5}]\n"
                         << (as_vehicle_part
                                 ? "meshes: [{name: bed, type: plane, size_m: [4, 4, 0], "
                                   "material: a}]\nvehicle: ["
                                 : "meshes: [")
                         << from_file << "]\n"
                         << "trajectory: {type: static, position_m: [0, 0, 1]}\n";
    return scene.string();
  };
  std::string output;
  EXPECT_EQ(
      RunCli("run " + scene_with("nan.obj") + " --out " + (dir.path() / "o").string(), &output), 2);
  EXPECT_NE(output.find("mesh 'rock' (" + (dir.path() / "nan.obj").string() +
                        "): vertex 2 is not finite"),
            std::string::npos)
      << output;
  EXPECT_EQ(
      RunCli("run " + scene_with("missing.stl") + " --out " + (dir.path() / "o").string(), &output),
      2);
  EXPECT_NE(output.find("scene.yaml:5:41: mesh 'rock': " + (dir.path() / "missing.stl").string() +
                        ": no such mesh file"),
            std::string::npos)
      << output;
  // A vehicle's part from a bad file is refused the same way.
  EXPECT_EQ(RunCli("run " + scene_with("nan.obj", true) + " --out " + (dir.path() / "v").string(),
                   &output),
            2);
  EXPECT_NE(
      output.find("mesh 'fin' (" + (dir.path() / "nan.obj").string() + "): vertex 2 is not finite"),
      std::string::npos)
      << output;
  // `simulate` and `sweep` refuse it before they make their directory (each once left a partial
  // dataset or study behind).
  for (const std::string command : {"simulate", "sweep"}) {
    const auto out = dir.path() / command;
    EXPECT_EQ(RunCli(command + " " + scene_with("nan.obj") + " --out " + out.string(), &output), 2);
    EXPECT_NE(output.find("vertex 2 is not finite"), std::string::npos) << output;
    EXPECT_FALSE(std::filesystem::exists(out)) << command;
  }
}

TEST(Cli, MessagesNameWhatToDoNext) {
  namespace fs = std::filesystem;
  test::TempDir dir;
  const auto scene = TankSceneWithCriteria(dir.path(), "");
  std::string output;
  EXPECT_EQ(
      RunCli("simulate " + scene.string() + " --outt " + (dir.path() / "d").string(), &output), 2);
  EXPECT_NE(output.find("sonarbench: error: simulate: "), std::string::npos) << output;
  EXPECT_NE(output.find("--outt is no option of simulate; did you mean --out?"), std::string::npos)
      << output;
  const auto ds = dir.path() / "ds";
  ASSERT_EQ(RunCli("simulate " + scene.string() + " --out " + ds.string(), &output), 0) << output;
  EXPECT_NE(output.find("wrote 1 sweep, skipped 0"), std::string::npos) << output;
  const auto bare = dir.path() / "bare";
  ASSERT_EQ(RunCli("simulate " + scene.string() + " --no-labels --out " + bare.string(), &output),
            0)
      << output;
  EXPECT_TRUE(fs::exists(ds / "truth/labels_0000.bin"));
  EXPECT_FALSE(fs::exists(bare / "truth/labels_0000.bin"));
  EXPECT_EQ(test::ReadFile(bare / "beams/sweep_0000.bin"),
            test::ReadFile(ds / "beams/sweep_0000.bin"));
  EXPECT_EQ(RunCli("simulate " + scene.string() + " --out " + bare.string(), &output), 2);
  EXPECT_NE(output.find("another configuration"), std::string::npos) << output;
  const auto mine = dir.path() / "mine.mcap";
  std::ofstream(mine) << "my notes";
  EXPECT_EQ(RunCli("export " + ds.string() + " --out " + mine.string(), &output), 2);
  EXPECT_NE(output.find("not an MCAP file sonarbench wrote; sonarbench never replaces it"),
            std::string::npos)
      << output;
  EXPECT_EQ(output.find("pass --force"), std::string::npos) << output;
  const auto bag = dir.path() / "ds.mcap";
  ASSERT_EQ(RunCli("export " + ds.string() + " --out " + bag.string(), &output), 0) << output;
  EXPECT_EQ(RunCli("export " + ds.string() + " --out " + bag.string(), &output), 2);
  EXPECT_NE(output.find("an MCAP file sonarbench wrote); pass --force"), std::string::npos)
      << output;
  EXPECT_EQ(RunCli("import " + bag.string() + " --topic /nope --out " + (dir.path() / "i").string(),
                   &output),
            2);
  EXPECT_NE(output.find("no topic named '/nope'; the bag's "
                        "marine_acoustic_msgs/msg/ProjectedSonarImage topics: /sonar/image"),
            std::string::npos)
      << output;
  const auto imported = dir.path() / "imported";
  ASSERT_EQ(RunCli("import " + test::RealLogPath() + " --out " + imported.string(), &output), 0);
  EXPECT_FALSE(fs::exists(imported / "truth"));  // an imported log has no truth
  const auto map = dir.path() / "map";
  ASSERT_EQ(RunCli("map " + imported.string() + " --out " + map.string(), &output), 0) << output;
  EXPECT_NE(output.find("detection: threshold 110, at most 2 echoes a beam (later echoes: "
                        "strongest), none behind a wall, arc_marking at 0.05 m "
                        "(from " +
                        test::SourcePath("sensor-models/shad-micron.yaml") + ")"),
            std::string::npos)
      << output;
  EXPECT_NE(ReadFile(map / "report.html").find("<td>detection.threshold</td><td>110</td>"),
            std::string::npos);
  // --mapping refines the model's defaults key by key.
  const auto mapping = dir.path() / "first.yaml";
  std::ofstream(mapping) << "detection: {max_obstacles: 1}\n";
  ASSERT_EQ(RunCli("map " + imported.string() + " --mapping " + mapping.string() + " --out " +
                       (dir.path() / "map2").string(),
                   &output),
            0)
      << output;
  EXPECT_NE(output.find("detection: threshold 110, the first echo a beam, none behind a wall, "
                        "arc_marking at 0.05 m (from " +
                        test::SourcePath("sensor-models/shad-micron.yaml") + " and " +
                        mapping.string() + ")"),
            std::string::npos)
      << output;
}

TEST(Cli, NeverReplacesOrRemovesWhatItDidNotWrite) {
  namespace fs = std::filesystem;
  test::TempDir dir;
  const auto scene = TankSceneWithCriteria(dir.path(), "");
  std::string output;
  const auto project = dir.path() / "project";
  fs::create_directories(project / "src");
  std::ofstream(project / "manifest.json") << R"({"name": "webapp"})";
  std::ofstream(project / "src/main.c") << "int main;";
  EXPECT_EQ(
      RunCli("simulate " + scene.string() + " --out " + project.string() + " --force", &output), 2);
  EXPECT_NE(output.find("holds files sonarbench did not write: manifest.json"), std::string::npos)
      << output;
  EXPECT_EQ(ReadFile(project / "src/main.c"), "int main;");
  EXPECT_EQ(ReadFile(project / "manifest.json"), R"({"name": "webapp"})");

  // The log's own folder: a manifest.json of the user's is refused; without one the dataset goes
  // beside the log, which --force never removes.
  const auto logs = dir.path() / "logs";
  fs::create_directories(logs);
  fs::copy_file(test::SourcePath("data/cras-tank-static/dataset_static.mat"), logs / "LOG.mat");
  std::ofstream(logs / "manifest.json") << "{}";
  const std::string import = "import " + (logs / "LOG.mat").string() + " --out " + logs.string();
  EXPECT_EQ(RunCli(import + " --force", &output), 2);
  EXPECT_NE(output.find("did not write: manifest.json"), std::string::npos) << output;
  fs::remove(logs / "manifest.json");
  EXPECT_EQ(RunCli(import, &output), 0) << output;
  EXPECT_EQ(RunCli(import + " --force", &output), 0) << output;
  EXPECT_EQ(fs::file_size(logs / "LOG.mat"),
            fs::file_size(test::SourcePath("data/cras-tank-static/dataset_static.mat")));

  // run and map refuse to overwrite a report, junit.xml or map the user wrote.
  const auto results = dir.path() / "results";
  fs::create_directories(results);
  std::ofstream(results / "junit.xml") << "mine";
  EXPECT_EQ(RunCli("run " + scene.string() + " --out " + results.string(), &output), 2);
  EXPECT_NE(output.find("did not write: junit.xml"), std::string::npos) << output;
  EXPECT_EQ(RunCli("map " + logs.string() + " --out " + results.string(), &output), 2);
  EXPECT_NE(output.find("did not write: junit.xml"), std::string::npos) << output;
  fs::rename(results / "junit.xml", results / "notes.txt");
  EXPECT_EQ(RunCli("map " + logs.string() + " --out " + results.string(), &output), 0) << output;
  fs::remove(results / "map.bt");
  std::ofstream(results / "map.bt") << "my map";
  // map.bt is listed as sonarbench's, so the user's copy under that name is replaced; notes.txt,
  // which map never claimed, stays.
  EXPECT_EQ(RunCli("map " + logs.string() + " --out " + results.string(), &output), 0) << output;
  EXPECT_EQ(ReadFile(results / "notes.txt"), "mine");

  // A symlinked --out is followed.
  fs::create_directories(dir.path() / "real");
  fs::create_directory_symlink(dir.path() / "real", dir.path() / "link");
  EXPECT_EQ(RunCli("run " + scene.string() + " --out " + (dir.path() / "link").string(), &output),
            0)
      << output;
  EXPECT_TRUE(fs::is_symlink(dir.path() / "link"));
  EXPECT_TRUE(fs::exists(dir.path() / "real/report.json"));
}

// A dataset is scored only against the scene it was simulated from.
TEST(Cli, VersionAndUnknownCommands) {
  std::string output;
  EXPECT_EQ(RunCli("--version", &output), 0);
  EXPECT_EQ(output, "sonarbench " + std::string(kVersion) + "\n");
  EXPECT_EQ(RunCli("frobnicate scenes", &output), 2);
  EXPECT_NE(output.find("unknown command 'frobnicate'; the commands are run, map, score, fidelity, "
                        "simulate, sweep, detectors, import, export"),
            std::string::npos)
      << output;
  EXPECT_EQ(RunCli("", &output), 2);
  EXPECT_NE(output.find("a command is required; the commands are run,"), std::string::npos)
      << output;
}

TEST(Cli, MissingSceneAndBadOptionsExitTwo) {
  std::string output;
  EXPECT_EQ(RunCli("run /nonexistent.yaml", &output), 2);
  EXPECT_NE(output.find("/nonexistent.yaml"), std::string::npos) << output;
  EXPECT_EQ(RunCli("run " + test::SourcePath("scenes/cras-tank.yaml") + " --threads -1"), 2);
  EXPECT_EQ(RunCli("frobnicate"), 2);
}

// A seed is a decimal integer from 0 to 2^64 - 1: "-1" and one past the top are refused, not
// wrapped or saturated.
TEST(Cli, SeedsOutsideTheirRangeExitTwo) {
  const std::string scene = test::SourcePath("scenes/cras-tank.yaml");
  for (const std::string seed : {"-1", "18446744073709551616", "12abc"}) {
    std::string output;
    EXPECT_EQ(RunCli("run " + scene + " --no-progress --seed " + seed, &output), 2) << seed;
    EXPECT_NE(output.find("--seed: expected an integer from 0 to 18446744073709551615, got '" +
                          seed + "'"),
              std::string::npos)
        << output;
  }
}

// The fidelity command's --wall-min-range is a range the sonar reaches: NaN, infinity, 0 and one
// past its 5 m are refused (past it the report was all zeros, as if walls matched).
TEST(Cli, FidelityRefusesAWallRangeTheSonarDoesNotReach) {
  const std::string scene = test::SourcePath("scenes/cras-tank.yaml");
  for (const std::string range : {"nan", "inf", "0", "5.5"}) {
    std::string output;
    EXPECT_EQ(RunCli("fidelity " + scene + " " + scene + " --wall-min-range " + range, &output), 2)
        << range;
    EXPECT_NE(output.find("--wall-min-range"), std::string::npos) << output;
    EXPECT_NE(output.find(range), std::string::npos) << output;
  }
}

// An --out that is a file is refused before any work, by every command that writes one; one
// that cannot be made is refused as bad input too.
TEST(Cli, AnOutputDirectoryThatIsAFileExitsTwo) {
  test::TempDir dir;
  const auto scene = TankSceneWithCriteria(dir.path(), "");
  const std::string file = scene.string();
  // Each command refuses its --out before reading its input (`map`'s directory holds no
  // dataset, `fidelity`'s log is not a .mat file).
  const std::vector<std::string> commands = {"run " + file + " --no-progress",
                                             "map " + dir.path().string(), "sweep " + file,
                                             "fidelity " + file + " " + file, "simulate " + file};
  const std::string blocked = file + "/out";  // under a file: cannot be made
  for (const auto& [out, says] :
       {std::pair{file, file + ": exists and is not a directory"},
        std::pair{blocked, blocked + ": cannot be made the output directory"}}) {
    for (const std::string& command : commands) {
      std::string output;
      EXPECT_EQ(RunCli(command + " --out " + out, &output), 2) << command;
      EXPECT_NE(output.find(says), std::string::npos) << command << "\n" << output;
    }
  }
}

TEST(Cli, HelpExplainsEachSubcommand) {
  std::string output;
  EXPECT_EQ(RunCli("--help", &output), 0);
  EXPECT_NE(output.find("run"), std::string::npos);
  EXPECT_EQ(RunCli("run --help", &output), 0);
  EXPECT_NE(output.find("--seed"), std::string::npos);
  EXPECT_NE(output.find("--out"), std::string::npos);
}

}  // namespace
}  // namespace sonarbench::sim
