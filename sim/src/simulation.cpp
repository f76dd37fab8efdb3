#include "sonarbench/sim/simulation.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "sonarbench/sim/random.hpp"

namespace sonarbench::sim {

std::size_t ScenarioBeamCount(const Scene& scene) {
  return static_cast<std::size_t>(scene.sweeps) *
         static_cast<std::size_t>(scene.sensor.geometry.BeamsPerSweep());
}

ScheduledBeam ScheduleBeam(const Scene& scene, std::size_t index) {
  const mapping::SensorGeometry& g = scene.sensor.geometry;
  ScheduledBeam out;
  out.time_s = static_cast<double>(index) / g.beams_per_second;
  const double angle = scene.start_head_angle_rad + static_cast<double>(index) * g.step_angle_rad;
  out.pose.head_angle_rad = std::remainder(angle - std::numbers::pi, 2.0 * std::numbers::pi) +
                            std::numbers::pi;  // in [0, 2π)
  out.pose.T_world_sonar = scene.trajectory.T_world_vehicle(out.time_s) * g.T_vehicle_sonar;
  return out;
}

std::vector<SynthesizedBeam> SimulateScene(
    const Scene& scene, const RayTracer& tracer, std::uint64_t seed, int threads,
    const std::function<void(std::size_t done, std::size_t total)>& on_sweep) {
  std::vector<Material> materials_by_mesh;
  for (const MeshSpec& mesh : scene.meshes)
    materials_by_mesh.push_back(scene.materials[mesh.material]);
  const BeamSynthesizer synthesizer(scene.sensor, tracer, std::move(materials_by_mesh));
  const std::size_t count = ScenarioBeamCount(scene);
  std::vector<SynthesizedBeam> beams(count);
  const int n_threads = threads > 0 ? threads : omp_get_max_threads();
  const auto per_sweep = static_cast<std::size_t>(scene.sensor.geometry.BeamsPerSweep());
  const auto sweeps = static_cast<std::size_t>(scene.sweeps);
  for (std::size_t sweep = 0; sweep < sweeps; ++sweep) {
    const auto first = static_cast<std::int64_t>(sweep * per_sweep);
    const auto last = static_cast<std::int64_t>(std::min(count, (sweep + 1) * per_sweep));
#pragma omp parallel for num_threads(n_threads) schedule(dynamic, 8)
    for (std::int64_t b = first; b < last; ++b) {
      const auto index = static_cast<std::size_t>(b);
      const ScheduledBeam s = ScheduleBeam(scene, index);
      beams[index] = synthesizer.Synthesize(s.time_s, s.pose.head_angle_rad, s.pose.T_world_sonar,
                                            DeriveSeed(seed, index));
    }
    if (on_sweep) on_sweep(sweep + 1, sweeps);
  }
  return beams;
}

std::vector<mapping::Beam> BeamsOf(std::span<const SynthesizedBeam> synthesized) {
  std::vector<mapping::Beam> beams;
  beams.reserve(synthesized.size());
  for (const SynthesizedBeam& s : synthesized) beams.push_back(s.beam);
  return beams;
}

}  // namespace sonarbench::sim
