#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "sonarbench/base/error.hpp"

namespace sonarbench::test {

/// A fresh directory under the system temp dir, removed when the test ends.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("sonarbench-" + std::string(info->test_suite_name()) + "-" + info->name() + "-" +
             std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// The message of the InputError `f` throws, or "" when it throws none.
inline std::string InputErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// Writes `text` byte for byte to the file `name` in `dir`; returns its path.
inline std::string WriteFile(const TempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = (dir.path() / name).string();
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

inline std::string SourcePath(const std::string& relative) {
  return std::string(SONARBENCH_SOURCE_DIR) + "/" + relative;
}

/// Success when `f` throws an InputError whose message holds every one of `parts`.
template <typename F>
::testing::AssertionResult ThrowsInputErrorWith(F&& f, const std::vector<std::string>& parts) {
  try {
    f();
  } catch (const InputError& e) {
    const std::string message = e.what();
    for (const auto& part : parts) {
      if (message.find(part) == std::string::npos) {
        return ::testing::AssertionFailure() << "message lacks \"" << part << "\"; message was:\n"
                                             << message;
      }
    }
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "no InputError thrown";
}

/// The real tank log, which ships in the repository (data/cras-tank-static/README.md).
inline std::string RealLogPath() { return SourcePath("data/cras-tank-static/dataset_static.mat"); }

}  // namespace sonarbench::test

/// Fails the test (rather than skipping it) when the real log is missing from the checkout.
#define REQUIRE_REAL_LOG()                                                \
  ASSERT_TRUE(std::filesystem::exists(::sonarbench::test::RealLogPath())) \
      << ::sonarbench::test::RealLogPath()
