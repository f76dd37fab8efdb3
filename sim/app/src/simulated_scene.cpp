#include "sonarbench/sim/app/simulated_scene.hpp"

#include "sonarbench/sim/app/detector_study.hpp"

namespace sonarbench::sim {
namespace {

// Each bin's path with the most power (io::DominantPath).
std::vector<std::uint8_t> DominantPaths(const SynthesizedBeam& beam) {
  std::vector<std::uint8_t> paths;
  paths.reserve(beam.labels.size());
  for (const BinLabel& label : beam.labels) {
    paths.push_back(static_cast<std::uint8_t>(io::DominantPath(label.energy)));
  }
  return paths;
}

}  // namespace

ObservedCells ObservedFrom(const Scene& scene, const SceneWorld& world, std::size_t beams,
                           const std::optional<std::pair<double, double>>& heads_deg) {
  std::vector<BeamPose> poses = TruePoses(scene, beams);
  if (heads_deg) {
    std::erase_if(poses, [&](const BeamPose& p) { return !InHeads(p.head_angle_rad, *heads_deg); });
  }
  const octomap::OcTree key_space(scene.mapping.resolution_m);
  ObservedCells seen;
  seen.observable = PerfectSensorCells(world.tracer, poses, scene.sensor.geometry,
                                       scene.sensor.acoustics, key_space, {}, &seen.direct);
  return seen;
}

SimulatedScene SimulateForScoring(const Scene& scene, const SceneWorld& world, std::uint64_t seed,
                                  int threads,
                                  const std::optional<std::pair<double, double>>& heads_deg) {
  SimulatedScene s;
  s.synthesized = SimulateScene(scene, world.tracer, seed, threads, {},
                                [&](std::span<const SynthesizedBeam> sweep) {
                                  for (const SynthesizedBeam& beam : sweep)
                                    s.bin_paths.push_back(DominantPaths(beam));
                                });
  s.beams = BeamsOf(s.synthesized);
  const octomap::OcTree key_space(scene.mapping.resolution_m);
  s.truth = VoxelizeMeshes(world.meshes, key_space);
  ObservedCells seen = ObservedFrom(scene, world, s.synthesized.size(), heads_deg);
  s.observable = std::move(seen.observable);
  s.direct = std::move(seen.direct);
  return s;
}

}  // namespace sonarbench::sim
