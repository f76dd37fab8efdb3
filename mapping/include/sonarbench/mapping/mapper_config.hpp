#pragma once

#include <limits>
#include <string>

namespace sonarbench::mapping {

/// How obstacles are found along a beam. See detection.hpp.
struct DetectionConfig {
  enum class Method {
    kThreshold,  ///< runs of bins over an intensity threshold (the paper's earlier work)
    kCanny,      ///< rising Canny edges on the sweep's polar image (the paper, section 4)
    kAutoCanny,  ///< Canny with thresholds from the image's median (the paper's future work)
    kCaCfar,     ///< cell-averaging CFAR along range: a bin above its training bins' mean power
                 ///< times the factor its false-alarm probability sets (docs/mapper.md, "CFAR")
    kOsCfar,     ///< ordered-statistic CFAR: the same over the training bins' k-th smallest
  };
  /// kCaCfar, kOsCfar: the constant-false-alarm-rate detector along each beam's range bins.
  struct Cfar {
    /// Bins left out each side of the bin under test (the echo's own spread) [bins].
    int guard_bins = 2;
    /// Bins each side of the guard bins whose power estimates the background [bins].
    int training_bins = 12;
    /// Probability that a bin of exponentially distributed (Rayleigh-envelope) noise passes.
    double false_alarm = 1e-3;
    /// kOsCfar: the order statistic k as a share of the training bins (Rohling's 3/4).
    double order = 0.75;
    /// The intensity's scale [dB per count]: power = 10^(count · this / 10). The Micron's
    /// converter spans 40 dB over 255 counts.
    double db_per_count = 40.0 / 255.0;

    bool operator==(const Cfar&) const = default;
  };
  Method method = Method::kThreshold;
  /// kThreshold: intensity [0-255] at or above which a bin belongs to an obstacle. 70 sits above
  /// the real tank log's floor returns (mean 25-50) and under its walls' (60-88 where oblique,
  /// 100-175 facing the sonar).
  int threshold = 70;
  /// kThreshold: width of the moving average applied along range first [bins, odd].
  int smoothing_bins = 3;
  /// kThreshold, kCaCfar, kOsCfar: a run of bins at or above the threshold must be this long to
  /// count [bins].
  int min_run_bins = 2;
  /// Obstacles reported per beam: 1 is the paper's "first obstacle"; more add the strongest of
  /// the later echoes (by peak intensity). 2 maps a wall behind a weaker object or the floor.
  int max_obstacles = 2;
  /// Which later echoes (after a beam's first) may be reported.
  enum class LaterEchoes {
    kStrongest,  ///< any: the strongest (the paper)
    kSupported,  ///< only those that a beam within `support_window_deg` hears as its first echo
                 ///< within `support_range_m`: a surface seen directly around a nearer object
  };
  LaterEchoes later_echoes = LaterEchoes::kStrongest;
  /// Whether echoes heard behind a wall are kept: kRefuse drops every echo more than a margin
  /// behind the walls (vertical, seen from above) that the batch's first echoes outline along
  /// the beam's bearing, and sets aside a beam that loses all (docs/mapper.md).
  enum class BehindWalls { kKeep, kRefuse };
  BehindWalls behind_walls = BehindWalls::kKeep;
  /// kSupported: head-angle distance [deg] within which a beam supports another's later echo.
  double support_window_deg = 9.0;
  /// kSupported: how close [m] the supporting beam's first echo must be to the later echo.
  double support_range_m = 0.1;
  /// kCanny: hysteresis thresholds on the gradient magnitude (L2, 3×3 Sobel) [intensity/pixel].
  double canny_low = 60.0;
  double canny_high = 150.0;
  /// kCanny, kAutoCanny: standard deviation of the Gaussian blur (5×5) applied first [pixels].
  double canny_blur_sigma = 1.4;
  /// kAutoCanny: thresholds are (1 ∓ sigma) · median of the blurred image's usable bins.
  double auto_canny_sigma = 0.33;
  Cfar cfar;

  bool operator==(const DetectionConfig&) const = default;
};

/// The key set the mapper collects cells in; the map does not depend on it.
enum class KeySetKind {
  kBlocks,          ///< BlockKeySet: 8³-cell bit blocks, merged block by block
  kOpenAddressing,  ///< sonarbench's OpenKeySet (quadratic probing, all-at-once resize)
  kStd,             ///< std::unordered_set with OctoMap's KeyHash (OctoMap's KeySet)
};

/// How a beam's volume becomes cells (docs/mapper.md).
enum class Integration {
  kRays,   ///< rays_horizontal × rays_vertical ray casts (the seed paper)
  kExact,  ///< every cell that meets the beam's wedge, examined once (BeamWedge)
};

/// How a detection's shell becomes occupancy (docs/mapper.md, "Arc evidence").
enum class Occupancy {
  kArcMarking,   ///< every cell of the shell in the wedge gets the full hit (the seed paper)
  kArcEvidence,  ///< each gets a share, by the vertical beam pattern and what the map knows
};

/// The water's extent along the world's z axis [m]: its surface (the vehicle's depth gauge) and a
/// flat floor (its altimeter), each infinite when unknown. No echo comes from beyond them, so no
/// cell wholly above the surface or below the floor is marked occupied (docs/mapper.md, "The
/// water column").
struct WaterColumn {
  double floor_z_m = -std::numeric_limits<double>::infinity();
  double surface_z_m = std::numeric_limits<double>::infinity();

  bool operator==(const WaterColumn&) const = default;
};

/// Parameters of the production mapper. In-class defaults are the seed paper's choices, but for
/// `integration` and `key_set`.
struct MapperConfig {
  /// Edge of an OctoMap leaf cell [m].
  double resolution_m = 0.05;
  /// kExact unless the seed paper's ray casts are asked for: on every shipped scene and the real
  /// log its maps' recall and coverage are the 32 × 64 rays' or better (docs/mapper.md).
  Integration integration = Integration::kExact;
  /// Ray casts across the beam's horizontal width (the paper's H; 32 by its study).
  int rays_horizontal = 32;
  /// Ray casts across the beam's vertical width (the paper's V; 64 by its study).
  int rays_vertical = 64;
  DetectionConfig detection;
  Occupancy occupancy = Occupancy::kArcMarking;
  WaterColumn water;
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
  /// kBlocks: the fastest in pipeline_bench, rays and exact alike (docs/benchmarks.md).
  KeySetKind key_set = KeySetKind::kBlocks;
};

}  // namespace sonarbench::mapping
