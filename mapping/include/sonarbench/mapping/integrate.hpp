#pragma once

#include <octomap/OcTree.h>
#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
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
  /// Distinct cells updated free / occupied.
  std::size_t free_cells = 0;
  std::size_t occupied_cells = 0;

  BatchStats& operator+=(const BatchStats& o) {
    beams += o.beams;
    beams_with_obstacle += o.beams_with_obstacle;
    ray_casts += o.ray_casts;
    cell_visits += o.cell_visits;
    free_cells += o.free_cells;
    occupied_cells += o.occupied_cells;
    return *this;
  }
};

/// Casts the rays of a batch of beams on `threads` threads, each into its own key sets of type
/// `Set`, merges the sets (no lock per key), lets occupied win over free, and applies one
/// log-odds update per cell. The result does not depend on `threads` or on `Set`: a set's content
/// does not depend on insertion order, and each cell gets exactly one update.
template <typename Set>
BatchStats IntegrateBatch(MapTree& tree, std::span<const Beam> beams,
                          std::span<const std::vector<double>> obstacles,
                          std::span<const Eigen::Vector3d> directions, double free_range_m,
                          int threads) {
  std::vector<BasicBeamCells<Set>> per_thread(static_cast<std::size_t>(threads));
  const auto count = static_cast<std::int64_t>(beams.size());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 4)
  for (std::int64_t b = 0; b < count; ++b) {
    const auto i = static_cast<std::size_t>(b);
    CastBeam(tree, beams[i], directions, obstacles[i], free_range_m,
             per_thread[static_cast<std::size_t>(omp_get_thread_num())]);
  }
  BasicBeamCells<Set> merged = std::move(per_thread.front());
  for (std::size_t t = 1; t < per_thread.size(); ++t) {
    if constexpr (requires(Set & s, const Set& o) { s.merge(o); }) {
      merged.free.merge(per_thread[t].free);
      merged.occupied.merge(per_thread[t].occupied);
    } else {
      merged.free.insert(per_thread[t].free.begin(), per_thread[t].free.end());
      merged.occupied.insert(per_thread[t].occupied.begin(), per_thread[t].occupied.end());
    }
    merged.visits += per_thread[t].visits;
  }
  ResolveConflicts(merged);
  // Updates in Morton (octree) order: consecutive updates descend the same branches, which stay
  // in cache. The order does not change the result: each cell is updated once.
  std::vector<std::pair<std::uint64_t, octomap::OcTreeKey>> updates;
  updates.reserve(merged.free.size() + merged.occupied.size());
  for (const auto& key : merged.free) updates.emplace_back(MortonCode(key) << 1, key);
  for (const auto& key : merged.occupied) updates.emplace_back((MortonCode(key) << 1) | 1, key);
  std::sort(updates.begin(), updates.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  // The Morton code's top three bits name the root's child (octant) a key lies in, so the sorted
  // updates fall into up to eight runs of disjoint subtrees, updated in parallel. The first key
  // of each run is updated serially, which creates the root and that child: afterwards no update
  // touches a node another thread may create. OctoMap's node count is then recounted.
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i < updates.size(); ++i) {
    if (i == 0 || (updates[i].first >> 46) != (updates[i - 1].first >> 46)) starts.push_back(i);
  }
  starts.push_back(updates.size());
  for (std::size_t r = 0; r + 1 < starts.size(); ++r) {
    const auto& [code, key] = updates[starts[r]];
    tree.updateNode(key, (code & 1) != 0, /*lazy_eval=*/true);
  }
  const auto runs = static_cast<std::int64_t>(starts.size()) - 1;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (std::int64_t r = 0; r < runs; ++r) {
    for (std::size_t i = starts[static_cast<std::size_t>(r)] + 1;
         i < starts[static_cast<std::size_t>(r) + 1]; ++i) {
      tree.updateNode(updates[i].second, (updates[i].first & 1) != 0, /*lazy_eval=*/true);
    }
  }
  tree.RecountNodes();
  tree.updateInnerOccupancy();

  BatchStats stats;
  stats.beams = beams.size();
  for (const auto& o : obstacles) stats.beams_with_obstacle += o.empty() ? 0 : 1;
  stats.ray_casts = beams.size() * directions.size();
  stats.cell_visits = merged.visits;
  stats.free_cells = merged.free.size();
  stats.occupied_cells = merged.occupied.size();
  return stats;
}

}  // namespace sonarbench::mapping
