#pragma once

#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <span>
#include <tuple>
#include <vector>

#include "arc_evidence.hpp"
#include "beam_raster.hpp"
#include "beam_wedge.hpp"
#include "key_set.hpp"
#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/beam_cells.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"
#include "water_keys.hpp"

namespace sonarbench::mapping {

/// The cells a batch of beams marks, in a set type `Set` with `insert(key)`, `erase(key)` and
/// iteration (std::unordered_set, OpenKeySet, absl::flat_hash_set, ...), and the scratch space
/// one thread needs to cast beams into them.
template <typename Set>
struct BasicBeamCells {
  Set free;
  Set occupied;
  /// Cell visits by all rays, repeats included (the paper's section 3.2 redundancy).
  std::size_t visits = 0;
  /// Distinct free cells of each beam, summed over the beams.
  std::size_t beam_free_cells = 0;
  /// Walks a beam's rays and keeps each of its cells once (see BeamRaster).
  BeamRaster raster;
  std::vector<octomap::point3d> ends;
  std::vector<std::uint64_t> beam_free;
  std::vector<std::uint64_t> beam_occupied;
  /// Cells of the exact mode decided by clipping their faces (BeamWedge::CellSpan).
  std::size_t clipped = 0;
  /// A beam's keys that go on to the sets: not caught by recent_free / recent_occupied.
  std::vector<std::uint64_t> fresh_free;
  std::vector<std::uint64_t> fresh_occupied;
  /// What was inserted into `free` and `occupied` lately: inserts these catch are skipped.
  RecentKeys recent_free;
  RecentKeys recent_occupied;
  /// Whether inserting a key already held costs what a new one does (BlockKeySet): then the
  /// recent-key filters only add work, and are skipped.
  static constexpr bool kNoRepeatFilter = requires(const Set& set) { set.blocks(); };
  /// With arc evidence, the occupied cells go here instead of `occupied`, each with its share
  /// (packed << kShareBits | level, AppendArcShares), a cell once per beam.
  std::vector<std::uint64_t> occupied_shares;
  ArcShareScratch share_scratch;

  /// Empties the sets and zeroes the counts, for the next batch. Each set keeps room for as
  /// many keys as it held (abseil's clear() frees a large table; the reserve gets it back).
  void Clear() {
    const std::size_t free_keys = free.size();
    const std::size_t occupied_keys = occupied.size();
    free.clear();
    occupied.clear();
    free.reserve(free_keys);
    occupied.reserve(occupied_keys);
    recent_free.clear();
    recent_occupied.clear();
    occupied_shares.clear();
    visits = 0;
    beam_free_cells = 0;
    clipped = 0;
  }

  /// Calls `f(packed)` for each key of `set`, one of the two, in the set's order.
  template <typename F>
  static void ForEach(const Set& set, F&& f) {
    if constexpr (requires { set.for_each_packed(f); }) {
      set.for_each_packed(f);
    } else {
      for (const octomap::OcTreeKey& key : set) f(PackKey(key));
    }
  }

