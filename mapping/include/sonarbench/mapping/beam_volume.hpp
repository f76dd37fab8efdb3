#pragma once

#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <span>
#include <unordered_set>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/key_set.hpp"
#include "sonarbench/mapping/ray_keys.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::mapping {

/// The standard library's set with OctoMap's key hash: OctoMap's own `KeySet`.
using KeySet = std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash>;

/// The H×V ray directions that sample a beam's volume, in the sonar frame, for head angle 0:
/// horizontal offsets evenly spaced over [-w_h/2, +w_h/2] and elevations over [-w_v/2, +w_v/2],
/// both edges included (a single ray sits on the axis). Rotate about z by the head angle.
[[nodiscard]] std::vector<Eigen::Vector3d> BeamRayDirections(const SensorGeometry& sensor,
                                                             int rays_horizontal,
                                                             int rays_vertical);

/// The cells a batch of beams marks, in a set type `Set` with `insert(key)`, `erase(key)` and
/// iteration (std::unordered_set, OpenKeySet, absl::flat_hash_set, ...).
template <typename Set>
struct BasicBeamCells {
  Set free;
  Set occupied;
  /// Cell visits by all rays, repeats included (the paper's section 3.2 redundancy).
  std::size_t visits = 0;
  /// The free keys inserted last, direct-mapped by hash: neighbouring rays of a beam cross the
  /// same cells in the same order, so most repeats are caught here, in L1, before the set.
  std::array<std::uint64_t, 2048> recent_free = MakeEmptyRecent();

  /// Inserts a free key (packed) unless the filter saw it (then the set already holds it).
  void InsertFree(std::uint64_t packed) {
    std::uint64_t& slot = recent_free[(packed * 0x9e3779b97f4a7c15ULL) >> 53];
    if (slot == packed) return;
    slot = packed;
    if constexpr (requires(Set & s) { s.insert_packed(packed); }) {
      free.insert_packed(packed);
    } else {
      free.insert(UnpackKey(packed));
    }
  }

 private:
  static std::array<std::uint64_t, 2048> MakeEmptyRecent() {
    std::array<std::uint64_t, 2048> a;
    a.fill(~std::uint64_t{0});  // no packed key is all ones
    return a;
  }
};
using BeamCells = BasicBeamCells<KeySet>;

/// Adds to `cells` the keys of one beam with obstacles at `obstacle_ranges_m` (nearest first).
/// Occupied cells are the cells of each ray's end point at an obstacle range, so the ends lie on
/// the true spherical wedge (|end - origin| = range exactly; the seed's code put them up to 4.4%
/// too far at the edges); free cells are those each ray crosses before the first obstacle, or
/// out to `free_range_m` without one (0 = clear nothing). `directions` are from
/// BeamRayDirections. Occupied does not yet win over free here: see ResolveConflicts.
template <typename Set>
void CastBeam(const octomap::OcTree& tree, const Beam& beam,
              std::span<const Eigen::Vector3d> directions,
              std::span<const double> obstacle_ranges_m, double free_range_m,
              BasicBeamCells<Set>& cells) {
  const double free_end_m = obstacle_ranges_m.empty() ? free_range_m : obstacle_ranges_m.front();
  if (obstacle_ranges_m.empty() && free_end_m <= 0.0) return;
  const Eigen::Matrix3d R_world_beam =
      beam.T_world_sonar.linear() *
      Eigen::AngleAxisd(beam.head_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d origin = beam.T_world_sonar.translation();
  auto to_point = [](const Eigen::Vector3d& v) {
    return octomap::point3d(static_cast<float>(v.x()), static_cast<float>(v.y()),
                            static_cast<float>(v.z()));
  };
  const octomap::point3d origin_point = to_point(origin);
  for (const Eigen::Vector3d& direction : directions) {
    const Eigen::Vector3d d_world = R_world_beam * direction;
    // The cells crossed before the end point's cell, which is left for the occupied update (or,
    // without an obstacle, for the next beam).
    ForEachRayKey(tree, origin_point, to_point(origin + free_end_m * d_world),
                  [&cells](std::uint64_t packed) {
                    ++cells.visits;
                    cells.InsertFree(packed);
                  });
    for (const double range : obstacle_ranges_m) {
      octomap::OcTreeKey key;
      if (tree.coordToKeyChecked(to_point(origin + range * d_world), key)) {
        cells.occupied.insert(key);
        ++cells.visits;
      }
    }
  }
}

/// Occupied wins over free within one update: removes from `cells.free` every occupied key.
template <typename Set>
void ResolveConflicts(BasicBeamCells<Set>& cells) {
  for (const auto& key : cells.occupied) cells.free.erase(key);
}

}  // namespace sonarbench::mapping
