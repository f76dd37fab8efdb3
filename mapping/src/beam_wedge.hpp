#pragma once

#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::mapping {

/// One beam's exact volume for the mapper's `exact` integration (docs/mapper.md, "Exact beam
/// volumes"). The wedge K is the cone through the sonar bounded by four planes: the azimuth
/// limits ±w_h/2 and the planes through the beam's four corner rays (azimuth ±w_h/2, elevation
/// ±w_v/2). K holds the true wedge {|azimuth| <= w_h/2, |elevation| <= w_v/2}; the two differ
/// by at most tan(w_v/2) (1/cos(w_h/2) - 1) of the range in elevation (0.6 mm at 5 m for the
/// Micron). Coordinates relative to the sonar's origin, world axes, metres.
class BeamWedge {
 public:
  BeamWedge(const SensorGeometry& sensor, const Beam& beam);

  /// The ranges |p| over the part of a cell inside K: the cell is the box centred at `centre`
  /// (relative to the origin) `half` wide each way. `meets` is false when the box misses K.
  struct Span {
    bool meets = false;
    double near = 0.0;
    double far = 0.0;
  };
  /// Exact (up to rounding): the box's faces clipped by K's planes.
  [[nodiscard]] Span CellSpan(const Eigen::Vector3d& centre, double half) const;

  [[nodiscard]] const Eigen::Vector3d& origin() const { return origin_; }
  /// Plane i (0-3): n·p <= 0 inside K.
  [[nodiscard]] const Eigen::Vector3d& normal(int i) const { return normals_[i]; }
  /// The cone's edge rays (unit vectors): index bit 0 set for elevation -w_v/2, bit 1 for
  /// azimuth -w_h/2.
  [[nodiscard]] const Eigen::Vector3d& edge(int i) const { return edges_[i]; }
  /// The beam's axis (head angle, elevation 0) and its elevation axis (the sonar's z): unit.
  [[nodiscard]] const Eigen::Vector3d& axis() const { return axis_; }
  [[nodiscard]] const Eigen::Vector3d& up() const { return up_; }

 private:
  Eigen::Vector3d origin_;
  Eigen::Vector3d normals_[4];
  Eigen::Vector3d edges_[4];
  Eigen::Vector3d axis_;
  Eigen::Vector3d up_;
};

/// What one beam marks under the exact semantics, for a beam whose detections lie at
/// `obstacle_ranges_m` (nearest first) and which clears out to `free_range_m` without one (0:
/// clears nothing). With [near, far] = the ranges of cell C's part inside K:
///   occupied  if some detection range r lies in [near, far] (C meets that range's shell in K);
///   free      otherwise, if far < r_1 (C's part in K lies wholly before the first detection), or,
///             without a detection, if near < free_range_m (the beam saw water there);
///   untouched otherwise (beyond the first detection, between shells, or outside K).
/// Appends packed keys (PackKey) to `free_keys` and `occupied_keys`, each cell once, and returns
/// the cells examined. Cells outside the tree's key range are left out.
struct WedgeCellCounts {
  std::size_t examined = 0;  ///< candidate cells classified
  std::size_t clipped = 0;   ///< of those, decided by clipping the cell's faces (CellSpan)
};
WedgeCellCounts ExactBeamCells(const octomap::OcTree& tree, const BeamWedge& wedge,
                               std::span<const double> obstacle_ranges_m, double free_range_m,
                               std::vector<std::uint64_t>& free_keys,
                               std::vector<std::uint64_t>& occupied_keys);

}  // namespace sonarbench::mapping
