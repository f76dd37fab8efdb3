#pragma once

#include <Eigen/Geometry>
#include <numbers>

namespace sonarbench::mapping {

constexpr double kDegToRad = std::numbers::pi / 180.0;

/// Pose from a position [m] and roll, pitch, yaw [rad] (rotation R = Rz(yaw) Ry(pitch) Rx(roll)).
[[nodiscard]] Eigen::Isometry3d PoseFromXyzRpy(const Eigen::Vector3d& position_m,
                                               const Eigen::Vector3d& rpy_rad);

/// What the mapper needs to know of the sonar: the beam's shape, the range bins, the head's
/// stepping and the mounting on the vehicle. Defaults are the SHAD AUV's Tritech Micron.
struct SensorGeometry {
  /// Full horizontal beam width [rad] (the -3 dB width of the main lobe).
  double beam_width_horizontal_rad = 3.0 * kDegToRad;
  /// Full vertical beam width [rad].
  double beam_width_vertical_rad = 35.0 * kDegToRad;
  /// Number of range bins per beam.
  int num_bins = 399;
  /// Range covered by one bin [m].
  double bin_size_m = 0.012531;
  /// Head rotation between consecutive beams [rad].
  double step_angle_rad = 1.8 * kDegToRad;
  /// Ping rate [beams/s].
  double beams_per_second = 23.5;
  /// Bins closer than this range [m] carry self-reflections of the vehicle and are discarded.
  /// The real log's mean falls from ≈105 (bins 7-19) to its tail level ≈20 by bin 28 (0.35 m).
  double self_reflection_range_m = 0.35;
  /// Pose of the sonar frame (head angle 0) in the vehicle frame.
  Eigen::Isometry3d T_vehicle_sonar = Eigen::Isometry3d::Identity();

  /// Maximum range [m]: the far edge of the last bin.
  [[nodiscard]] double MaxRangeM() const { return num_bins * bin_size_m; }
  /// Beams in one full 360° revolution of the head.
  [[nodiscard]] int BeamsPerSweep() const;
  /// Index of the first bin at or beyond the self-reflection range.
  [[nodiscard]] int FirstUsableBin() const;
};

}  // namespace sonarbench::mapping
