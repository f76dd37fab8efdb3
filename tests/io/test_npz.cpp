#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "sonarbench/io/npz.hpp"
#include "test_util.hpp"

namespace sonarbench::io {
namespace {

std::string Archive(const std::string& comment) {
  NpzArchive npz;
  const std::uint16_t values[] = {1, 2, 3, 4, 5, 6};
  npz.Add("a", "<u2", {2, 3}, {reinterpret_cast<const char*>(values), sizeof values});
  const double scalar = 0.5;
  npz.Add("s", "<f8", {}, {reinterpret_cast<const char*>(&scalar), sizeof scalar});
  const auto [names, width] = NumpyUnicode({"direct", "noise"});
  EXPECT_EQ(width, 6u);
  EXPECT_EQ(names.size(), 2u * 6u * 4u);
  npz.Add("names", "<U6", {2}, names);
  std::ostringstream out;
  npz.Write(out, comment);
  return out.str();
}

// The same arrays give the same bytes, the zip's comment reads back, a size that is not the
// shape's is refused. (numpy.load reading it: tests/docs/test_npz_example.sh.)
TEST(Npz, SameArraysSameBytesAndTheCommentReadsBack) {
  const std::string bytes = Archive("sonarbench test");
  EXPECT_EQ(bytes, Archive("sonarbench test"));
  EXPECT_EQ(bytes.substr(0, 4), std::string("PK\x03\x04", 4));
  test::TempDir dir;
  const std::string path = (dir.path() / "a.npz").string();
  std::ofstream(path, std::ios::binary) << bytes;
  EXPECT_EQ(NpzComment(path), "sonarbench test");
  std::ofstream(path, std::ios::binary) << "not a zip";
  EXPECT_FALSE(NpzComment(path).has_value());
  NpzArchive npz;
  EXPECT_THROW(npz.Add("a", "<u2", {2, 3}, "12345"), std::invalid_argument);
}

}  // namespace
}  // namespace sonarbench::io
