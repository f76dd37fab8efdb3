#include "sonarbench/sim/app/simulated_scene.hpp"

#include <algorithm>

#include "sonarbench/sim/app/detector_study.hpp"

namespace sonarbench::sim {
namespace {

// Each bin's path with the most power; noise where the bin holds none.
std::vector<std::uint8_t> DominantPaths(const SynthesizedBeam& beam) {
  std::vector<std::uint8_t> paths(beam.labels.size(), static_cast<std::uint8_t>(EchoPath::kNoise));
  for (std::size_t k = 0; k < paths.size(); ++k) {
    const auto& energy = beam.labels[k].energy;
    const auto most = std::max_element(energy.begin(), energy.end());
    if (*most > 0.0F) paths[k] = static_cast<std::uint8_t>(most - energy.begin());
  }
  return paths;
}

}  // namespace

SimulatedScene SimulateForScoring(const Scene& scene, const std::vector<TriangleMesh>& meshes,
                                  const RayTracer& tracer, std::uint64_t seed, int threads,
                                  const std::optional<std::pair<double, double>>& heads_deg) {
  SimulatedScene s;
  s.synthesized =
      SimulateScene(scene, tracer, seed, threads, {}, [&](std::span<const SynthesizedBeam> sweep) {
        for (const SynthesizedBeam& beam : sweep) s.bin_paths.push_back(DominantPaths(beam));
      });
  s.beams = BeamsOf(s.synthesized);
  const octomap::OcTree key_space(scene.mapping.resolution_m);
  s.truth = VoxelizeMeshes(meshes, key_space);
  std::vector<BeamPose> poses;
  for (std::size_t b = 0; b < s.synthesized.size(); ++b) {
    const BeamPose pose = ScheduleBeam(scene, b).pose;
    if (!heads_deg || InHeads(pose.head_angle_rad, *heads_deg)) poses.push_back(pose);
  }
  s.observable = PerfectSensorCells(tracer, poses, scene.sensor.geometry, scene.sensor.acoustics,
                                    key_space, {}, &s.direct);
  return s;
}

}  // namespace sonarbench::sim
