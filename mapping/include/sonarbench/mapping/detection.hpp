#pragma once

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
/// highest peaks. Empty if the beam saw nothing.
[[nodiscard]] std::vector<double> DetectThreshold(const Beam& beam, const SensorGeometry& sensor,
                                                  const DetectionConfig& config);

}  // namespace sonarbench::mapping
