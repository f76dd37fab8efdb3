#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/mesh.hpp"
#include "sonarbench/sim/scene.hpp"
#include "sonarbench/sim/score.hpp"

namespace sonarbench::sim {

struct RunOptions {
  /// Overrides the scene's seed.
  std::optional<std::uint64_t> seed;
  /// Threads for simulation and mapping; 0 = all. Outputs do not depend on it.
  int threads = 0;
  /// Called after each sweep of a long stage ("simulate", "map") with sweeps done and total.
  std::function<void(std::string_view stage, std::size_t done, std::size_t total)> progress;
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
  /// The sonar's position at the first beam [m], where the side slice of the map is cut.
  Eigen::Vector3d sonar_start_m = Eigen::Vector3d::Zero();
  /// Each mesh's name, triangle count and preflight findings, in scene order, then the
  /// vehicle's parts'.
  struct MeshSummary {
    std::string name;
    std::size_t triangles = 0;
    MeshCheck check;
    bool vehicle_part = false;
  };
  std::vector<MeshSummary> meshes;
  /// The metrics against the scene's criteria.
  Verdict verdict;
};

/// Simulates the scene, maps every sweep, builds the ground truth and scores the map.
[[nodiscard]] ScenarioResult RunScenario(const Scene& scene, const RunOptions& options);

}  // namespace sonarbench::sim
