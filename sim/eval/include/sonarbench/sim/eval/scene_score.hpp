#pragma once

#include <octomap/OcTree.h>

#include <functional>
#include <span>
#include <string_view>

#include "sonarbench/mapping/beam_cells.hpp"
#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/eval/verdict.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/ray_tracer.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// A map scored against a scene: what `run`, `score` and `map --scene` report.
struct SceneScore {
  mapping::KeySet truth;               ///< the scene's surface cells, at the map's resolution
  mapping::KeySet observable;          ///< those a perfect sensor sees from the beams' poses
  DirectEchoes direct;                 ///< the beams' direct echoes
  mapping::KeySet detector_ghosts;     ///< the ghosts no direct echo explains
  std::vector<TriangleMesh> surfaces;  ///< the truth's meshes (world frame), for the 3D view
  MapMetrics metrics;
  Verdict verdict;              ///< the metrics against the scene's criteria
  double ground_truth_s = 0.0;  ///< wall-clock time of truth and observable cells [s]
  double score_s = 0.0;         ///< of the metrics [s]
};

/// Called after each pass of a stage ("truth", "observable", "score") with passes done and total.
using ScoreProgress =
    std::function<void(std::string_view stage, std::size_t done, std::size_t total)>;

/// Scores `map` against `scene` the one way every command does: the scene's `meshes` voxelised at
/// the map's resolution, the cells a perfect sensor sees from the beams at `poses` with the
/// beams' geometry `sensor` (PerfectSensorCells over `tracer`, built from `meshes`), ScoreMap,
/// and the scene's criteria. With `labelled` (a simulated run's LabelledDirectBeam), the ghosts
/// are split by it too (MapMetrics::labelled_ghost_split).
[[nodiscard]] SceneScore ScoreAgainstScene(const octomap::OcTree& map, const Scene& scene,
                                           std::span<const TriangleMesh> meshes,
                                           const RayTracer& tracer, std::span<const BeamPose> poses,
                                           const mapping::SensorGeometry& sensor,
                                           const ScoreProgress& progress = {},
                                           const DirectEchoes* labelled = nullptr);

}  // namespace sonarbench::sim
