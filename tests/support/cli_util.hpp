#pragma once

// Running the sonarbench command line as a user (or CI) does, for the tests of its commands.

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace sonarbench::test {

/// `sonarbench ARGUMENTS`, stdout and stderr together into `output`; its exit status.
inline int RunCli(const std::string& arguments, std::string* output = nullptr) {
  const std::string command = std::string(SONARBENCH_CLI) + " " + arguments + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  std::string text;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) text += buffer;
  const int status = ::pclose(pipe);
  if (output != nullptr) *output = text;
  return WEXITSTATUS(status);
}

/// The whole of a text file ("" when it cannot be read).
inline std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace sonarbench::test
