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

// A one-sweep copy of the tank scene with the given criteria section, in `dir`.
std::filesystem::path TankSceneWithCriteria(const std::filesystem::path& dir,
                                            const std::string& criteria) {
  std::string text = ReadFile(test::SourcePath("scenes/cras-tank.yaml"));
  auto replace_line = [&](const std::string& key, const std::string& line) {
    const auto at = text.find("\n" + key);
    ASSERT_NE(at, std::string::npos) << key;
    text.replace(at + 1, text.find('\n', at + 1) - at - 1, line);
  };
  replace_line("sweeps:", "sweeps: 1");
  replace_line("sensor_model:",
               "sensor_model: " + test::SourcePath("sensor-models/shad-micron.yaml"));
  const auto at = text.find("\ncriteria:");
  if (at != std::string::npos) text.erase(at + 1);
  const auto path = dir / "tank.yaml";
  std::ofstream(path) << text << "\n" << criteria;
  return path;
}

// Exit status of xmllint on `file`, or -1 when xmllint is not installed.
int XmlLint(const std::filesystem::path& file) {
  if (std::system("command -v xmllint > /dev/null 2>&1") != 0) return -1;
  return WEXITSTATUS(std::system(("xmllint --noout " + file.string()).c_str()));
}

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

TEST(Cli, SimulateWritesADatasetThatMapReads) {
  test::TempDir dir;
  const auto scene = TankSceneWithCriteria(dir.path(), "");
  const auto ds = dir.path() / "ds";
  std::string output;
  EXPECT_EQ(RunCli("simulate " + scene.string() + " --out " + ds.string(), &output), 0) << output;
  EXPECT_TRUE(std::filesystem::exists(ds / "manifest.json"));
  EXPECT_EQ(RunCli("simulate " + scene.string() + " --out " + ds.string(), &output), 0);
  EXPECT_NE(output.find("nothing to do"), std::string::npos) << output;
  EXPECT_EQ(RunCli("simulate " + scene.string() + " --out " + ds.string() + " --seed 5", &output),
            2);
  EXPECT_NE(output.find("pass --force"), std::string::npos) << output;
  EXPECT_EQ(
      RunCli("simulate " + scene.string() + " --out " + ds.string() + " --shard 3/2", &output), 2);
  const auto map = dir.path() / "map";
  EXPECT_EQ(RunCli("map " + ds.string() + " --out " + map.string(), &output), 0) << output;
  EXPECT_TRUE(std::filesystem::exists(map / "map.bt"));
  EXPECT_EQ(RunCli("map " + dir.path().string() + " --out " + map.string(), &output), 2);
  EXPECT_NE(output.find("no manifest.json"), std::string::npos) << output;
}

