#pragma once

#include <span>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::mapping {

/// Threshold detection (the seed paper's earlier work): the bins before the self-reflection range
/// are discarded, the rest are smoothed with a moving average, and each run of at least
/// `min_run_bins` bins at or above `threshold` is an echo whose range [m] is the centre of the
/// run's first bin (the echo of a surface starts at its range; the pulse extends it behind).
/// Returns up to `max_obstacles` ranges, nearest first: the first run, then the runs with the
/// highest peaks. Empty if the beam saw nothing. One beam has no neighbours: `later_echoes` is
/// applied by DetectObstacles only.
[[nodiscard]] std::vector<double> DetectThreshold(const Beam& beam, const SensorGeometry& sensor,
                                                  const DetectionConfig& config);

/// Canny detection (the seed paper, section 4) on the polar image of `beams` (one row per beam,
/// one column per bin; the self-reflection bins are blanked): a 5×5 Gaussian blur, OpenCV's
/// Canny with an L2 gradient, and of its edges only the rising ones along range (the near side
/// of an echo). Per beam, the first edge and then the strongest (by blurred intensity) up to
/// `max_obstacles`. kAutoCanny takes the thresholds from the median of the blurred usable bins.
[[nodiscard]] std::vector<std::vector<double>> DetectCanny(std::span<const Beam> beams,
                                                           const SensorGeometry& sensor,
                                                           const DetectionConfig& config);

/// The obstacle ranges [m] of every beam of a batch, by the configured method. With
/// `behind_walls` kRefuse, echoes behind the walls the batch's first echoes outline are dropped
/// (docs/mapper.md); `heard_through_walls`, when given, is set to whether each beam lost every
/// echo so. With `later_echoes` kSupported a later echo is kept only if another beam of the batch
/// within `support_window_deg` of head angle has its first echo within `support_range_m` of it.
[[nodiscard]] std::vector<std::vector<double>> DetectObstacles(
    std::span<const Beam> beams, const SensorGeometry& sensor, const DetectionConfig& config,
    std::vector<bool>* heard_through_walls = nullptr);

}  // namespace sonarbench::mapping
