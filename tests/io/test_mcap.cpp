#include <gtest/gtest.h>
#include <zstd.h>

#include <cstring>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/mcap.hpp"
#include "sonarbench/io/rosbag.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

constexpr std::uint64_t kNoLimit = std::uint64_t{1} << 40;

// A bag of 30 beams of 399 bins (with their /tf and true poses): one chunk, about 50 kB.
std::string Written(const test::TempDir& dir) {
  io::RosbagContent bag;
  for (int b = 0; b < 30; ++b) {
    mapping::Beam beam;
    beam.time_s = b * 0.1;
    beam.head_angle_rad = b * 0.2;
    beam.bin_size_m = bag.sensor.bin_size_m;
    beam.intensities.assign(399, static_cast<std::uint8_t>(b));
    bag.beams.push_back(beam);
    bag.true_vehicle.push_back(Eigen::Isometry3d::Identity());
  }
  std::ostringstream out;
  io::WriteRosbag(out, bag, "sonarbench test");
  return test::WriteFile(dir, "bag.mcap", out.str());
}

// Offsets of the top-level records of an MCAP file's bytes, by opcode, in file order.
std::vector<std::pair<std::size_t, char>> Records(const std::string& file) {
  std::vector<std::pair<std::size_t, char>> records;
  for (std::size_t at = 8; at + 9 <= file.size() - 8;) {
    std::uint64_t length = 0;
    std::memcpy(&length, file.data() + at + 1, 8);
    records.emplace_back(at, file[at]);
    at += 9 + length;
  }
  return records;
}
std::size_t FirstRecord(const std::string& file, char opcode) {
  for (const auto& [at, op] : Records(file)) {
    if (op == opcode) return at;
  }
  return std::string::npos;
}

// The chunk compression rosbag2 uses by default.
TEST(Mcap, ReadsZstdChunks) {
  const test::TempDir dir;
  const std::string plain = ReadFileBytes(Written(dir), kMaxLogBytes);
  // Rewrite the first chunk (opcode 6) with its records zstd-compressed; the summary no longer
  // matches the file, so the footer's summary offset and CRC are zeroed (no summary).
  const std::size_t chunk = FirstRecord(plain, '\x06');
  std::uint64_t length = 0;
  std::memcpy(&length, plain.data() + chunk + 1, 8);
  std::size_t at = chunk + 9 + 8 + 8 + 8 + 4;
  std::uint32_t compression = 0;
  std::memcpy(&compression, plain.data() + at, 4);
  ASSERT_EQ(compression, 0U);  // an empty string: uncompressed
  at += 4;
  std::uint64_t records_size = 0;
  std::memcpy(&records_size, plain.data() + at, 8);
  const std::string records = plain.substr(at + 8, records_size);
  std::string packed(ZSTD_compressBound(records.size()), '\0');
  packed.resize(ZSTD_compress(packed.data(), packed.size(), records.data(), records.size(), 3));
  std::string body = plain.substr(chunk + 9, 8 + 8 + 8 + 4) + std::string("\x04\0\0\0zstd", 8);
  const std::uint64_t packed_size = packed.size();
  body.append(reinterpret_cast<const char*>(&packed_size), 8);
  body += packed;
  std::string record("\x06");
  const std::uint64_t body_size = body.size();
  record.append(reinterpret_cast<const char*>(&body_size), 8);
  std::string file = plain.substr(0, chunk) + record + body;
  // Keep the data section up to the end of that chunk's message indexes, then a bare footer.
  const std::size_t data_end = FirstRecord(plain, '\x0F');
  std::size_t next = chunk + 9 + length;
  while (next < data_end && plain[next] == '\x07') {
    std::uint64_t n = 0;
    std::memcpy(&n, plain.data() + next + 1, 8);
    file += plain.substr(next, 9 + n);
    next += 9 + n;
  }
  file += std::string("\x02\x14\0\0\0\0\0\0\0", 9) + std::string(20, '\0') + io::kMcapMagic;
  const io::McapFile read = io::ReadMcap(test::WriteFile(dir, "zstd.mcap", file), kNoLimit);
  EXPECT_FALSE(read.has_summary);
  EXPECT_EQ(read.messages.size(), 1U + 3U * 30U);  // /tf_static, then /tf, image, truth a beam
}

TEST(Mcap, RefusesDamagedFilesNamingTheByte) {
  const test::TempDir dir;
  const std::string good = ReadFileBytes(Written(dir), kMaxLogBytes);
  const auto bad = [&](const std::string& bytes, const std::vector<std::string>& parts) {
    const std::string path = test::WriteFile(dir, "bad.mcap", bytes);
    EXPECT_TRUE(test::ThrowsInputErrorWith([&] { (void)io::ReadMcap(path, kNoLimit); }, parts));
  };
  bad("PK\x03\x04 not a bag", {"bad.mcap", "not an MCAP file"});
  bad(good.substr(0, good.size() - 8), {"closing magic"});
  bad(good.substr(0, good.size() / 2), {"truncated"});
  const std::size_t data = FirstRecord(good, '\x06') + 9 + 8 + 8 + 8 + 4 + 4 + 8 + 100;
  std::string corrupt = good;
  corrupt[data] ^= 0x01;
  bad(corrupt, {"CRC-32"});
  std::string summary = good;
  summary[summary.size() - 8 - 29 - 10] ^= 0x01;  // inside the last summary offset record
  bad(summary, {"summary's CRC-32"});
  // Every cut of the file is refused with a message, none crashes.
  for (std::size_t n = 0; n < good.size(); n += 997) {
    const std::string path = test::WriteFile(dir, "cut.mcap", good.substr(0, n));
    EXPECT_THROW((void)io::ReadMcap(path, kNoLimit), InputError) << n;
  }
}

TEST(Mcap, RefusesAFileLargerThanTheLimitBeforeReadingIt) {
  const test::TempDir dir;
  const std::string path = Written(dir);
  EXPECT_TRUE(test::ThrowsInputErrorWith([&] { (void)io::ReadMcap(path, 1000); },
                                         {"bag.mcap", "more than the 1000 bytes"}));
}

}  // namespace
}  // namespace sonarbench
