#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sonarbench/sim/eval/scenario_result.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

struct RunOptions {
  /// Overrides the scene's seed.
  std::optional<std::uint64_t> seed;
  /// Threads for simulation and mapping; 0 = all. Outputs do not depend on it.
  int threads = 0;
  /// Called after each sweep of a long stage ("simulate", "map") with sweeps done and total.
  std::function<void(std::string_view stage, std::size_t done, std::size_t total)> progress;
};

/// Simulates the scene, maps every sweep, builds the ground truth and scores the map.
[[nodiscard]] ScenarioResult RunScenario(const Scene& scene, const RunOptions& options);

}  // namespace sonarbench::sim
