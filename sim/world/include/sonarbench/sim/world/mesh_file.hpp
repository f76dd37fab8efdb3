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
/// Throws InputError naming the file when it cannot be read (a FIFO, device or directory is
/// refused by its type; a file over kMaxMeshFileBytes by its size), holds no triangle, or holds
/// more than `max_triangles` (counted from the file before Assimp builds anything).
[[nodiscard]] MeshFileData LoadMeshFile(const std::string& path, double max_triangles = 2e7);

/// The largest mesh file read (bytes).
inline constexpr std::uint64_t kMaxMeshFileBytes = std::uint64_t{1} << 30;
/// Corners of one polygon (OBJ and PLY faces): Assimp triangulates one in quadratic time.
inline constexpr double kMaxPolygonCorners = 1024;

}  // namespace sonarbench::sim
