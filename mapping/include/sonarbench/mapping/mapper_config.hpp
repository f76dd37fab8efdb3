#pragma once

#include <string>

#include "sonarbench/mapping/yaml_reader.hpp"

namespace sonarbench::mapping {

/// How obstacles are found along a beam. See detection.hpp.
struct DetectionConfig {
  /// Intensity [0-255] at or above which a bin belongs to an obstacle.
  int threshold = 90;
  /// Width of the moving average applied along range before thresholding [bins, odd].
  int smoothing_bins = 3;
  /// A run of bins at or above the threshold must be this long to count [bins].
  int min_run_bins = 2;
  /// Obstacles reported per beam: 1 is the paper's "first obstacle"; more add the strongest of
  /// the later runs (by peak intensity).
  int max_obstacles = 1;
};

/// Parameters of the production mapper. In-class defaults are the seed paper's choices.
struct MapperConfig {
  /// Edge of an OctoMap leaf cell [m].
  double resolution_m = 0.05;
  /// Ray casts across the beam's horizontal width (the paper's H; 32 by its study).
  int rays_horizontal = 32;
  /// Ray casts across the beam's vertical width (the paper's V; 64 by its study).
  int rays_vertical = 64;
  DetectionConfig detection;
  /// OctoMap hit / miss probabilities and clamping thresholds.
  double prob_hit = 0.7;
  double prob_miss = 0.4;
  double clamp_min = 0.12;
  double clamp_max = 0.97;
  /// Whether a beam with no obstacle clears free space out to `free_range_m`.
  bool clear_without_obstacle = true;
  /// Range [m] a beam without an obstacle clears; 0 means the sensor's maximum range.
  double free_range_m = 0.0;
  /// Worker threads for ray casting; 0 means all hardware threads. The map does not depend on it.
  int threads = 0;
};

/// Reads a `mapping` mapping of a scene file.
[[nodiscard]] MapperConfig ReadMapperConfig(YamlReader& node);

}  // namespace sonarbench::mapping
