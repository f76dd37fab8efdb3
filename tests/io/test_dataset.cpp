#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/ray_tracer.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

namespace fs = std::filesystem;
using mapping::Beam;

TEST(BeamFile, RoundTripsAndRejectsDamage) {
  std::vector<Beam> beams(2);
  beams[0].time_s = 1.25;
  beams[0].head_angle_rad = 0.5;
  beams[0].bin_size_m = 0.0125;
  beams[0].intensities = {0, 7, 255};
  beams[1].time_s = 1.5;
  beams[1].bin_size_m = 0.0125;  // no bins: a beam cut short
  std::stringstream file;
  io::WriteBeamFile(file, beams);
  const std::string bytes = file.str();
  EXPECT_EQ(bytes.size(), 8u + 4u + 2 * (3 * 8u + 4u) + 3u);
  std::istringstream in(bytes);
  const auto back = io::ReadBeamFile(in, "f.bin");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].time_s, 1.25);
  EXPECT_EQ(back[0].head_angle_rad, 0.5);
  EXPECT_EQ(back[0].intensities, beams[0].intensities);
  EXPECT_TRUE(back[1].intensities.empty());

  std::istringstream truncated(bytes.substr(0, bytes.size() - 1));
  EXPECT_NE(test::InputErrorOf([&] {
              (void)io::ReadBeamFile(truncated, "f.bin");
            }).find("f.bin: truncated in the header of beam 1"),
            std::string::npos);
  std::istringstream trailing(bytes + "x");
  EXPECT_NE(
      test::InputErrorOf([&] { (void)io::ReadBeamFile(trailing, "f.bin"); }).find("bytes after"),
      std::string::npos);
  std::istringstream wrong("PNG....");
  EXPECT_NE(test::InputErrorOf([&] { (void)io::ReadBeamFile(wrong, "f.bin"); }).find("SBBEAMS1"),
            std::string::npos);
}

// A manifest without its list of files is bad input, named as such, like every other key.
TEST(Dataset, AManifestWithoutItsListOfFilesIsRefused) {
  test::TempDir dir;
  nlohmann::json manifest = {{"format", io::kDatasetFormat},
                             {"schema_version", io::kDatasetSchemaVersion},
                             {"sweeps", 0},
                             {"sensor", io::SensorGeometryJson(mapping::SensorGeometry{})}};
  for (const nlohmann::json& files : {nlohmann::json(), nlohmann::json::object()}) {
    if (!files.is_null()) manifest["files"] = files;
    const std::string path = test::WriteFile(dir, "manifest.json", manifest.dump());
    EXPECT_EQ(test::InputErrorOf([&] { (void)io::ReadDataset(dir.path().string()); }),
              path + ": key 'files': expected a list of {path, sha256, bytes}");
  }
  // A number past a double's range is bad JSON as a syntax error is.
  const std::string path = test::WriteFile(dir, "manifest.json", R"({"sweeps": 1e999})");
  EXPECT_EQ(test::InputErrorOf([&] { (void)io::ReadDataset(dir.path().string()); }),
            path +
                ": not valid JSON: [json.exception.out_of_range.406] number overflow parsing "
                "'1e999'");
  manifest["files"] = nlohmann::json::array();
  test::WriteFile(dir, "manifest.json", manifest.dump());
  fs::create_directories(dir.path() / "poses");
  test::WriteFile(dir, "poses/sonar.tum", "");
  EXPECT_TRUE(io::ReadDataset(dir.path().string()).beams.empty());
}

// A pose stamped at 1e300 s is named in a number a person reads, not in 300 digits.
TEST(Dataset, APoseStampedOffItsBeamIsNamedInShortNumbers) {
  test::TempDir dir;
  fs::create_directories(dir.path() / "beams");
  fs::create_directories(dir.path() / "poses");
  Beam beam;
  beam.bin_size_m = 0.01;
  beam.intensities.assign(4, 9);
  std::ostringstream beams;
  io::WriteBeamFile(beams, std::span<const Beam>(&beam, 1));
  const std::string beam_file = test::WriteFile(dir, "beams/sweep_0000.bin", beams.str());
  const std::string poses = test::WriteFile(dir, "poses/sonar.tum", "1e300 0 0 0 0 0 0 1\n");
  nlohmann::json manifest = {{"format", io::kDatasetFormat},
                             {"schema_version", io::kDatasetSchemaVersion},
                             {"sweeps", 1},
                             {"sensor", io::SensorGeometryJson(mapping::SensorGeometry{})}};
  manifest["files"] = nlohmann::json::array();
  for (const auto& [relative, path] :
       {std::pair{"beams/sweep_0000.bin", beam_file}, std::pair{"poses/sonar.tum", poses}}) {
    manifest["files"].push_back(
        {{"path", relative}, {"sha256", io::Sha256OfFile(path)}, {"bytes", fs::file_size(path)}});
  }
  test::WriteFile(dir, "manifest.json", manifest.dump());
  EXPECT_EQ(test::InputErrorOf([&] { (void)io::ReadDataset(dir.path().string()); }),
            poses + ": pose 0 is stamped 1e+300 s, its beam 0 s");
}

TEST(Tum, RoundTripsAPoseAndNamesTheBadLine) {
  test::TempDir dir;
  Eigen::Isometry3d pose = mapping::PoseFromXyzRpy({1, -2, 0.5}, {0.1, -0.2, 2.5});
  const auto path = dir.path() / "p.tum";
  std::ofstream(path) << "# comment\n" << io::TumLine(3.5, pose);
  const auto back = io::ReadTum(path.string());
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].time_s, 3.5);
  EXPECT_TRUE(back[0].pose.isApprox(pose, 1e-8));
  std::ofstream(path) << io::TumLine(0, pose) << "1 2 3\n";
  EXPECT_NE(
      test::InputErrorOf([&] { (void)io::ReadTum(path.string()); }).find("p.tum:2: expected 8"),
      std::string::npos);
  // A damaged line is quoted printable and short: its bytes as \xNN, cut after 80.
  std::ofstream(path) << "0 0.1 0.4\xfa" << std::string(5000, '7') << "\n";
  const std::string damaged = test::InputErrorOf([&] { (void)io::ReadTum(path.string()); });
  EXPECT_NE(damaged.find("got '0 0.1 0.4\\xfa777"), std::string::npos) << damaged;
  EXPECT_NE(damaged.find("7777'..."), std::string::npos) << damaged;
  EXPECT_LT(damaged.size(), path.string().size() + 200) << damaged;
  std::ofstream(path) << "0 0 0 0 0 0 0 2\n";
  EXPECT_NE(test::InputErrorOf([&] { (void)io::ReadTum(path.string()); }).find("norm"),
            std::string::npos);
}

TEST(Sha256, MatchesFips180Vectors) {
  EXPECT_EQ(io::Sha256("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(io::Sha256(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

}  // namespace
}  // namespace sonarbench
