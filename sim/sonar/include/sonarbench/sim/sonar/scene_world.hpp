#pragma once

#include <cstddef>
#include <vector>

#include "sonarbench/sim/world/geometry.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/ray_tracer.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// A scene's world as the simulator and the scorer see it, built once per command: the scene's
/// meshes (world frame; a mesh's index is its Embree geometry id) and the ray tracer over them.
struct SceneWorld {
  /// Builds the meshes (BuildSceneMeshes: budgets checked, each mesh's preflight; InputError for
  /// bad input) and the tracer.
  explicit SceneWorld(const Scene& scene);
  SceneWorld(const SceneWorld&) = delete;
  SceneWorld& operator=(const SceneWorld&) = delete;

  const std::vector<TriangleMesh> meshes;
  const RayTracer tracer;
};

/// The sonar's true poses at beams [0, count) of the scene's run (ScheduleBeam), in time order.
[[nodiscard]] std::vector<BeamPose> TruePoses(const Scene& scene, std::size_t count);

}  // namespace sonarbench::sim