// `map --score` scores a log's map against a scene as `run` scores its own simulation: a dataset
// of the scene, mapped from its own poses, gets the metrics `run` reports, count for count, and
// reports the same mapper settings. A
// .mat log is static, so it can be placed only at a scene's static sonar (rocks-slope's moves;
// the check comes before the log is read); --score needs the scene.
TEST(Cli, MapScoresALogAgainstASceneAsRunScoresItsSimulation) {
  test::TempDir dir;
  const auto scene = TankSceneWithCriteria(dir.path(), "");
  const auto run = dir.path() / "run";
  const auto ds = dir.path() / "ds";
  const auto map = dir.path() / "map";
  std::string output;
  ASSERT_EQ(RunCli("run " + scene.string() + " --out " + run.string(), &output), 0) << output;
  ASSERT_EQ(RunCli("simulate " + scene.string() + " --out " + ds.string(), &output), 0) << output;
  ASSERT_EQ(
      RunCli("map " + ds.string() + " --scene " + scene.string() + " --score --out " + map.string(),
             &output),
      0)
      << output;
  EXPECT_NE(output.find("against " + scene.string() + ": occupied precision"), std::string::npos)
      << output;
  const auto scored = nlohmann::json::parse(ReadFile(map / "report.json"))["metrics"];
  const auto simulated = nlohmann::json::parse(ReadFile(run / "report.json"))["metrics"];
  EXPECT_GT(scored["counts"]["true_positive_cells"].get<std::size_t>(), 0u);
  EXPECT_EQ(scored, simulated);
  // And the mapper's settings the same way: every one, by its YAML name.
  EXPECT_EQ(nlohmann::json::parse(ReadFile(map / "report.json"))["mapping"],
            nlohmann::json::parse(ReadFile(run / "report.json"))["parameters"]["mapping"]);
  EXPECT_NE(output.find("PASS cras-tank: 0/0 criteria met"), std::string::npos) << output;
  EXPECT_NE(ReadFile(map / "report.html").find("<p class=\"verdict pass\">PASS"),
            std::string::npos);
  EXPECT_NE(XmlLint(map / "junit.xml"), 1);  // 0 when well-formed, -1 without xmllint
  // The same map from its .ot file, scored by `score`, scores the same.
  ASSERT_EQ(RunCli("score " + (map / "map.ot").string() + " --scene " + scene.string() + " --out " +
                       (dir.path() / "score").string(),
                   &output),
            0)
      << output;
  EXPECT_EQ(nlohmann::json::parse(ReadFile(dir.path() / "score" / "report.json"))["metrics"],
            scored);

  // The scene's criteria decide as they do for `run`: a missed one exits 1, outputs written.
  std::filesystem::create_directories(dir.path() / "strict");
  const auto strict = TankSceneWithCriteria(
      dir.path() / "strict", "criteria:\n  metrics: {occupied_recall: {min: 0.99}}\n");
  EXPECT_EQ(RunCli("map " + ds.string() + " --scene " + strict.string() + " --score --out " +
                       map.string(),
                   &output),
            1)
      << output;
  EXPECT_NE(output.find("FAIL cras-tank: 0/1 criteria met"), std::string::npos) << output;
  EXPECT_NE(output.find("expected >= 0.99"), std::string::npos) << output;
  const auto failed = nlohmann::json::parse(ReadFile(map / "report.json"));
  EXPECT_FALSE(failed["verdict"]["passed"].get<bool>());
  EXPECT_EQ(failed["criteria"]["results"][0]["metric"], "occupied_recall");
  EXPECT_EQ(failed["criteria"]["results"][0]["status"], "fail");

  EXPECT_NE(ReadFile(map / "junit.xml").find("<failure type=\"criterion\""), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(map / "map_side.png"));  // scored: the map against truth
  // Certainty sweep by sweep: a row a sweep, in the report's files.
  const std::string certainty = ReadFile(map / "certainty.csv");
  EXPECT_EQ(std::count(certainty.begin(), certainty.end(), '\n'), 2);  // header, one sweep
  EXPECT_TRUE(failed["files_sha256"].contains("certainty.png"));
  // Unscored, a map has no junit.xml: the scored run's is removed, not left stale.
  EXPECT_EQ(RunCli("map " + ds.string() + " --out " + map.string(), &output), 0) << output;
  EXPECT_FALSE(std::filesystem::exists(map / "junit.xml"));
  EXPECT_FALSE(std::filesystem::exists(map / "map_side.png"));
  EXPECT_FALSE(std::filesystem::exists(map / "certainty.csv"));
  EXPECT_TRUE(std::filesystem::exists(map / "report.html"));

  EXPECT_EQ(RunCli("map " + ds.string() + " --score --out " + map.string(), &output), 2);
  EXPECT_NE(output.find("--score requires --scene"), std::string::npos) << output;
  const std::string moving = test::SourcePath("scenes/rocks-slope.yaml");
  EXPECT_EQ(
      RunCli("map " + scene.string() + " --scene " + moving + " --score --out " + map.string(),
             &output),
      2);
  EXPECT_NE(output.find("rocks-slope.yaml: the sonar moves along the scene's trajectory"),
            std::string::npos)
      << output;
}

