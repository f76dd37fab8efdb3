#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sonarbench::sim {

/// The sonar's pose and head angle for one beam.
struct BeamPose {
  Eigen::Isometry3d T_world_sonar = Eigen::Isometry3d::Identity();
  double head_angle_rad = 0.0;
};

/// Exact triangle / axis-aligned box overlap (separating axis theorem, Akenine-Möller 2001).
/// Touching counts as overlapping, so a surface on a cell face marks both cells.
[[nodiscard]] bool TriangleBoxOverlap(const Eigen::Vector3d& box_centre,
                                      const Eigen::Vector3d& box_half_size,
                                      const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                      const Eigen::Vector3d& c);

/// Exact distance [m] from `p` to the triangle a, b, c (Ericson, Real-Time Collision Detection,
/// 5.1.5).
[[nodiscard]] double PointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                           const Eigen::Vector3d& b, const Eigen::Vector3d& c);

}  // namespace sonarbench::sim
