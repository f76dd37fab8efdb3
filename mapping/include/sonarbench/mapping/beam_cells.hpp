#pragma once

#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <unordered_set>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::mapping {

/// A set of map cells: the standard library's set with OctoMap's key hash (OctoMap's KeySet).
using KeySet = std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash>;

/// The H×V ray directions that sample a beam's volume, in the sonar frame, for head angle 0:
/// horizontal offsets evenly spaced over [-w_h/2, +w_h/2] and elevations over [-w_v/2, +w_v/2],
/// both edges included (a single ray sits on the axis). Rotate about z by the head angle.
[[nodiscard]] std::vector<Eigen::Vector3d> BeamRayDirections(const SensorGeometry& sensor,
                                                             int rays_horizontal,
                                                             int rays_vertical);

/// The cells one beam marks, in the key space of `tree` (its resolution and origin).
struct BeamKeys {
  KeySet free;
  KeySet occupied;
  std::size_t visits = 0;  ///< cell visits by all rays (rays), or cells examined (exact)
};

/// One beam's cells by ray casts along `directions` (BeamRayDirections), the seed paper's way:
/// free before the first of `obstacle_ranges_m` (nearest first), occupied at each range, or
/// free out to `free_range_m` without an obstacle (0 clears nothing). A cell may be in both sets:
/// the mapper lets occupied win when it integrates.
[[nodiscard]] BeamKeys RayCastBeamKeys(const octomap::OcTree& tree, const Beam& beam,
                                       std::span<const Eigen::Vector3d> directions,
                                       std::span<const double> obstacle_ranges_m,
                                       double free_range_m);

/// One beam's cells under the mapper's exact integration (docs/mapper.md, "Exact beam volumes"):
/// every cell meeting the beam's wedge, examined once, free wholly before the first obstacle,
/// occupied where an obstacle's shell meets it.
[[nodiscard]] BeamKeys ExactBeamKeys(const octomap::OcTree& tree, const SensorGeometry& sensor,
                                     const Beam& beam, std::span<const double> obstacle_ranges_m,
                                     double free_range_m);

}  // namespace sonarbench::mapping
