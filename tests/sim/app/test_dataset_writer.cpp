#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/labels.hpp"
#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/app/map_log.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/ray_tracer.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

namespace fs = std::filesystem;
using mapping::Beam;

std::string Bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Every file under `dir` (relative path → bytes).
std::map<std::string, std::string> Tree(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = Bytes(e.path());
  }
  return files;
}

class TankDataset : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new sim::Scene(sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml")));
    scene_->sweeps = 3;
  }
  static void TearDownTestSuite() {
    delete scene_;
    scene_ = nullptr;
  }
  static sim::Scene* scene_;
};

sim::Scene* TankDataset::scene_ = nullptr;

TEST(Shard, ParsesKOfNAndSlurmArrays) {
  EXPECT_EQ(sim::ParseShard("3/8").index, 2);
  EXPECT_EQ(sim::ParseShard("3/8").count, 8);
  for (const char* bad : {"0/3", "4/3", "a/b", "1/0", "2", "1/2/3", "1/ 3", " 1/3", "1/3 ", "+1/3",
                          "1/+3", "1/", "/3", "99999999999/3"}) {
    EXPECT_NE(test::InputErrorOf([&] { (void)sim::ParseShard(bad); }).find("expected K/N"),
              std::string::npos)
        << bad;
  }
  ::unsetenv("SLURM_ARRAY_TASK_ID");
  EXPECT_FALSE(sim::ShardFromSlurm().has_value());
  ::setenv("SLURM_ARRAY_TASK_ID", "5", 1);
  ::setenv("SLURM_ARRAY_TASK_MIN", "4", 1);
  ::setenv("SLURM_ARRAY_TASK_COUNT", "3", 1);
  const auto shard = sim::ShardFromSlurm();
  ASSERT_TRUE(shard.has_value());
  EXPECT_EQ(shard->index, 1);
  EXPECT_EQ(shard->count, 3);
  // --array=1-5:2 runs tasks 1, 3 and 5 (count 3, step 2): shards 1/3, 2/3 and 3/3.
  ::setenv("SLURM_ARRAY_TASK_MIN", "1", 1);
  ::setenv("SLURM_ARRAY_TASK_STEP", "2", 1);
  for (const auto& [task, index] : {std::pair{"1", 0}, std::pair{"3", 1}, std::pair{"5", 2}}) {
    ::setenv("SLURM_ARRAY_TASK_ID", task, 1);
    ASSERT_TRUE(sim::ShardFromSlurm().has_value());
    EXPECT_EQ(sim::ShardFromSlurm()->index, index) << task;
  }
  for (const char* off_step : {"2", "7"}) {
    ::setenv("SLURM_ARRAY_TASK_ID", off_step, 1);
    EXPECT_NE(test::InputErrorOf([] { (void)sim::ShardFromSlurm(); }).find("outside the array"),
              std::string::npos);
  }
  ::setenv("SLURM_ARRAY_TASK_ID", "x", 1);
  EXPECT_NE(test::InputErrorOf([] { (void)sim::ShardFromSlurm(); }).find("SLURM_ARRAY_TASK_ID='x'"),
            std::string::npos);
  ::setenv("SLURM_ARRAY_TASK_ID", " 3", 1);
  EXPECT_NE(test::InputErrorOf([] { (void)sim::ShardFromSlurm(); }).find("non-negative integer"),
            std::string::npos);
  for (const char* v : {"SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_MIN", "SLURM_ARRAY_TASK_COUNT",
                        "SLURM_ARRAY_TASK_STEP"})
    ::unsetenv(v);
}

