#include <gtest/gtest.h>
#include <zstd.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <numeric>
#include <random>
#include <string>

#include "sonarbench/io/labels.hpp"
#include "test_util.hpp"

namespace sonarbench::io {
namespace {

// Each share within one 255th of its exact value, and 255 in all.
TEST(Labels, SharesRoundToTwoHundredFiftyFifths) {
  const std::array<float, kEchoPaths> energy = {3.0F, 1.0F, 0.0F, 0.5F, 0.25F, 0.0F, 1.0F / 3.0F};
  const auto shares = ShareOf(energy);
  const double total = std::accumulate(energy.begin(), energy.end(), 0.0);
  EXPECT_EQ(std::accumulate(shares.begin(), shares.end(), 0U), 255U);
  for (std::size_t p = 0; p < kEchoPaths; ++p) {
    EXPECT_LT(std::abs(shares[p] - 255.0 * energy[p] / total), 1.0) << p;
  }
  EXPECT_EQ(shares[2], 0);
  const std::array<float, kEchoPaths> nothing{};
  EXPECT_EQ(ShareOf(nothing)[static_cast<std::size_t>(EchoPath::kNoise)], 255);
}

// What rounding down leaves goes to the largest remainders, the earlier path on a tie.
TEST(Labels, SharesLeftByRoundingGoToTheEarlierPathOnATie) {
  using Shares = std::array<std::uint8_t, kEchoPaths>;
  EXPECT_EQ(ShareOf(std::array<float, kEchoPaths>{1, 1, 0, 0, 0, 0, 0}),
            (Shares{128, 127, 0, 0, 0, 0, 0}));
  EXPECT_EQ(ShareOf(std::array<float, kEchoPaths>{0, 0, 0, 1, 1, 1, 1}),
            (Shares{0, 0, 0, 64, 64, 64, 63}));
}

// Over random energies of one to seven paths: each share is its exact value rounded down or up,
// and a path rounded up has a larger remainder than any rounded down (or an equal one, earlier).
TEST(Labels, SharesAreTheLargestRemainderRounding) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> size(0.0F, 1.0F);
  for (int trial = 0; trial < 20000; ++trial) {
    std::array<float, kEchoPaths> energy{};
    for (float& e : energy) e = rng() % 3 == 0 ? 0.0F : std::pow(size(rng), 4.0F);
    const auto shares = ShareOf(energy);
    const double total = std::accumulate(energy.begin(), energy.end(), 0.0);
    if (total == 0.0) continue;
    ASSERT_EQ(std::accumulate(shares.begin(), shares.end(), 0U), 255U) << trial;
    std::array<double, kEchoPaths> rest{};
    std::array<bool, kEchoPaths> up{};
    for (std::size_t p = 0; p < kEchoPaths; ++p) {
      const double exact = 255.0 * energy[p] / total;
      rest[p] = exact - std::floor(exact);
      ASSERT_LE(std::abs(shares[p] - exact), 1.0) << trial;
      up[p] = shares[p] > exact;
    }
    for (std::size_t i = 0; i < kEchoPaths; ++i) {
      for (std::size_t j = 0; j < kEchoPaths; ++j) {
        if (!up[i] || up[j] || energy[j] == 0.0F) continue;
        ASSERT_TRUE(rest[i] > rest[j] || (rest[i] == rest[j] && i < j)) << trial;
      }
    }
  }
}

BeamLabels TwoBins() {
  BeamLabels beam;
  beam.shares = {{255, 0, 0, 0, 0, 0, 0}, {10, 20, 30, 40, 50, 60, 45}};
  beam.mesh = {3, kNoLabelMesh};
  beam.point_sonar_m = {{1.5f, -0.25f, 0.125f}, Eigen::Vector3f::Constant(std::nanf(""))};
  return beam;
}

TEST(Labels, ReadBackAsWritten) {
  test::TempDir dir;
  const std::string path = (dir.path() / "labels.bin").string();
  const std::vector<BeamLabels> beams = {TwoBins(), BeamLabels{}, TwoBins()};
  WriteLabelFile(path, beams);
  const std::vector<BeamLabels> read = ReadLabelFile(path);
  ASSERT_EQ(read.size(), 3u);
  EXPECT_TRUE(read[1].shares.empty());
  for (const std::size_t b : {0u, 2u}) {
    EXPECT_EQ(read[b].shares, beams[b].shares);
    EXPECT_EQ(read[b].mesh, beams[b].mesh);
    EXPECT_EQ(read[b].point_sonar_m[0], beams[b].point_sonar_m[0]);
    EXPECT_TRUE(read[b].point_sonar_m[1].array().isNaN().all());
  }
}

// A file of `raw` bytes compressed as the writer does.
void WriteFrame(const std::string& path, const std::string& raw) {
  std::string frame(ZSTD_compressBound(raw.size()), '\0');
  frame.resize(ZSTD_compress(frame.data(), frame.size(), raw.data(), raw.size(), 1));
  std::ofstream(path, std::ios::binary) << frame;
}

TEST(Labels, ADamagedFileIsRefusedNamingIt) {
  test::TempDir dir;
  const std::string path = (dir.path() / "labels.bin").string();
  const auto error = [&] { return test::InputErrorOf([&] { (void)ReadLabelFile(path); }); };
  std::ofstream(path) << "not zstd";
  EXPECT_NE(error().find(path + ": not a label file"), std::string::npos) << error();
  WriteFrame(path, "SBBEAMS1");
  EXPECT_NE(error().find("magic 'SBLABEL1'"), std::string::npos) << error();
  // A beam count the file cannot hold is refused before anything is allocated for it.
  std::string raw = "SBLABEL1";
  const std::uint32_t huge = 0xFFFFFFFF, paths = kEchoPaths;
  raw.append(reinterpret_cast<const char*>(&huge), 4)
      .append(reinterpret_cast<const char*>(&paths), 4);
  WriteFrame(path, raw);
  EXPECT_NE(error().find("4294967295 beams do not fit"), std::string::npos) << error();
  // One beam of one bin whose shares add up past 255.
  raw = "SBLABEL1";
  const std::uint32_t one = 1;
  raw.append(reinterpret_cast<const char*>(&one), 4)
      .append(reinterpret_cast<const char*>(&paths), 4);
  raw.append(reinterpret_cast<const char*>(&one), 4);
  raw += std::string(6, static_cast<char>(100));
  raw += std::string("\xff\xff", 2) + std::string(4, '\0');
  WriteFrame(path, raw);
  EXPECT_NE(error().find("beam 0, bin 0: shares sum to 600"), std::string::npos) << error();
  // A frame that claims more than 1 GiB.
  {
    // A frame header whose content size field says 2 GiB: magic, descriptor (8-byte size), size.
    std::string claim = std::string("\x28\xb5\x2f\xfd", 4) + '\xe0';
    const std::uint64_t size = 2ULL << 30;
    claim.append(reinterpret_cast<const char*>(&size), 8);
    std::ofstream(path, std::ios::binary) << claim;
  }
  EXPECT_NE(error().find("at most 1 GiB"), std::string::npos) << error();
}

}  // namespace
}  // namespace sonarbench::io
