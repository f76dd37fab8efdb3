#pragma once

// Scenes and checks the command-line tests share.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli_util.hpp"
#include "test_util.hpp"

namespace sonarbench::test {

// A one-sweep copy of the tank scene with the given criteria section, in `dir`.
inline std::filesystem::path TankSceneWithCriteria(const std::filesystem::path& dir,
                                                   const std::string& criteria) {
  std::string text = ReadFile(SourcePath("scenes/cras-tank.yaml"));
  auto replace_line = [&](const std::string& key, const std::string& line) {
    const auto at = text.find("\n" + key);
    ASSERT_NE(at, std::string::npos) << key;
    text.replace(at + 1, text.find('\n', at + 1) - at - 1, line);
  };
  replace_line("sweeps:", "sweeps: 1");
  replace_line("sensor_model:", "sensor_model: " + SourcePath("sensor-models/shad-micron.yaml"));
  const auto at = text.find("\ncriteria:");
  if (at != std::string::npos) text.erase(at + 1);
  const auto path = dir / "tank.yaml";
  std::ofstream(path) << text << "\n" << criteria;
  return path;
}

// Exit status of xmllint on `file`, or -1 when xmllint is not installed.
inline int XmlLint(const std::filesystem::path& file) {
  if (std::system("command -v xmllint > /dev/null 2>&1") != 0) return -1;
  return WEXITSTATUS(std::system(("xmllint --noout " + file.string()).c_str()));
}

}  // namespace sonarbench::test
