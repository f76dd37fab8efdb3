#include "sonarbench/mapping/sensor_geometry.hpp"

#include <cmath>

namespace sonarbench::mapping {

Eigen::Isometry3d PoseFromXyzRpy(const Eigen::Vector3d& position_m,
                                 const Eigen::Vector3d& rpy_rad) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = (Eigen::AngleAxisd(rpy_rad.z(), Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(rpy_rad.y(), Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(rpy_rad.x(), Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  pose.translation() = position_m;
  return pose;
}

int SensorGeometry::BeamsPerSweep() const {
  return static_cast<int>(std::lround(2.0 * std::numbers::pi / step_angle_rad));
}

int SensorGeometry::FirstUsableBin() const {
  return static_cast<int>(std::ceil(self_reflection_range_m / bin_size_m - 1e-9));
}

}  // namespace sonarbench::mapping
