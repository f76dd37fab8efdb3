#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "sonarbench/mapping/atomic_file.hpp"

namespace sonarbench::sim {

/// The fields every JSON report starts with: its schema version and the tool that wrote it.
[[nodiscard]] inline nlohmann::json ReportHeader() {
  return {{"schema_version", 1}, {"tool", {{"name", "sonarbench"}, {"version", "0.1.0"}}}};
}

/// Writes `report` as indented JSON to `path`, atomically.
inline void WriteJson(const std::string& path, const nlohmann::json& report) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << report.dump(2) << "\n"; });
}

}  // namespace sonarbench::sim
