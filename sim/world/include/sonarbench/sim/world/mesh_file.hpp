#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace sonarbench::sim {

/// The triangles of a mesh file, in the file's own frame and units (metres expected; COLLADA's
/// <unit> is applied).
struct MeshFileData {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// Loads every mesh of an OBJ, STL, PLY or COLLADA (.dae) file with Assimp: polygons
/// triangulated, node transforms applied, points and lines ignored. COLLADA's up_axis is ignored
/// (sonarbench's world is z-up, like Gazebo's; rotate a y-up file with the scene's rpy_deg).
/// Throws InputError naming the file when it cannot be read or holds no triangle.
[[nodiscard]] MeshFileData LoadMeshFile(const std::string& path);

}  // namespace sonarbench::sim
