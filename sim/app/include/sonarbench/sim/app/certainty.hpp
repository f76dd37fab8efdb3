#pragma once

#include <octomap/OcTree.h>

#include <span>
#include <string>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/beam_cells.hpp"
#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::sim {

/// How certain the map grows sweep by sweep (the seed paper's figure 12): the cells the final map
/// holds occupied, split into those on a surface (in the truth) and the others (false), and their
/// mean occupancy probability after each sweep (a cell not yet updated counts at the prior, 0.5).
struct CertaintyCurve {
  std::size_t true_cells = 0;
  std::size_t false_cells = 0;
  /// One value a sweep, sweep 1 first.
  std::vector<double> true_mean;
  std::vector<double> false_mean;
};

/// Maps `beams` again from an empty map, sweep by sweep, and reads the probability of
/// `final_map`'s occupied leaf cells after each sweep. The last values are `final_map`'s own.
[[nodiscard]] CertaintyCurve SweepCertainty(std::span<const mapping::Beam> beams,
                                            const mapping::SensorGeometry& sensor,
                                            const mapping::MapperConfig& config,
                                            const octomap::OcTree& final_map,
                                            const mapping::KeySet& truth);

/// certainty.csv: `sweep,true_cells,true_mean_probability,false_cells,false_mean_probability`.
[[nodiscard]] std::string CertaintyCsv(const CertaintyCurve& curve);

}  // namespace sonarbench::sim
