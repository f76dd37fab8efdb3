#include "sonarbench/mapping/beam_volume.hpp"

namespace sonarbench::mapping {
namespace {

// Evenly spaced samples over [-width/2, +width/2], both edges included; one sample sits on 0.
double Offset(int i, int count, double width) {
  if (count == 1) return 0.0;
  return -0.5 * width + width * static_cast<double>(i) / static_cast<double>(count - 1);
}

octomap::point3d ToPoint(const Eigen::Vector3d& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

}  // namespace

std::vector<Eigen::Vector3d> BeamRayDirections(const SensorGeometry& sensor, int rays_horizontal,
                                               int rays_vertical) {
  std::vector<Eigen::Vector3d> directions;
  directions.reserve(static_cast<std::size_t>(rays_horizontal) * rays_vertical);
  for (int i = 0; i < rays_horizontal; ++i) {
    const double theta = Offset(i, rays_horizontal, sensor.beam_width_horizontal_rad);
    for (int j = 0; j < rays_vertical; ++j) {
      const double epsilon = Offset(j, rays_vertical, sensor.beam_width_vertical_rad);
      directions.push_back(SonarRayDirection(theta, epsilon));
    }
  }
  return directions;
}

void CastBeam(const octomap::OcTree& tree, const Beam& beam,
              std::span<const Eigen::Vector3d> directions,
              std::span<const double> obstacle_ranges_m, double free_range_m, BeamCells& cells) {
  const double free_end_m = obstacle_ranges_m.empty() ? free_range_m : obstacle_ranges_m.front();
  if (obstacle_ranges_m.empty() && free_end_m <= 0.0) return;
  const Eigen::Matrix3d R_world_beam =
      beam.T_world_sonar.linear() *
      Eigen::AngleAxisd(beam.head_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d origin = beam.T_world_sonar.translation();
  const octomap::point3d origin_point = ToPoint(origin);
  octomap::KeyRay ray;
  for (const Eigen::Vector3d& direction : directions) {
    const Eigen::Vector3d d_world = R_world_beam * direction;
    // computeRayKeys gives the cells crossed before the end point's cell, which stays for the
    // occupied update (or, without an obstacle, for the next beam).
    if (tree.computeRayKeys(origin_point, ToPoint(origin + free_end_m * d_world), ray)) {
      cells.free.insert(ray.begin(), ray.end());
    }
    for (const double range : obstacle_ranges_m) {
      octomap::OcTreeKey key;
      if (tree.coordToKeyChecked(ToPoint(origin + range * d_world), key)) {
        cells.occupied.insert(key);
      }
    }
  }
}

void ResolveConflicts(BeamCells& cells) {
  for (const auto& key : cells.occupied) cells.free.erase(key);
}

}  // namespace sonarbench::mapping
