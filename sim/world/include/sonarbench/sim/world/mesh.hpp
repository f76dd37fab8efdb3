#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// What the preflight found in a mesh (see CheckMesh).
struct MeshCheck {
  std::size_t zero_area_triangles = 0;  ///< dropped
  std::size_t boundary_edges = 0;       ///< edges of one triangle: the mesh is open
  std::size_t non_manifold_edges = 0;   ///< edges of three or more triangles
};

/// A triangle soup in the world frame.
struct TriangleMesh {
  std::string name;
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::size_t material = 0;
  /// Its inside counts as occupied truth too (a closed mesh: checked by BuildSceneMeshes).
  bool fill = false;
  /// Scored as ground truth (see MeshSpec::truth); the simulator traces every mesh.
  bool truth = true;
  MeshCheck check;
};

/// Triangles below this area [m²] (a 4.5 µm square) count as zero-area.
inline constexpr double kMinTriangleAreaM2 = 1e-11;

/// The preflight of a mesh: throws InputError (prefixed with `where`) for a non-finite vertex or a
/// mesh left without a triangle; drops zero-area triangles; counts open and non-manifold edges
/// (vertices welded by exact position). Open meshes are fine for surfaces (a seabed, a tank open
/// at the top) and are reported, not refused.
MeshCheck CheckMesh(TriangleMesh& mesh, const std::string& where);

/// Builds the world-frame triangles of a procedural mesh. `seed` drives height-field roughness.
[[nodiscard]] TriangleMesh BuildMesh(const MeshSpec& spec, std::uint64_t seed);

/// Builds every mesh of a scene, in scene order (the index is the Embree geometry id), each
/// checked by CheckMesh, once the scene's estimate is within its budgets (CheckBudgets).
[[nodiscard]] std::vector<TriangleMesh> BuildSceneMeshes(const Scene& scene);

/// Builds the scene's vehicle parts (Scene::vehicle) as BuildSceneMeshes does, in the vehicle's
/// body frame.
[[nodiscard]] std::vector<TriangleMesh> BuildVehicleMeshes(const Scene& scene);

}  // namespace sonarbench::sim