TEST_F(TankDataset, ReadsBackTheSimulatedBeamsAndPoses) {
  test::TempDir dir;
  const auto out = dir.path() / "ds";
  const auto summary = sim::SimulateDataset(*scene_, out.string(), {});
  EXPECT_TRUE(summary.complete);
  EXPECT_EQ(summary.sweeps_written, 3u);

  const io::Dataset dataset = io::ReadDataset(out.string());
  EXPECT_EQ(dataset.manifest["schema_version"], io::kDatasetSchemaVersion);
  EXPECT_EQ(dataset.manifest["seed"], scene_->seed);
  EXPECT_EQ(dataset.sweeps, 3u);
  EXPECT_EQ(dataset.sensor.num_bins, scene_->sensor.geometry.num_bins);
  // Every file but the manifest is listed with its hash: beams, images, truth and labels per
  // sweep, three pose files and the truth occupancy.
  EXPECT_EQ(dataset.manifest["files"].size(), 3u * 4u + 3u + 1u);
  EXPECT_FALSE(fs::exists(out / ".sonarbench-partial.json"));

  const auto meshes = sim::BuildSceneMeshes(*scene_);
  const sim::RayTracer tracer(meshes);
  const auto expected = sim::BeamsOf(sim::SimulateScene(*scene_, tracer, scene_->seed, 1));
  ASSERT_EQ(dataset.beams.size(), expected.size());
  for (std::size_t b = 0; b < expected.size(); b += 37) {
    EXPECT_EQ(dataset.beams[b].intensities, expected[b].intensities) << b;
    EXPECT_EQ(dataset.beams[b].head_angle_rad, expected[b].head_angle_rad);
    EXPECT_TRUE(dataset.beams[b].T_world_sonar.isApprox(expected[b].T_world_sonar, 1e-8));
  }
  // The per-beam truth: beam 388 of sweep 1 (which starts at 180°, a head step of 1.8°) looks at
  // 158.4°, between the vehicle's parts (its scene's comments). Its axis meets the -x wall at
  // (4.36/2 + 0.10) / cos(21.6°) m; its nearest hit is the floor plane (0.0005 m) seen by the
  // fan's lowest rays: at 17.5° down, or up to one ray stratum (35°/160) higher.
  std::ifstream truth(out / "truth/sweep_0001.csv");
  std::string header;
  std::getline(truth, header);
  EXPECT_EQ(header, "beam,time_s,head_angle_rad,first_hit_range_m,first_hit_mesh,axis_hit_range_m");
  std::vector<std::string> f;
  for (std::string line; f.empty() && std::getline(truth, line);) {
    if (!line.starts_with("388,")) continue;
    std::stringstream fields(line);
    for (std::string field; std::getline(fields, field, ',');) f.push_back(field);
  }
  ASSERT_EQ(f.size(), 6u) << "beam 388's line";
  const double head = (180.0 + 188 * 1.8 - 360.0) * M_PI / 180;
  EXPECT_NEAR(std::stod(f[2]), head, 1e-6);
  EXPECT_EQ(f[4], "floor");
  const double height = expected[388].T_world_sonar.translation().z() - 0.0005;
  const double edge = 17.5 * M_PI / 180;
  EXPECT_GE(std::stod(f[3]), height / std::sin(edge) - 1e-6);
  EXPECT_LE(std::stod(f[3]), height / std::sin(edge - 35.0 / 160 * M_PI / 180));
  EXPECT_NEAR(std::stod(f[5]), (4.36 / 2 + 0.10) / -std::cos(head), 1e-5);

  // Its labels: the synthesiser's, each bin's shares in 255ths, the meshes and points kept.
  const std::vector<io::BeamLabels> labels =
      io::ReadLabelFile((out / "truth/labels_0001.bin").string());
  ASSERT_EQ(labels.size(), 200u);
  const sim::BeamSynthesizer synthesizer = sim::SceneSynthesizer(*scene_, tracer, scene_->seed);
  const auto beam =
      sim::SimulateBeams(*scene_, synthesizer, scene_->seed, 1, 388, 389, sim::Labels::kKeep);
  const io::BeamLabels& read = labels[188];
  ASSERT_EQ(read.shares.size(), beam[0].labels.size());
  std::size_t direct_bins = 0;
  for (std::size_t k = 0; k < read.shares.size(); ++k) {
    const sim::BinLabel& bin = beam[0].labels[k];
    EXPECT_EQ(read.shares[k], io::ShareOf(bin.energy)) << k;
    if (bin.mesh == sim::kNoMesh) {
      EXPECT_EQ(read.mesh[k], io::kNoLabelMesh) << k;
      continue;
    }
    ++direct_bins;
    EXPECT_EQ(read.mesh[k], bin.mesh) << k;
    EXPECT_EQ(read.point_sonar_m[k], bin.point_sonar_m) << k;
  }
  EXPECT_GT(direct_bins, 10u);
}

