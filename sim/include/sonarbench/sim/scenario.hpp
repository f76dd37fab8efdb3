#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/scene.hpp"
#include "sonarbench/sim/score.hpp"

namespace sonarbench::sim {

struct RunOptions {
  /// Overrides the scene's seed.
  std::optional<std::uint64_t> seed;
  /// Threads for simulation and mapping; 0 = all. Outputs do not depend on it.
  int threads = 0;
};

/// Wall-clock time of each stage of a run [s].
struct StageTimings {
  double build_scene_s = 0.0;
  double simulate_s = 0.0;
  double map_s = 0.0;
  double ground_truth_s = 0.0;
  double score_s = 0.0;
};

/// Everything a scenario run produced.
struct ScenarioResult {
  std::uint64_t seed = 0;
  int threads = 0;
  std::size_t beams = 0;
  StageTimings timings;
  mapping::BatchStats mapping_totals;
  MapMetrics metrics;
  std::unique_ptr<mapping::Mapper> mapper;
  /// The first sweep's beams, for images.
  std::vector<mapping::Beam> first_sweep;
  mapping::KeySet truth;
  mapping::KeySet observable;
};

/// Simulates the scene, maps every sweep, builds the ground truth and scores the map.
[[nodiscard]] ScenarioResult RunScenario(const Scene& scene, const RunOptions& options);

/// Writes `report.json`, `map.bt`, `polar.png`, `fan.png` and `map_top.png` into `out_dir`
/// (created if needed); each file is written atomically, the report last.
void WriteScenarioOutputs(const std::string& out_dir, const Scene& scene,
                          const ScenarioResult& result);

}  // namespace sonarbench::sim
