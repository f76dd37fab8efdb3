#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/version.hpp"

namespace sonarbench::sim {

/// sonarbench's version: CMake's project(VERSION).
inline constexpr const char* kVersion = io::kVersion;

/// The fields every JSON report starts with: its schema version and the tool that wrote it.
[[nodiscard]] inline nlohmann::json ReportHeader() {
  return {{"schema_version", 1}, {"tool", {{"name", "sonarbench"}, {"version", kVersion}}}};
}

/// {name: sha256} of each of `files` in `dir`: what a report covers, for a reader to check.
[[nodiscard]] inline nlohmann::json FilesSha256(const std::string& dir,
                                                const std::vector<std::string>& files) {
  nlohmann::json hashes = nlohmann::json::object();
  for (const std::string& file : files) hashes[file] = io::Sha256OfFile(dir + "/" + file);
  return hashes;
}

/// Writes `report` as indented JSON to `path`, atomically.
inline void WriteJson(const std::string& path, const nlohmann::json& report) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << report.dump(2) << "\n"; });
}

}  // namespace sonarbench::sim
