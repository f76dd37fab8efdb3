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

SensorGeometry ReadSensorGeometry(YamlReader& node) {
  SensorGeometry g;
  double width_h_deg = g.beam_width_horizontal_rad / kDegToRad;
  double width_v_deg = g.beam_width_vertical_rad / kDegToRad;
  double step_deg = g.step_angle_rad / kDegToRad;
  node.Required("beam_width_horizontal_deg", width_h_deg, InRange(0.1, 90.0));
  node.Required("beam_width_vertical_deg", width_v_deg, InRange(0.1, 90.0));
  node.Required("num_bins", g.num_bins, IntInRange(1, 100000));
  node.Required("bin_size_m", g.bin_size_m, Positive());
  node.Required("step_angle_deg", step_deg, InRange(0.01, 180.0));
  node.Required("beams_per_second", g.beams_per_second, Positive());
  node.Required("self_reflection_range_m", g.self_reflection_range_m, NonNegative());
  if (auto mounting = node.OptionalChild("mounting")) {
    std::array<double, 3> position{0, 0, 0};
    std::array<double, 3> rpy_deg{0, 0, 0};
    mounting->Optional("position_m", position);
    mounting->Optional("rpy_deg", rpy_deg);
    mounting->RejectUnknownKeys();
    g.T_vehicle_sonar =
        PoseFromXyzRpy({position[0], position[1], position[2]},
                       Eigen::Vector3d(rpy_deg[0], rpy_deg[1], rpy_deg[2]) * kDegToRad);
  }
  node.RejectUnknownKeys();
  g.beam_width_horizontal_rad = width_h_deg * kDegToRad;
  g.beam_width_vertical_rad = width_v_deg * kDegToRad;
  g.step_angle_rad = step_deg * kDegToRad;
  if (g.self_reflection_range_m >= g.MaxRangeM()) {
    node.Fail("self_reflection_range_m", "a range below num_bins * bin_size_m");
  }
  return g;
}

}  // namespace sonarbench::mapping
