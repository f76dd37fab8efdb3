#include "sonarbench/base/atomic_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include "test_util.hpp"

namespace sonarbench {
namespace {

namespace fs = std::filesystem;

std::string Contents(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// The temporary file is made new: a symlink planted under its name is refused, and the file it
// names is left as it was.
TEST(WriteFileAtomically, NeverWritesThroughAPlantedTemporaryName) {
  test::TempDir dir;
  const fs::path precious = dir.path() / "precious.txt";
  std::ofstream(precious) << "precious";
  const fs::path target = dir.path() / "out.txt";
  fs::create_symlink(precious, target.string() + ".tmp." + std::to_string(::getpid()));
  EXPECT_TRUE(test::ThrowsInputErrorWith(
      [&] { WriteFileAtomically(target.string(), [](std::ostream& out) { out << "new"; }); },
      {"out.txt: cannot be written", "File exists"}));
  EXPECT_EQ(Contents(precious), "precious");
  EXPECT_FALSE(fs::exists(target));
  fs::remove(target.string() + ".tmp." + std::to_string(::getpid()));
  WriteFileAtomically(target.string(), [](std::ostream& out) { out << "new"; });
  EXPECT_EQ(Contents(target), "new");
}

// A write that throws leaves the previous file whole and no temporary file beside it.
TEST(WriteFileAtomically, AFailedWriteKeepsThePreviousFile) {
  test::TempDir dir;
  const fs::path target = dir.path() / "map.bt";
  WriteFileAtomically(target.string(), [](std::ostream& out) { out << "old"; });
  EXPECT_THROW(WriteFileAtomically(target.string(),
                                   [](std::ostream& out) {
                                     out << "half";
                                     throw std::runtime_error("stopped");
                                   }),
               std::runtime_error);
  EXPECT_EQ(Contents(target), "old");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

}  // namespace
}  // namespace sonarbench
