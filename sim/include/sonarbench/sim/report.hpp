#pragma once

#include <nlohmann/json.hpp>

namespace sonarbench::sim {

/// The fields every JSON report starts with: its schema version and the tool that wrote it.
[[nodiscard]] inline nlohmann::json ReportHeader() {
  return {{"schema_version", 1}, {"tool", {{"name", "sonarbench"}, {"version", "0.1.0"}}}};
}

}  // namespace sonarbench::sim
