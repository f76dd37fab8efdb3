#include "sonarbench/sim/app/scenario.hpp"

#include <omp.h>

#include <chrono>

#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/sonar/scene_world.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"

namespace sonarbench::sim {
namespace {

class Stopwatch {
 public:
  double Lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace

ScenarioResult RunScenario(const Scene& scene, const RunOptions& options) {
  ScenarioResult result;
  result.seed = options.seed.value_or(scene.seed);
  result.threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  Stopwatch clock;

  const SceneWorld world(scene);
  for (const TriangleMesh& mesh : world.meshes)
    result.meshes.push_back({mesh.name, mesh.triangles.size(), mesh.check});
  for (const TriangleMesh& part : BuildVehicleMeshes(scene))
    result.meshes.push_back({part.name, part.triangles.size(), part.check, true});
  result.timings.build_scene_s = clock.Lap();

  auto report = [&](std::string_view stage) {
    return [&options, stage](std::size_t done, std::size_t total) {
      if (options.progress) options.progress(stage, done, total);
    };
  };
  // The labels' direct echoes, a check of the score's geometric ones (MapMetrics).
  const auto& g = scene.sensor.geometry;
  DirectEchoes labelled = DirectEchoesOf(g, 0.5 * std::sqrt(3.0) * scene.mapping.resolution_m);
  const auto take_labels = [&](std::span<const SynthesizedBeam> sweep) {
    for (const SynthesizedBeam& beam : sweep) {
      labelled.beams.push_back(
          LabelledDirectBeam({beam.truth.T_world_sonar, beam.beam.head_angle_rad}, beam.labels,
                             g.bin_size_m, labelled.tolerance_m));
    }
  };
  const std::vector<SynthesizedBeam> synthesized = SimulateScene(
      scene, world.tracer, result.seed, result.threads, report("simulate"), take_labels);
  result.beams = synthesized.size();
  result.timings.simulate_s = clock.Lap();

  mapping::MapperConfig mapper_config = scene.mapping;
  mapper_config.threads = result.threads;
  result.mapper = std::make_unique<mapping::Mapper>(mapper_config, scene.sensor.geometry);
  const std::vector<mapping::Beam> beams = BeamsOf(synthesized);
  result.mapping_totals = result.mapper->IntegrateSweeps(beams, report("map"));
  const auto per_sweep = static_cast<std::size_t>(scene.sensor.geometry.BeamsPerSweep());
  result.first_sweep.assign(beams.begin(),
                            beams.begin() + static_cast<long>(std::min(per_sweep, beams.size())));
  result.timings.map_s = clock.Lap();

  const std::vector<BeamPose> poses = TruePoses(scene, synthesized.size());
  if (!poses.empty()) result.sonar_start_m = poses.front().T_world_sonar.translation();
  result.score = ScoreAgainstScene(result.mapper->tree(), scene, world.meshes, world.tracer, poses,
                                   scene.sensor.geometry, options.progress, &labelled);
  result.timings.ground_truth_s = result.score.ground_truth_s;
  result.timings.score_s = result.score.score_s;
  return result;
}

}  // namespace sonarbench::sim
