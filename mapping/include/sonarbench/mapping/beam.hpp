#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace sonarbench::mapping {

/// One ping of a mechanical scanning sonar. A simulated beam and a beam imported from a real log
/// are the same type, so the mapper cannot tell them apart.
struct Beam {
  /// Time of the ping [s] since the start of the run or log.
  double time_s = 0.0;
  /// Head (bearing) angle [rad] about the sonar frame's z axis; 0 looks along the sonar's x axis.
  double head_angle_rad = 0.0;
  /// Pose of the sonar frame (head angle 0) in the world frame at `time_s`.
  Eigen::Isometry3d T_world_sonar = Eigen::Isometry3d::Identity();
  /// Range covered by one bin [m]; bin k spans [k, k+1) * bin_size_m.
  double bin_size_m = 0.0;
  /// Echo intensity per range bin, bin 0 at the transducer, 8-bit like the Micron's output.
  std::vector<std::uint8_t> intensities;

  /// Range of the centre of bin `bin` [m].
  [[nodiscard]] double BinCentreRange(std::size_t bin) const {
    return (static_cast<double>(bin) + 0.5) * bin_size_m;
  }
};

/// The beams of one revolution (or sector) of the head, in time order.
using Sweep = std::vector<Beam>;

/// Unit direction, in the sonar frame, of a ray at head angle `theta` [rad] and elevation
/// `epsilon` [rad]: (cos θ cos ε, sin θ cos ε, sin ε).
[[nodiscard]] inline Eigen::Vector3d SonarRayDirection(double theta, double epsilon) {
  return {std::cos(theta) * std::cos(epsilon), std::sin(theta) * std::cos(epsilon),
          std::sin(epsilon)};
}

}  // namespace sonarbench::mapping
