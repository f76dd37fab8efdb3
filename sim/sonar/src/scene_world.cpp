#include "sonarbench/sim/sonar/scene_world.hpp"

#include "sonarbench/sim/sonar/simulation.hpp"

namespace sonarbench::sim {

SceneWorld::SceneWorld(const Scene& scene) : meshes(BuildSceneMeshes(scene)), tracer(meshes) {}

std::vector<BeamPose> TruePoses(const Scene& scene, std::size_t count) {
  std::vector<BeamPose> poses;
  poses.reserve(count);
  for (std::size_t b = 0; b < count; ++b) poses.push_back(ScheduleBeam(scene, b).pose);
  return poses;
}

}  // namespace sonarbench::sim
