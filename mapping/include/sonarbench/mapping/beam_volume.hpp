#pragma once

#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <span>
#include <unordered_set>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::mapping {

using KeySet = std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash>;

/// The H×V ray directions that sample a beam's volume, in the sonar frame, for head angle 0:
/// horizontal offsets evenly spaced over [-w_h/2, +w_h/2] and elevations over [-w_v/2, +w_v/2],
/// both edges included (a single ray sits on the axis). Rotate about z by the head angle.
[[nodiscard]] std::vector<Eigen::Vector3d> BeamRayDirections(const SensorGeometry& sensor,
                                                             int rays_horizontal,
                                                             int rays_vertical);

/// The cells one beam marks. Occupied cells are the cells of each ray's end point at an obstacle
/// range, so the ends lie on the true spherical wedge (|end - origin| = range exactly); free cells
/// are those each ray crosses before the first obstacle (or out to `free_range_m` without one).
struct BeamCells {
  KeySet free;
  KeySet occupied;
};

/// Adds to `cells` the keys of one beam with obstacles at `obstacle_ranges_m` (nearest first).
/// `directions` are from BeamRayDirections; `free_range_m` applies only when there is no obstacle
/// (0 = clear nothing). Occupied does not yet win over free here: see ResolveConflicts.
void CastBeam(const octomap::OcTree& tree, const Beam& beam,
              std::span<const Eigen::Vector3d> directions,
              std::span<const double> obstacle_ranges_m, double free_range_m, BeamCells& cells);

/// Occupied wins over free within one update: removes from `cells.free` every occupied key.
void ResolveConflicts(BeamCells& cells);

}  // namespace sonarbench::mapping
