#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sonarbench/mapping/batch_stats.hpp"
#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/eval/scene_score.hpp"
#include "sonarbench/sim/world/mesh.hpp"

namespace sonarbench::sim {

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
  std::unique_ptr<mapping::Mapper> mapper;
  /// The first sweep's beams, for images.
  std::vector<mapping::Beam> first_sweep;
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
  /// The map scored against the scene.
  SceneScore score;
};

}  // namespace sonarbench::sim
