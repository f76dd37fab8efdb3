#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <future>

#include "sonarbench/io/files.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

namespace fs = std::filesystem;

// A FIFO is refused by its type at once: the open never waits for a writer (the future would
// time out, and the test with it, if it did).
TEST(ReadFileBytes, AFifoIsRefusedWithoutWaiting) {
  test::TempDir dir;
  const fs::path fifo = dir.path() / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto read = std::async(std::launch::async, [&] {
    return test::InputErrorOf([&] { (void)ReadFileBytes(fifo.string(), 1024); });
  });
  ASSERT_EQ(read.wait_for(std::chrono::seconds(10)), std::future_status::ready);
  EXPECT_EQ(read.get(), fifo.string() + ": is a FIFO (expected a regular file)");
  EXPECT_TRUE(test::ThrowsInputErrorWith([&] { (void)CheckInputFile(fifo.string(), 1024); },
                                         {"is a FIFO"}));
}

TEST(ReadFileBytes, DevicesAndFoldersAreRefusedByTheirType) {
  test::TempDir dir;
  EXPECT_TRUE(test::ThrowsInputErrorWith([] { (void)ReadFileBytes("/dev/zero", 1024); },
                                         {"/dev/zero: is a character device"}));
  EXPECT_TRUE(test::ThrowsInputErrorWith([&] { (void)ReadFileBytes(dir.path().string(), 1024); },
                                         {"is a directory"}));
  EXPECT_TRUE(
      test::ThrowsInputErrorWith([&] { (void)ReadFileBytes((dir.path() / "none").string(), 1024); },
                                 {"none: cannot be read (No such file or directory)"}));
}

// The budget is checked on the size before the allocation; a file of exactly the budget is read.
TEST(ReadFileBytes, AFileLargerThanItsBudgetIsRefusedByItsSize) {
  test::TempDir dir;
  const std::string path = test::WriteFile(dir, "f.yaml", std::string(2048, 'x'));
  EXPECT_EQ(ReadFileBytes(path, 2048).size(), 2048u);
  EXPECT_TRUE(test::ThrowsInputErrorWith([&] { (void)ReadFileBytes(path, 2047); },
                                         {"f.yaml: holds 2048 bytes, more than the 2047 bytes"}));
  EXPECT_EQ(CheckInputFile(path, 2048), 2048u);
}

TEST(ByteCount, IsExactBelowTenKibibytesAndThreeDigitsAbove) {
  EXPECT_EQ(ByteCount(1000), "1000 bytes");
  EXPECT_EQ(ByteCount(2047), "2047 bytes");
  EXPECT_EQ(ByteCount(20480), "20 KiB");
  EXPECT_EQ(ByteCount(std::uint64_t{384} << 20), "384 MiB");
  EXPECT_EQ(ByteCount(std::uint64_t{3} << 30), "3 GiB");
}

}  // namespace
}  // namespace sonarbench
