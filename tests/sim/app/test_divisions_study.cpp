#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "sonarbench/base/error.hpp"
#include "sonarbench/sim/app/divisions_study.hpp"
#include "sonarbench/sim/eval/beam_coverage.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

using Eigen::Vector3d;

std::size_t Lines(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

// The study on one sweep of the tank, three settings, split in two shards and merged.
TEST(DivisionsStudy, ShardsMergeAndMoreVerticalRaysCoverMore) {
  test::TempDir dir;
  Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  StudyOptions options;
  options.sweeps = 1;
  options.coverage_beams = 4;
  options.items = {{"vertical", 32, 4}, {"vertical", 32, 16}, {"vertical", 32, 64}};
  options.shard = {0, 2};
  const auto out = dir.path() / "study";
  const StudySummary first = RunDivisionsStudy(scene, out.string(), options);
  EXPECT_EQ(first.items_written, 2u);  // items 0 and 2
  EXPECT_FALSE(first.complete);
  EXPECT_FALSE(std::filesystem::exists(out / "divisions.csv"));
  options.shard = {1, 2};
  const StudySummary second = RunDivisionsStudy(scene, out.string(), options);
  EXPECT_EQ(second.items_written, 1u);
  EXPECT_TRUE(second.complete);
  EXPECT_EQ(Lines(out / "divisions.csv"), 4u);
  EXPECT_TRUE(std::filesystem::exists(out / "coverage_vs_divisions.png"));
  EXPECT_TRUE(std::filesystem::exists(out / "time_vs_divisions.png"));

  std::ifstream in(out / "study.json");
  const auto study = nlohmann::json::parse(in);
  const auto& items = study["items"];
  ASSERT_EQ(items.size(), 3u);
  EXPECT_LT(items[0]["beam_coverage"].get<double>(), items[1]["beam_coverage"].get<double>());
  EXPECT_LT(items[1]["beam_coverage"].get<double>(), items[2]["beam_coverage"].get<double>());
  EXPECT_EQ(items[2]["visited_outside_cells"], 0);
  EXPECT_LT(items[0]["ray_casts"].get<double>(), items[2]["ray_casts"].get<double>());

  // A rerun skips what is done; another configuration is refused until --force.
  options.shard = {};
  EXPECT_EQ(RunDivisionsStudy(scene, out.string(), options).items_skipped, 3u);
  options.coverage_beams = 5;
  EXPECT_THROW((void)RunDivisionsStudy(scene, out.string(), options), InputError);
  options.force = true;
  EXPECT_TRUE(RunDivisionsStudy(scene, out.string(), options).complete);
}

// The exact mode's item: its cells are the wedge's (coverage 1, none outside, the undecided band
// taken), each examined about once, and no ray cast.
TEST(DivisionsStudy, TheExactItemCoversTheWholeWedge) {
  test::TempDir dir;
  Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  StudyOptions options;
  options.sweeps = 1;
  options.coverage_beams = 4;
  options.items = {{"vertical", 32, 64}, {"exact", 0, 0}};
  const auto out = dir.path() / "study";
  ASSERT_TRUE(RunDivisionsStudy(scene, out.string(), options).complete);
  std::ifstream in(out / "study.json");
  const auto items = nlohmann::json::parse(in)["items"];
  ASSERT_EQ(items.size(), 2u);
  const auto& exact = items[1];
  EXPECT_EQ(exact["group"], "exact");
  EXPECT_EQ(exact["beam_coverage"].get<double>(), 1.0);
  EXPECT_EQ(exact["beam_coverage_upper"].get<double>(), 1.0);
  EXPECT_EQ(exact["visited_outside_cells"], 0);
  EXPECT_EQ(exact["ray_casts"], 0);
  EXPECT_LT(exact["visits_per_cell"].get<double>(), 1.5);
  EXPECT_LT(items[0]["beam_coverage"].get<double>(), 1.0);
  EXPECT_GT(exact["map_recall"].get<double>(), 0.0);
}

}  // namespace
}  // namespace sonarbench::sim