// The label file's records are the same on any number of threads and into reused memory; a mesh the
// file's 16 bits cannot number is refused with what the file can hold.
TEST(LabelFileBeams, AreTheSameOnAnyThreadsAndRefuseMeshesPastSixteenBits) {
  std::vector<sim::SynthesizedBeam> beams(5);
  for (std::size_t b = 0; b < beams.size(); ++b) {
    beams[b].labels.resize(40);
    for (std::size_t k = 0; k < 40; ++k) {
      sim::BinLabel& bin = beams[b].labels[k];
      bin.energy = {static_cast<float>(k % 3), 0.5F, 0, 0, 0, 0, static_cast<float>(b + 1)};
      if (k % 4 == 0) {
        bin.mesh = static_cast<std::uint32_t>(b);
        bin.point_sonar_m = Eigen::Vector3f(1.0F, static_cast<float>(k), 0.0F);
      }
    }
  }
  std::vector<io::BeamLabels> one;
  sim::LabelFileBeams(beams, 1, one);
  // Into the memory of a sweep of more beams and bins: the same as into none.
  std::vector<sim::SynthesizedBeam> longer = beams;
  longer.push_back(beams[1]);
  for (sim::SynthesizedBeam& beam : longer) beam.labels.resize(60, beams[2].labels[0]);
  std::vector<io::BeamLabels> two;
  sim::LabelFileBeams(longer, 2, two);
  sim::LabelFileBeams(beams, 2, two);
  ASSERT_EQ(one.size(), 5u);
  EXPECT_EQ(io::EncodeLabelFile(one), io::EncodeLabelFile(two));
  EXPECT_EQ(one[3].mesh[8], 3);
  EXPECT_EQ(one[3].mesh[9], io::kNoLabelMesh);
  EXPECT_EQ(one[3].shares[2], io::ShareOf(beams[3].labels[2].energy));
  beams[4].labels[7].mesh = 70000;
  EXPECT_NE(test::InputErrorOf([&] {
              sim::LabelFileBeams(beams, 2, two);
            }).find("a scene of at most 65535 meshes"),
            std::string::npos);
}

TEST_F(TankDataset, ShardsAndResumedRunsGiveTheSameBytesAsOneRun) {
  test::TempDir dir;
  const auto whole = dir.path() / "whole";
  const auto split = dir.path() / "split";
  (void)sim::SimulateDataset(*scene_, whole.string(), {});

  sim::DatasetOptions first;
  first.shard = {0, 2};  // sweeps 0 and 2, on one thread
  first.threads = 1;
  const auto partial = sim::SimulateDataset(*scene_, split.string(), first);
  EXPECT_FALSE(partial.complete);
  EXPECT_EQ(partial.sweeps_written, 2u);
  EXPECT_NE(
      test::InputErrorOf([&] { (void)io::ReadDataset(split.string()); }).find("no manifest.json"),
      std::string::npos);
  // A run killed while writing leaves at most a temporary file, and its name in the lock file:
  // the rerun removes it.
  std::ofstream(split / "beams/sweep_0001.bin.tmp.999") << "half";
  std::ofstream(split / ".sonarbench.lock") << "sonarbench simulate, pid 999 on host, config c\n";

  const auto resumed = sim::SimulateDataset(*scene_, split.string(), {});
  EXPECT_TRUE(resumed.complete);
  EXPECT_EQ(resumed.sweeps_skipped, 2u);
  EXPECT_EQ(resumed.sweeps_written, 1u);
  EXPECT_EQ(Tree(whole), Tree(split));

  const auto again = sim::SimulateDataset(*scene_, split.string(), {});
  EXPECT_TRUE(again.already_complete);
}

