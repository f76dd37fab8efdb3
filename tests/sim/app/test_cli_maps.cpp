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

// map, score and simulate as a user runs them: maps scored as `run` scores its own.
namespace sonarbench::sim {
namespace {

using mapping::kDegToRad;

using test::ReadFile;
using test::RunCli;
using test::TankSceneWithCriteria;
using test::XmlLint;

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
  EXPECT_NE(output.find("against " + scene.string() + ": within a cell: precision"),
            std::string::npos)
      << output;
  const auto scored = nlohmann::json::parse(ReadFile(map / "report.json"))["metrics"];
  // The same figures, but the split by the labels, which only the run that made them has.
  auto simulated = nlohmann::json::parse(ReadFile(run / "report.json"))["metrics"];
  EXPECT_EQ(simulated.erase("ghost_split_from_labels"), 1u);
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
  auto simulated = nlohmann::json::parse(ReadFile(run / "report.json"));
  EXPECT_EQ(simulated["metrics"].erase("ghost_split_from_labels"), 1u);  // the run's alone
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

}  // namespace
}  // namespace sonarbench::sim
