#pragma once

#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <functional>
#include <span>

#include "sonarbench/mapping/detail/beam_volume.hpp"
#include "sonarbench/sim/world/geometry.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/ray_tracer.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

namespace sonarbench::sim {

/// Called as a long stage goes: work done and the stage's total, in the stage's own units.
using StageProgress = std::function<void(std::size_t done, std::size_t total)>;

/// Every cell of `key_space`'s grid whose box the surface of a mesh crosses (cells half-open, as
/// OctoMap assigns points), and, for a mesh with `fill`, every cell whose centre lies inside it.
/// Meshes that are not `truth` (the water surface) add nothing.
/// `progress` counts triangles and, for filled meshes, rows of cells.
[[nodiscard]] mapping::KeySet VoxelizeMeshes(std::span<const TriangleMesh> meshes,
                                             const octomap::OcTree& key_space,
                                             const StageProgress& progress = {});

/// Cells a perfect sensor with the same beams, poses and range could see: the cell of the first
/// surface along each ray of a dense regular rays_h × rays_v grid across every beam's full
/// aperture. Rays that leave the scene or pass the maximum range see no cell.
[[nodiscard]] mapping::KeySet ObservableSurfaceCells(const RayTracer& tracer,
                                                     std::span<const BeamPose> beams,
                                                     const mapping::SensorGeometry& sensor,
                                                     int rays_horizontal, int rays_vertical,
                                                     const octomap::OcTree& key_space,
                                                     const StageProgress& progress = {});

/// ObservableSurfaceCells as every score takes it: a perfect sensor, with rays twice as dense in
/// each direction as the synthesis samples a beam (`acoustics`).
[[nodiscard]] mapping::KeySet PerfectSensorCells(const RayTracer& tracer,
                                                 std::span<const BeamPose> beams,
                                                 const mapping::SensorGeometry& sensor,
                                                 const Acoustics& acoustics,
                                                 const octomap::OcTree& key_space,
                                                 const StageProgress& progress = {});

}  // namespace sonarbench::sim
