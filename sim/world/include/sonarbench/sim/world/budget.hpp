#pragma once

#include <Eigen/Geometry>
#include <span>
#include <string>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::sim {

struct Scene;

/// What one run may build, checked from the scene before anything is allocated. The command
/// line's --max-triangles, --max-cells and --max-beams raise them.
struct Budgets {
  /// Triangles of every mesh and vehicle part (Embree and the meshes take ~100 bytes each).
  double max_triangles = 2e7;
  /// Cells of the ground truth, and of the map (OctoMap takes ~20-80 bytes a cell).
  double max_cells = 1e8;
  /// Beams of the trajectory, sweeps x beams per sweep (a run holds each, ~600 bytes).
  double max_beams = 2e6;
};

/// The estimates a budget is checked against.
struct SceneEstimate {
  double triangles = 0.0;
  /// Surface area / resolution², plus volume / resolution³ for filled meshes.
  double truth_cells = 0.0;
  /// The volume the sonar's beams sweep (its range around the trajectory's box) / resolution³.
  double map_cells = 0.0;
};

/// The scene's estimate; mesh files count as loaded (their triangles are in the scene).
[[nodiscard]] SceneEstimate EstimateScene(const Scene& scene);

/// Throws InputError naming the scene file and the key (a mesh's cell_m or scale, the mapping's
/// resolution_m), the estimate and the limit, and the option that raises it.
void CheckBudgets(const Scene& scene, const Budgets& budgets);

/// Cells a map of `resolution_m` can hold when the sonar stays within the box [lo, hi] and its
/// beams reach `range_m`: the box grown by that range, over the cell volume.
[[nodiscard]] double MapCellsEstimate(const mapping::SensorGeometry& sensor, double range_m,
                                      double resolution_m, const Eigen::Vector3d& lo,
                                      const Eigen::Vector3d& hi);

/// Throws InputError when `estimate` map cells exceed `budgets.max_cells`; `what` names the input.
void CheckMapCells(double estimate, const Budgets& budgets, const std::string& what);

/// Throws InputError (naming `what` and --max-cells) when a map of `beams` at `resolution_m` would
/// hold more than `budgets.max_cells` cells: their poses' box grown by the longest beam's reach.
void CheckBeamsMapCells(std::span<const mapping::Beam> beams, const mapping::SensorGeometry& sensor,
                        double resolution_m, const Budgets& budgets, const std::string& what);

}  // namespace sonarbench::sim
