#pragma once

#include <octomap/OcTree.h>
#include <omp.h>

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "sonarbench/mapping/beam_volume.hpp"

namespace sonarbench::mapping {

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
BatchStats IntegrateBatch(octomap::OcTree& tree, std::span<const Beam> beams,
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
    if constexpr (requires(Set& s, const Set& o) { s.merge(o); }) {
      merged.free.merge(per_thread[t].free);
      merged.occupied.merge(per_thread[t].occupied);
    } else {
      merged.free.insert(per_thread[t].free.begin(), per_thread[t].free.end());
      merged.occupied.insert(per_thread[t].occupied.begin(), per_thread[t].occupied.end());
    }
    merged.visits += per_thread[t].visits;
  }
  ResolveConflicts(merged);
  for (const auto& key : merged.free) tree.updateNode(key, false, /*lazy_eval=*/true);
  for (const auto& key : merged.occupied) tree.updateNode(key, true, /*lazy_eval=*/true);
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
