#pragma once

#include <octomap/OcTree.h>
#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "sonarbench/mapping/beam_volume.hpp"
#include "sonarbench/mapping/map_tree.hpp"

namespace sonarbench::mapping {

/// The key's Morton code: the bits of x, y and z interleaved, most significant first, which is
/// the order of a depth-first walk of the octree.
[[nodiscard]] inline std::uint64_t MortonCode(const octomap::OcTreeKey& key) {
  auto spread = [](std::uint64_t v) {  // 16 bits to every third of 48
    v = (v | (v << 16)) & 0x0000ff0000ffULL;
    v = (v | (v << 8)) & 0x00f00f00f00fULL;
    v = (v | (v << 4)) & 0x0c30c30c30c3ULL;
    v = (v | (v << 2)) & 0x249249249249ULL;
    return v;
  };
  return (spread(key[0]) << 2) | (spread(key[1]) << 1) | spread(key[2]);
}

/// Per-batch counts, for reports and benchmarks.
struct BatchStats {
  std::size_t beams = 0;
  std::size_t beams_with_obstacle = 0;
  std::size_t ray_casts = 0;
  /// Cell visits by all rays, repeats included.
  std::size_t cell_visits = 0;
  /// Distinct free cells of each beam, summed over the beams: what goes into the key sets.
  std::size_t beam_free_cells = 0;
  /// Distinct cells updated free / occupied.
  std::size_t free_cells = 0;
  std::size_t occupied_cells = 0;
  /// Wall time [s] of the stages: ray casting into the threads' sets, splitting the sets' cells
  /// into octants, and per octant merging (occupied winning), sorting and applying the updates.
  double cast_s = 0.0;
  double split_s = 0.0;
  double update_s = 0.0;

  BatchStats& operator+=(const BatchStats& o) {
    beams += o.beams;
    beams_with_obstacle += o.beams_with_obstacle;
    ray_casts += o.ray_casts;
    cell_visits += o.cell_visits;
    beam_free_cells += o.beam_free_cells;
    free_cells += o.free_cells;
    occupied_cells += o.occupied_cells;
    cast_s += o.cast_s;
    split_s += o.split_s;
    update_s += o.update_s;
    return *this;
  }
};

/// Brings a tree that IntegrateBatch updated up to date for reading and writing: OctoMap's node
/// count, and the inner nodes' occupancy (the maximum of their children's). Updates leave both
/// stale (lazy evaluation, no pruning): neither changes how a later update goes, so this is
/// needed once after the last batch, not after each.
inline void FinishUpdates(MapTree& tree) {
  tree.RecountNodes();
  tree.updateInnerOccupancy();
}

/// Casts the rays of a batch of beams on `threads` threads, each into its own key sets of type
/// `Set`, merges the threads' cells (no lock per key), lets occupied win over free, and applies
/// one log-odds update per cell. The result does not depend on `threads` or on `Set`: a set's
/// content does not depend on insertion order, and each cell gets exactly one update. Call
/// FinishUpdates before reading the tree.
template <typename Set>
BatchStats IntegrateBatch(MapTree& tree, std::span<const Beam> beams,
                          std::span<const std::vector<double>> obstacles,
                          std::span<const Eigen::Vector3d> directions, double free_range_m,
                          int threads) {
  const double start = omp_get_wtime();
  std::vector<BasicBeamCells<Set>> per_thread(static_cast<std::size_t>(threads));
  const auto count = static_cast<std::int64_t>(beams.size());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 4)
  for (std::int64_t b = 0; b < count; ++b) {
    const auto i = static_cast<std::size_t>(b);
    CastBeam(tree, beams[i], directions, obstacles[i], free_range_m,
             per_thread[static_cast<std::size_t>(omp_get_thread_num())]);
  }
  const double cast_done = omp_get_wtime();
  // The threads' cells are merged without a lock per key: each thread splits its own into the
  // root's eight octants (the top bit of each key coordinate), whose subtrees are disjoint; then
  // one thread per octant sorts that octant's cells from all threads in octree (Morton) order,
  // where a cell's copies meet, keeps one (occupied winning over free), and applies the updates,
  // walking only the part of each key's path that differs from the previous key's. The root
  // and each octant's path to one of its keys are created first, serially, so no two threads
  // create the same node. Neither the order nor the threads change the result: each cell is
  // updated once. OctoMap's node count and the inner nodes are left for FinishUpdates.
  using Update = std::pair<std::uint64_t, octomap::OcTreeKey>;  // Morton code << 1 | occupied
  std::vector<std::array<std::vector<Update>, 8>> split(per_thread.size());
#pragma omp parallel for num_threads(threads) schedule(static, 1)
  for (int t = 0; t < threads; ++t) {
    auto& octants = split[static_cast<std::size_t>(t)];
    const auto& cells = per_thread[static_cast<std::size_t>(t)];
    auto add = [&octants](const octomap::OcTreeKey& key, std::uint64_t occupied) {
      const std::uint64_t code = MortonCode(key);
      octants[code >> 45].emplace_back((code << 1) | occupied, key);
    };
    for (const auto& key : cells.free) add(key, 0);
    for (const auto& key : cells.occupied) add(key, 1);
  }
  const double split_done = omp_get_wtime();
  for (unsigned o = 0; o < 8; ++o) {
    for (const auto& octants : split) {
      if (octants[o].empty()) continue;
      tree.CreatePath(octants[o].front().second);
      break;
    }
  }
  const float log_odds[2] = {tree.getProbMissLog(), tree.getProbHitLog()};
  std::array<std::size_t, 8> free_cells{};
  std::array<std::size_t, 8> occupied_cells{};
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (int o = 0; o < 8; ++o) {
    std::vector<Update> updates;
    for (auto& octants : split) {
      auto& part = octants[static_cast<std::size_t>(o)];
      updates.insert(updates.end(), part.begin(), part.end());
      std::vector<Update>().swap(part);
    }
    std::sort(updates.begin(), updates.end(),
              [](const Update& a, const Update& b) { return a.first < b.first; });
    // A cell's copies are adjacent, free (0) before occupied (1): the last one is kept.
    std::size_t kept = 0;
    for (const Update& u : updates) {
      if (kept > 0 && (updates[kept - 1].first >> 1) == (u.first >> 1)) {
        updates[kept - 1] = u;
      } else {
        updates[kept++] = u;
      }
    }
    updates.resize(kept);
    for (const Update& u : updates) {
      (u.first & 1 ? occupied_cells : free_cells)[static_cast<std::size_t>(o)] += 1;
    }
    tree.UpdateLeavesInOrder(
        updates.size(), [&updates](std::size_t i) { return updates[i].second; },
        [&updates, &log_odds](std::size_t i) { return log_odds[updates[i].first & 1]; });
  }

  BatchStats stats;
  stats.beams = beams.size();
  for (const auto& o : obstacles) stats.beams_with_obstacle += o.empty() ? 0 : 1;
  stats.ray_casts = beams.size() * directions.size();
  for (const auto& cells : per_thread) {
    stats.cell_visits += cells.visits;
    stats.beam_free_cells += cells.beam_free_cells;
  }
  for (unsigned o = 0; o < 8; ++o) {
    stats.free_cells += free_cells[o];
    stats.occupied_cells += occupied_cells[o];
  }
  stats.cast_s = cast_done - start;
  stats.split_s = split_done - cast_done;
  stats.update_s = omp_get_wtime() - split_done;
  return stats;
}

}  // namespace sonarbench::mapping
