#include "sonarbench/sim/sonar/simulation.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>
#include <stdexcept>
#include <string>

#include "sonarbench/sim/world/random.hpp"

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
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  out.pose.head_angle_rad = std::remainder(angle - std::numbers::pi, kTwoPi) + std::numbers::pi;
  // remainder() is at most π in size, and π + π rounds to 2π itself: a full turn is 0.
  if (out.pose.head_angle_rad >= kTwoPi) out.pose.head_angle_rad = 0.0;
  out.pose.T_world_sonar = scene.trajectory.T_world_vehicle(out.time_s) * g.T_vehicle_sonar;
  return out;
}

Eigen::Isometry3d ReportedSonarPose(const Scene& scene, std::size_t index, double time_s,
                                    std::uint64_t seed) {
  const Eigen::Isometry3d T_world_vehicle = scene.trajectory.T_world_vehicle(time_s);
  const NavigationError& nav = scene.navigation;
  if (!nav.Any()) return T_world_vehicle * scene.sensor.geometry.T_vehicle_sonar;
  // Its own stream of draws, apart from the beam's acoustic noise.
  Rng rng(DeriveSeed(DeriveSeed(seed, 0x6e6176ULL), index));
  Eigen::Vector3d offset(nav.drift_m_per_s[0], nav.drift_m_per_s[1], nav.drift_m_per_s[2]);
  offset *= time_s;
  for (int i = 0; i < 3; ++i) offset[i] += nav.position_noise_m * rng.Normal();
  const double yaw = nav.heading_drift_rad_per_s * time_s + nav.heading_noise_rad * rng.Normal();
  Eigen::Isometry3d reported = T_world_vehicle;
  reported.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                      T_world_vehicle.linear();
  reported.translation() += offset;
  return reported * scene.sensor.geometry.T_vehicle_sonar;
}

BeamSynthesizer SceneSynthesizer(const Scene& scene, const RayTracer& tracer, std::uint64_t seed) {
  std::vector<Material> materials_by_mesh;
  for (const MeshSpec& mesh : scene.meshes)
    materials_by_mesh.push_back(scene.materials[mesh.material]);
  VehicleParts vehicle{.meshes = BuildVehicleMeshes(scene), .materials = {}};
  for (const MeshSpec& part : scene.vehicle)
    vehicle.materials.push_back(scene.materials[part.material]);
  return BeamSynthesizer(scene.sensor, tracer, std::move(materials_by_mesh), seed, vehicle);
}

std::vector<SynthesizedBeam> SimulateBeams(const Scene& scene, const BeamSynthesizer& synthesizer,
                                           std::uint64_t seed, int threads, std::size_t first,
                                           std::size_t last, Labels labels) {
  std::vector<SynthesizedBeam> beams;
  SimulateBeamsInto(scene, synthesizer, seed, threads, first, last, labels, beams);
  return beams;
}

void SimulateBeamsInto(const Scene& scene, const BeamSynthesizer& synthesizer, std::uint64_t seed,
                       int threads, std::size_t first, std::size_t last, Labels labels,
                       std::vector<SynthesizedBeam>& beams) {
  if (first > last) {
    throw std::invalid_argument("SimulateBeams: beams [" + std::to_string(first) + ", " +
                                std::to_string(last) + ") run backwards");
  }
  beams.resize(last - first);
  const int n_threads = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for num_threads(n_threads) schedule(dynamic, 8)
  for (std::int64_t b = 0; b < static_cast<std::int64_t>(beams.size()); ++b) {
    const std::size_t index = first + static_cast<std::size_t>(b);
    const ScheduledBeam s = ScheduleBeam(scene, index);
    SynthesizedBeam& out = beams[static_cast<std::size_t>(b)];
    synthesizer.SynthesizeInto(s.time_s, s.pose.head_angle_rad, s.pose.T_world_sonar,
                               DeriveSeed(seed, index), EchoPower::kDrop, labels, out);
    out.beam.T_world_sonar = ReportedSonarPose(scene, index, s.time_s, seed);
  }
}

std::vector<SynthesizedBeam> SimulateScene(
    const Scene& scene, const RayTracer& tracer, std::uint64_t seed, int threads,
    const std::function<void(std::size_t done, std::size_t total)>& on_sweep,
    const std::function<void(std::span<const SynthesizedBeam>)>& on_labels) {
  const std::size_t count = ScenarioBeamCount(scene);
  const auto per_sweep = static_cast<std::size_t>(scene.sensor.geometry.BeamsPerSweep());
  const auto sweeps = static_cast<std::size_t>(scene.sweeps);
  const BeamSynthesizer synthesizer = SceneSynthesizer(scene, tracer, seed);
  std::vector<SynthesizedBeam> beams;
  beams.reserve(count);
  std::vector<SynthesizedBeam> part;  // one sweep's, its labels' memory kept for the next
  for (std::size_t sweep = 0; sweep < sweeps; ++sweep) {
    SimulateBeamsInto(scene, synthesizer, seed, threads, sweep * per_sweep,
                      std::min(count, (sweep + 1) * per_sweep),
                      on_labels ? Labels::kKeep : Labels::kDrop, part);
    if (on_labels) on_labels(part);
    for (SynthesizedBeam& b : part) {
      beams.push_back({.beam = std::move(b.beam),
                       .truth = b.truth,
                       .echo_power = std::move(b.echo_power),
                       .labels = {},
                       .traced_rays = b.traced_rays});
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
