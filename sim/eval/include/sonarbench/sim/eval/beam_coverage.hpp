#pragma once

#include <octomap/OcTree.h>

#include <cstddef>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/beam_cells.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::sim {

/// The cells whose box meets one beam's volume W = {p : |azimuth| <= w_h/2, |elevation| <=
/// w_v/2, |p - origin| <= range} (azimuth and elevation in the beam's frame: the sonar frame
/// turned by the head angle), by a geometric test per candidate cell, independent of any ray
/// casting.
///
/// The elevation limits are cones, not planes, so W is bracketed by two polyhedral cones cut by
/// the sphere: inner |z| <= tan(w_v/2)·x and outer |z| <= tan(w_v/2)·x / cos(w_h/2) (within the
/// azimuth limits the horizontal distance lies between x and x / cos(w_h/2)), with the azimuth
/// limits as planes. A cell meeting the inner volume meets W (`inside`); a cell missing the outer
/// volume misses W; the cells between are `undecided` (at 3° they are at most a few per beam: the
/// two cones differ by 0.034%). Each test is exact: the point of (box ∩ cone) nearest the sonar,
/// found by enumerating the faces of that polytope, is within `range` or not.
struct WedgeCells {
  mapping::KeySet inside;
  mapping::KeySet undecided;
};
[[nodiscard]] WedgeCells ExactWedgeCells(const mapping::Beam& beam,
                                         const mapping::SensorGeometry& sensor, double range_m,
                                         const octomap::OcTree& key_space);

/// How well H x V ray casts (the mapper's CastBeam, with an obstacle at `range_m`) cover one
/// beam's exact volume.
struct BeamCoverage {
  std::size_t wedge_cells = 0;      ///< |inside|
  std::size_t undecided_cells = 0;  ///< |undecided|
  std::size_t visited_cells = 0;    ///< distinct cells the rays visit
  std::size_t covered_cells = 0;    ///< visited ∩ inside
  std::size_t visited_outside = 0;  ///< visited cells in neither set (0 unless rays stray)
  std::size_t visits = 0;           ///< cell visits, repeats included
  /// covered / wedge; and its bounds once the undecided cells are counted either way.
  double coverage = 0.0;
  double coverage_lower = 0.0;
  double coverage_upper = 0.0;
  /// visits / visited: the ray casts' redundancy.
  double visits_per_cell = 0.0;
};
[[nodiscard]] BeamCoverage MeasureBeamCoverage(const mapping::Beam& beam,
                                               const mapping::SensorGeometry& sensor,
                                               double range_m, int rays_horizontal,
                                               int rays_vertical, const octomap::OcTree& key_space);
/// The same against an already computed ExactWedgeCells(beam, sensor, range_m, key_space).
[[nodiscard]] BeamCoverage MeasureBeamCoverage(const mapping::Beam& beam,
                                               const mapping::SensorGeometry& sensor,
                                               double range_m, int rays_horizontal,
                                               int rays_vertical, const octomap::OcTree& key_space,
                                               const WedgeCells& wedge);
/// The same for the mapper's exact mode (ExactBeamCells with a detection at `range_m`): visits
/// are the cells it examined.
[[nodiscard]] BeamCoverage MeasureExactBeamCoverage(const mapping::Beam& beam,
                                                    const mapping::SensorGeometry& sensor,
                                                    double range_m,
                                                    const octomap::OcTree& key_space,
                                                    const WedgeCells& wedge);

}  // namespace sonarbench::sim
