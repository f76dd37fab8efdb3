#pragma once

#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "sonarbench/mapping/beam_cells.hpp"
#include "sonarbench/sim/sonar/bin_labels.hpp"
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

/// The ranges at which each distinct beam (pose and head angle) meets a surface directly: the
/// first hits of its rays on any mesh, truth or not. An echo a perfect detector would report
/// lies at one of them, somewhere on its arc. Ranges are kept as intervals widened on both sides
/// by `tolerance_m`: a cell's half-diagonal plus one range bin, how far from the shell a cell the
/// mapper marks for that echo may lie.
struct DirectEchoes {
  struct Beam {
    Eigen::Vector3d origin;         ///< the sonar [m, world]
    Eigen::Matrix3d world_to_head;  ///< world → the head's frame (x along the beam, z up)
    std::vector<std::pair<double, double>> ranges;  ///< widened, sorted, disjoint [m]
  };
  std::vector<Beam> beams;
  double half_width_horizontal_rad = 0.0;
  double half_width_vertical_rad = 0.0;
  double tolerance_m = 0.0;

  /// Whether a beam's aperture holds the cell centred at `centre` [m, world] (its direction,
  /// widened by the cell's angular radius seen from the sonar) at a range one of that beam's
  /// direct echoes explains.
  [[nodiscard]] bool Explains(const Eigen::Vector3d& centre, double cell_half_diagonal_m) const;
};

/// No beams yet, the apertures of `sensor`'s beams and `tolerance_m` [m].
[[nodiscard]] DirectEchoes DirectEchoesOf(const mapping::SensorGeometry& sensor,
                                          double tolerance_m);

/// A beam's direct echoes as the simulator's labels name them: the bins a main-lobe return of a
/// scene surface is heard in (BinLabel::mesh), each widened by `tolerance_m` on both sides. Its
/// pose is `pose`'s. Add it to a DirectEchoes whose widths and tolerance are the sensor's.
[[nodiscard]] DirectEchoes::Beam LabelledDirectBeam(const BeamPose& pose,
                                                    std::span<const BinLabel> labels,
                                                    double bin_size_m, double tolerance_m);

/// Cells a perfect sensor with the same beams, poses and range could see: the cell of the first
/// surface along each ray of a dense regular rays_h × rays_v grid across every beam's full
/// aperture. Rays that leave the scene or pass the maximum range see no cell. With `direct`,
/// the same rays' first hits fill it (its tolerance from the key space's resolution and the
/// sensor's bin).
[[nodiscard]] mapping::KeySet ObservableSurfaceCells(
    const RayTracer& tracer, std::span<const BeamPose> beams, const mapping::SensorGeometry& sensor,
    int rays_horizontal, int rays_vertical, const octomap::OcTree& key_space,
    const StageProgress& progress = {}, DirectEchoes* direct = nullptr);

/// ObservableSurfaceCells as every score takes it: a perfect sensor, with rays twice as dense in
/// each direction as the synthesis samples a beam (`acoustics`).
[[nodiscard]] mapping::KeySet PerfectSensorCells(
    const RayTracer& tracer, std::span<const BeamPose> beams, const mapping::SensorGeometry& sensor,
    const Acoustics& acoustics, const octomap::OcTree& key_space,
    const StageProgress& progress = {}, DirectEchoes* direct = nullptr);

}  // namespace sonarbench::sim
