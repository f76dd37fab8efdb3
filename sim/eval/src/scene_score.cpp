#include "sonarbench/sim/eval/scene_score.hpp"

#include <chrono>

namespace sonarbench::sim {

SceneScore ScoreAgainstScene(const octomap::OcTree& map, const Scene& scene,
                             std::span<const TriangleMesh> meshes, const RayTracer& tracer,
                             std::span<const BeamPose> poses, const mapping::SensorGeometry& sensor,
                             const ScoreProgress& progress, const DirectEchoes* labelled) {
  auto stage = [&progress](std::string_view name) -> StageProgress {
    if (!progress) return {};
    return [&progress, name](std::size_t done, std::size_t total) { progress(name, done, total); };
  };
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point since) {
    return std::chrono::duration<double>(Clock::now() - since).count();
  };
  auto start = Clock::now();
  SceneScore s;
  s.truth = VoxelizeMeshes(meshes, map, stage("truth"));
  s.observable = PerfectSensorCells(tracer, poses, sensor, scene.sensor.acoustics, map,
                                    stage("observable"), &s.direct);
  s.ground_truth_s = seconds(start);
  start = Clock::now();
  s.metrics =
      ScoreMap(map, s.truth, s.observable, meshes, stage("score"), &s.direct, &s.detector_ghosts);
  if (labelled) s.metrics.labelled_ghost_split = SplitGhostsBy(map, s.truth, *labelled);
  s.verdict = Evaluate(scene.criteria, s.metrics);
  s.score_s = seconds(start);
  for (const TriangleMesh& mesh : meshes) {
    if (mesh.truth) s.surfaces.push_back(mesh);
  }
  return s;
}

}  // namespace sonarbench::sim
