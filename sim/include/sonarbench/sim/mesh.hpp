#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "sonarbench/sim/scene.hpp"

namespace sonarbench::sim {

/// A triangle soup in the world frame.
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::size_t material = 0;
};

/// Builds the world-frame triangles of a procedural mesh. `seed` drives height-field roughness.
[[nodiscard]] TriangleMesh BuildMesh(const MeshSpec& spec, std::uint64_t seed);

/// Builds every mesh of a scene, in scene order (the index is the Embree geometry id).
[[nodiscard]] std::vector<TriangleMesh> BuildSceneMeshes(const Scene& scene);

}  // namespace sonarbench::sim