  /// Inserts keys (packed) into `set`, one of the two.
  static void Insert(Set& set, std::span<const std::uint64_t> packed) {
    if constexpr (requires { set.insert_packed(packed); }) {
      set.insert_packed(packed);
    } else {
      for (const std::uint64_t key : packed) set.insert(UnpackKey(key));
    }
  }
};
using BeamCells = BasicBeamCells<KeySet>;

/// Adds to `cells` the keys of one beam with obstacles at `obstacle_ranges_m` (nearest first).
/// Occupied cells are the cells of each ray's end point at an obstacle range, so the ends lie on
/// the true spherical wedge (|end - origin| = range exactly; the seed's code put them up to 4.4%
/// too far at the edges); free cells are those each ray crosses before the first obstacle, or
/// out to `free_range_m` without one (0 = clear nothing): OctoMap's computeRayKeys cells for
/// each ray, each distinct cell of the beam inserted into the set once. `directions` are from
/// BeamRayDirections. Occupied does not yet win over free here: IntegrateBatch resolves that.
/// With `evidence` on, the occupied cells go to `cells.occupied_shares` with their shares. No cell
/// that `water` does not hold is occupied.
template <typename Set>
void CastBeam(const octomap::OcTree& tree, const Beam& beam,
              std::span<const Eigen::Vector3d> directions,
              std::span<const double> obstacle_ranges_m, double free_range_m,
              BasicBeamCells<Set>& cells, const ArcEvidence& evidence = {},
              const WaterKeys& water = {}) {
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
  cells.ends.clear();
  cells.fresh_occupied.clear();
  for (const Eigen::Vector3d& direction : directions) {
    const Eigen::Vector3d d_world = R_world_beam * direction;
    // The cells crossed before the end point's cell, which is left for the occupied update (or,
    // without an obstacle, for the next beam).
    cells.ends.push_back(to_point(origin + free_end_m * d_world));
    for (std::size_t k = 0; k < obstacle_ranges_m.size(); ++k) {
      octomap::OcTreeKey key;
      if (tree.coordToKeyChecked(to_point(origin + obstacle_ranges_m[k] * d_world), key)) {
        ++cells.visits;
        // Neighbouring rays mostly end in the same cell.
        if (evidence.on() || !cells.recent_occupied.CheckAndRemember(PackKey(key))) {
          cells.fresh_occupied.push_back(PackKey(key));
        }
      }
    }
  }
  if (!water.all()) {
    std::erase_if(cells.fresh_occupied, [&](std::uint64_t k) { return !water.Holds(k); });
  }
  if (evidence.on()) {
    std::sort(cells.fresh_occupied.begin(), cells.fresh_occupied.end());
    cells.fresh_occupied.erase(
        std::unique(cells.fresh_occupied.begin(), cells.fresh_occupied.end()),
        cells.fresh_occupied.end());
    AppendArcShares(tree, evidence, origin, R_world_beam.col(2), obstacle_ranges_m,
                    cells.fresh_occupied, cells.share_scratch, cells.occupied_shares);
  } else {
    cells.Insert(cells.occupied, cells.fresh_occupied);
  }
  cells.beam_free.clear();
  cells.visits += cells.raster.Trace(tree, to_point(origin), cells.ends, cells.beam_free);
  cells.beam_free_cells += cells.beam_free.size();
  if constexpr (BasicBeamCells<Set>::kNoRepeatFilter) {
    cells.Insert(cells.free, cells.beam_free);
    return;
  }
  cells.fresh_free.clear();
  for (const std::uint64_t packed : cells.beam_free) {
    if (!cells.recent_free.CheckAndRemember(packed)) cells.fresh_free.push_back(packed);
  }
  cells.Insert(cells.free, cells.fresh_free);
}

/// Adds to `cells` the keys of one beam under the exact semantics (ExactBeamCells): every cell
/// of the wedge examined once, free before the first obstacle, occupied on each obstacle's shell,
/// clearing out to `free_range_m` without an obstacle (0 = clear nothing). With `evidence` on,
/// the occupied cells go to `cells.occupied_shares` with their shares. No cell that `water` does
/// not hold is occupied.
template <typename Set>
void CastBeamExact(const octomap::OcTree& tree, const SensorGeometry& sensor, const Beam& beam,
                   std::span<const double> obstacle_ranges_m, double free_range_m,
                   BasicBeamCells<Set>& cells, const ArcEvidence& evidence = {},
                   const WaterKeys& water = {}) {
  cells.beam_free.clear();
  cells.beam_occupied.clear();
  const BeamWedge wedge(sensor, beam);
  const WedgeCellCounts counts = ExactBeamCells(tree, wedge, obstacle_ranges_m, free_range_m,
                                                cells.beam_free, cells.beam_occupied);
  if (!water.all()) {
    std::erase_if(cells.beam_occupied, [&](std::uint64_t k) { return !water.Holds(k); });
  }
  cells.visits += counts.examined;
  cells.clipped += counts.clipped;
  cells.beam_free_cells += cells.beam_free.size();
  if (evidence.on()) {
    AppendArcShares(tree, evidence, wedge.origin(), wedge.up(), obstacle_ranges_m,
                    cells.beam_occupied, cells.share_scratch, cells.occupied_shares);
    cells.beam_occupied.clear();
  }
  for (auto [keys, recent, fresh, set] :
       {std::tuple(&cells.beam_free, &cells.recent_free, &cells.fresh_free, &cells.free),
        std::tuple(&cells.beam_occupied, &cells.recent_occupied, &cells.fresh_occupied,
                   &cells.occupied)}) {
    if constexpr (BasicBeamCells<Set>::kNoRepeatFilter) {
      cells.Insert(*set, *keys);
      continue;
    }
    fresh->clear();
    for (const std::uint64_t packed : *keys) {
      if (!recent->CheckAndRemember(packed)) fresh->push_back(packed);
    }
    cells.Insert(*set, *fresh);
  }
}

}  // namespace sonarbench::mapping