// An OcTree file of resolution `resolution_m` with one occupied cell at each of `points` [m].
std::string WriteOcTree(const std::filesystem::path& path, double resolution_m,
                        const std::vector<octomap::point3d>& points) {
  octomap::OcTree tree(resolution_m);
  for (const octomap::point3d& p : points) tree.updateNode(p, true);
  tree.writeBinary(path.string());
  return path.string();
}

TEST(Cli, ScoreScoresAMapFileAsRunScoresItsOwnMap) {
  test::TempDir dir;
  const auto scene = TankSceneWithCriteria(dir.path(), "");
  const auto run = dir.path() / "run";
  const auto score = dir.path() / "score";
  std::string output;
  ASSERT_EQ(RunCli("run " + scene.string() + " --out " + run.string(), &output), 0) << output;
  ASSERT_EQ(RunCli("score " + (run / "map.bt").string() + " --scene " + scene.string() + " --out " +
                       score.string(),
                   &output),
            0)
      << output;
  const auto scored = nlohmann::json::parse(ReadFile(score / "report.json"));
  const auto simulated = nlohmann::json::parse(ReadFile(run / "report.json"));
  EXPECT_GT(scored["metrics"]["counts"]["true_positive_cells"].get<std::size_t>(), 0u);
  EXPECT_EQ(scored["metrics"], simulated["metrics"]);
  EXPECT_EQ(scored["map"]["format"], "bt");
  EXPECT_EQ(scored["map"]["resolution_m"], 0.05);
  EXPECT_EQ(scored["frame_check"]["occupied_in_reach"], 1.0);
  // The same cells, so the same picture size (the PNG header's width and height); the titles
  // differ (the seed, the map file).
  for (const char* image : {"map_top.png", "map_side.png"}) {
    EXPECT_EQ(ReadFile(score / image).substr(16, 8), ReadFile(run / image).substr(16, 8)) << image;
  }
  EXPECT_NE(ReadFile(score / "report.html").find("sonarbench score: cras-tank"), std::string::npos);
  EXPECT_NE(XmlLint(score / "junit.xml"), 1);  // 0 when well-formed, -1 without xmllint
  EXPECT_NE(output.find("PASS cras-tank: 0/0 criteria met"), std::string::npos) << output;

  // The scene's criteria decide, with run's exit codes and junit failures.
  std::filesystem::create_directories(dir.path() / "strict");
  const auto strict = TankSceneWithCriteria(
      dir.path() / "strict", "criteria:\n  metrics: {occupied_recall: {min: 0.99}}\n");
  EXPECT_EQ(RunCli("score " + (run / "map.bt").string() + " --scene " + strict.string() +
                       " --out " + score.string(),
                   &output),
            1)
      << output;
  EXPECT_NE(output.find("FAIL cras-tank: 0/1 criteria met"), std::string::npos) << output;
  EXPECT_NE(ReadFile(score / "junit.xml").find("<failure type=\"criterion\""), std::string::npos);
}

// A map of exactly the tank's surfaces, occupied cells only (the simulated dataset's truth, as a
// mapper that exports no free cells writes), passes: free_accuracy is not applicable, not 0.
TEST(Cli, ScoreJudgesAMapWithoutFreeCellsOnWhatItHolds) {
  test::TempDir dir;
  const auto scene =
      TankSceneWithCriteria(dir.path(),
                            "criteria:\n  metrics:\n    occupied_precision: {min: 0.99}\n"
                            "    free_accuracy: {min: 0.9}\n");
  std::string output;
  const auto ds = dir.path() / "ds";
  ASSERT_EQ(RunCli("simulate " + scene.string() + " --out " + ds.string(), &output), 0) << output;
  const auto out = dir.path() / "score";
  EXPECT_EQ(RunCli("score " + (ds / "truth/occupancy.bt").string() + " --scene " + scene.string() +
                       " --out " + out.string(),
                   &output),
            0)
      << output;
  EXPECT_NE(output.find("PASS cras-tank: 1/1 criteria met, 1 not applicable"), std::string::npos)
      << output;
  EXPECT_NE(ReadFile(out / "junit.xml").find("skipped=\"1\""), std::string::npos);
  const auto report = nlohmann::json::parse(ReadFile(out / "report.json"));
  EXPECT_TRUE(report["metrics"]["free_accuracy"].is_null());
}