// Without label files: the same beams, images, poses and truth, no label file listed or written, a
// configuration of its own (a rerun never mixes the two), and mapped against its scene without a
// warning.
TEST_F(TankDataset, WithoutLabelFilesTheOtherFilesAreTheSameBytes) {
  test::TempDir dir;
  const auto whole = dir.path() / "whole";
  const auto bare = dir.path() / "bare";
  (void)sim::SimulateDataset(*scene_, whole.string(), {});
  sim::DatasetOptions no_labels;
  no_labels.labels = false;
  no_labels.threads = 1;
  EXPECT_TRUE(sim::SimulateDataset(*scene_, bare.string(), no_labels).complete);

  const auto with = Tree(whole);
  const auto without = Tree(bare);
  std::size_t compared = 0;
  for (const auto& [path, bytes] : with) {
    if (path.starts_with("truth/labels_")) {
      EXPECT_EQ(without.count(path), 0u) << path;
    } else if (path != "manifest.json" && !path.starts_with(".sonarbench")) {
      EXPECT_EQ(without.at(path), bytes) << path;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 3u * 3u + 3u + 1u);
  EXPECT_EQ(without.size(), with.size() - 3u);
  const io::Dataset dataset = io::ReadDataset(bare.string());
  EXPECT_EQ(dataset.manifest["files"].size(), 3u * 3u + 3u + 1u);
  EXPECT_FALSE(dataset.manifest["truth"].contains("labels"));
  EXPECT_TRUE(io::ReadDatasetLabels(bare.string(), dataset).empty());
  EXPECT_NE(dataset.manifest["config_sha256"],
            io::ReadDataset(whole.string()).manifest["config_sha256"]);
  EXPECT_TRUE(sim::MapLog(bare.string(), scene_->sensor.geometry, scene_->mapping, scene_)
                  .warnings.empty());

  EXPECT_NE(test::InputErrorOf([&] {
              (void)sim::SimulateDataset(*scene_, bare.string(), {});
            }).find("another configuration"),
            std::string::npos);
  sim::DatasetOptions labels_again;
  labels_again.force = true;
  EXPECT_TRUE(sim::SimulateDataset(*scene_, bare.string(), labels_again).complete);
  EXPECT_EQ(Tree(bare), with);

  // A scene of more meshes than the label files number: refused before anything is made.
  sim::Scene crowded = *scene_;
  crowded.meshes.resize(io::kNoLabelMesh, crowded.meshes.front());
  const auto none = dir.path() / "none";
  EXPECT_NE(test::InputErrorOf([&] {
              (void)sim::SimulateDataset(crowded, none.string(), {});
            }).find("65535 meshes; the label files number meshes in 16 bits, at most 65535"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(none));
}

TEST_F(TankDataset, NeverOverwritesWithoutForceAndNeverDeletesStrangers) {
  test::TempDir dir;
  const auto out = dir.path() / "ds";
  (void)sim::SimulateDataset(*scene_, out.string(), {});
  sim::DatasetOptions other_seed;
  other_seed.seed = 99;
  EXPECT_NE(test::InputErrorOf([&] {
              (void)sim::SimulateDataset(*scene_, out.string(), other_seed);
            }).find("another configuration"),
            std::string::npos);
  other_seed.force = true;
  EXPECT_TRUE(sim::SimulateDataset(*scene_, out.string(), other_seed).complete);
  EXPECT_EQ(io::ReadDataset(out.string()).manifest["seed"], 99);

  // A directory sonarbench did not write: a file of a name a dataset uses is refused, even with
  // --force; other files stay as they are beside a dataset, whatever --force.
  const auto stranger = dir.path() / "home";
  fs::create_directories(stranger / "src");
  std::ofstream(stranger / "thesis.tex") << "precious";
  std::ofstream(stranger / "src/main.c") << "int main;";
  std::ofstream(stranger / "manifest.json") << R"({"name": "webapp"})";
  EXPECT_NE(test::InputErrorOf([&] {
              (void)sim::SimulateDataset(*scene_, stranger.string(), other_seed);
            }).find("holds files sonarbench did not write: manifest.json"),
            std::string::npos);
  EXPECT_EQ(Bytes(stranger / "manifest.json"), R"({"name": "webapp"})");
  EXPECT_FALSE(fs::exists(stranger / ".sonarbench.lock"));
  fs::remove(stranger / "manifest.json");
  EXPECT_TRUE(sim::SimulateDataset(*scene_, stranger.string(), other_seed).complete);
  other_seed.seed = 98;
  EXPECT_TRUE(sim::SimulateDataset(*scene_, stranger.string(), other_seed).complete);
  EXPECT_EQ(io::ReadDataset(stranger.string()).manifest["seed"], 98);
  EXPECT_EQ(Bytes(stranger / "thesis.tex"), "precious");
  EXPECT_EQ(Bytes(stranger / "src/main.c"), "int main;");
}

TEST_F(TankDataset, ADamagedFileIsNamed) {
  test::TempDir dir;
  const auto out = dir.path() / "ds";
  (void)sim::SimulateDataset(*scene_, out.string(), {});
  {
    // Flip every bit of one byte (writing a fixed value leaves the file as it was whenever the
    // byte already held it).
    std::fstream f(out / "beams/sweep_0002.bin", std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(100);
    const int byte = f.get();
    ASSERT_NE(byte, std::char_traits<char>::eof());
    f.seekp(100);
    f.put(static_cast<char>(~byte));
  }
  EXPECT_NE(test::InputErrorOf([&] {
              (void)io::ReadDataset(out.string());
            }).find("sweep_0002.bin: its sha256 differs"),
            std::string::npos);
}

}  // namespace
}  // namespace sonarbench
