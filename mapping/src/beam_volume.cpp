#include "beam_volume.hpp"

namespace sonarbench::mapping {
namespace {

// Evenly spaced samples over [-width/2, +width/2], both edges included; one sample sits on 0.
double Offset(int i, int count, double width) {
  if (count == 1) return 0.0;
  return -0.5 * width + width * static_cast<double>(i) / static_cast<double>(count - 1);
}

}  // namespace

std::vector<Eigen::Vector3d> BeamRayDirections(const SensorGeometry& sensor, int rays_horizontal,
                                               int rays_vertical) {
  std::vector<Eigen::Vector3d> directions;
  directions.reserve(static_cast<std::size_t>(rays_horizontal) * rays_vertical);
  // Horizontal neighbours (0.1° apart for 32 rays over 3°) cross nearly the same cells, so they
  // come one after another: the mapper's recently-inserted filter then catches their repeats.
  for (int j = 0; j < rays_vertical; ++j) {
    const double epsilon = Offset(j, rays_vertical, sensor.beam_width_vertical_rad);
    for (int i = 0; i < rays_horizontal; ++i) {
      const double theta = Offset(i, rays_horizontal, sensor.beam_width_horizontal_rad);
      directions.push_back(SonarRayDirection(theta, epsilon));
    }
  }
  return directions;
}

BeamKeys RayCastBeamKeys(const octomap::OcTree& tree, const Beam& beam,
                         std::span<const Eigen::Vector3d> directions,
                         std::span<const double> obstacle_ranges_m, double free_range_m) {
  BeamCells cells;
  CastBeam(tree, beam, directions, obstacle_ranges_m, free_range_m, cells);
  return {std::move(cells.free), std::move(cells.occupied), cells.visits};
}

BeamKeys ExactBeamKeys(const octomap::OcTree& tree, const SensorGeometry& sensor, const Beam& beam,
                       std::span<const double> obstacle_ranges_m, double free_range_m) {
  std::vector<std::uint64_t> free, occupied;
  const WedgeCellCounts counts = ExactBeamCells(tree, BeamWedge(sensor, beam), obstacle_ranges_m,
                                                free_range_m, free, occupied);
  BeamKeys keys;
  for (const std::uint64_t packed : free) keys.free.insert(UnpackKey(packed));
  for (const std::uint64_t packed : occupied) keys.occupied.insert(UnpackKey(packed));
  keys.visits = counts.examined;
  return keys;
}

}  // namespace sonarbench::mapping