TEST(Cli, ScoreRefusesMapsItCannotScoreAndWritesNothing) {
  test::TempDir dir;
  const auto scene = TankSceneWithCriteria(dir.path(), "");
  const auto out = dir.path() / "out";
  const std::string color = test::WriteFile(
      dir, "color.bt", "# Octomap OcTree binary file\nid ColorOcTree\nsize 0\nres 0.05\ndata\n");
  const std::string text = test::WriteFile(dir, "notes.bt", "not a map\n");
  // Far from the tank: another frame. Tiny cells: a truth too large to build.
  const std::string far =
      WriteOcTree(dir.path() / "far.bt", 0.05, {{100, 100, 100}, {0, 0, 0}, {100, 99, 100}});
  const std::string tiny = WriteOcTree(dir.path() / "tiny.bt", 1e-4, {{0.5F, 0.5F, 0.5F}});
  for (const auto& [map, expected] : std::vector<std::pair<std::string, std::string>>{
           {color, "ColorOcTree"},
           {text, "the first line is 'not a map'"},
           {far, "1 of its 3 occupied cells lie within reach"},
           {tiny, "--max-cells"}}) {
    std::string output;
    EXPECT_EQ(
        RunCli("score " + map + " --scene " + scene.string() + " --out " + out.string(), &output),
        2)
        << output;
    EXPECT_NE(output.find(map + ": "), std::string::npos) << output;
    EXPECT_NE(output.find(expected), std::string::npos) << output;
    EXPECT_FALSE(std::filesystem::exists(out)) << map;
  }
}

// sonarbench writes only into what it owns: a user's files of its outputs' names are refused by
// name and left as they were, --force or not; --force never removes a tree or an input; a
// symlinked --out is followed, not replaced.
// The messages a newcomer meets: an unknown option named with the nearest the command has, a
// file export never replaces said at once (not "pass --force"), a topic a bag lacks with the
// topics it has, the detection `map` used without a scene, counts in the singular.
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
  EXPECT_NE(output.find("a bag sonarbench wrote); pass --force"), std::string::npos) << output;
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
  EXPECT_NE(output.find("detection: threshold 70, at most 2 echoes a beam (later echoes: "
                        "strongest), arc_marking at 0.05 m (the mapper's defaults; --scene or "
                        "--mapping sets them)"),
            std::string::npos)
      << output;
  EXPECT_NE(ReadFile(map / "report.html").find("<td>detection.threshold</td><td>70</td>"),
            std::string::npos);
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
TEST(Cli, ADatasetIsScoredOnlyAgainstItsOwnScene) {
  test::TempDir dir;
  const auto scene = TankSceneWithCriteria(dir.path(), "");
  const auto ds = dir.path() / "ds";
  std::string output;
  ASSERT_EQ(RunCli("simulate " + scene.string() + " --out " + ds.string(), &output), 0) << output;
  const std::string harbour = test::SourcePath("scenes/harbour-wall.yaml");
  EXPECT_EQ(RunCli("map " + ds.string() + " --scene " + harbour + " --score --out " +
                       (dir.path() / "map").string(),
                   &output),
            2);
  EXPECT_NE(output.find("cannot be scored against scene 'harbour-wall'"), std::string::npos)
      << output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "map"));
}

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
