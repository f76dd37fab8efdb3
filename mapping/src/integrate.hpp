#pragma once

#include <octomap/OcTree.h>
#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "beam_volume.hpp"
#include "block_set.hpp"
#include "map_tree.hpp"
#include "sonarbench/mapping/batch_stats.hpp"

namespace sonarbench::mapping {

/// Sorts `values` in increasing order: a least-significant-digit radix sort, 11 bits a pass,
/// that skips a pass whose digit is the same in every value (the high bits of the Morton codes
/// of one region of space). `scratch` is reused between calls.
inline void RadixSort(std::vector<std::uint64_t>& values, std::vector<std::uint64_t>& scratch) {
  constexpr unsigned kBits = 11;
  constexpr std::size_t kBuckets = std::size_t{1} << kBits;
  if (values.size() < 2) return;
  std::uint64_t all_or = 0;
  std::uint64_t all_and = ~std::uint64_t{0};
  for (const std::uint64_t v : values) {
    all_or |= v;
    all_and &= v;
  }
  const std::uint64_t varying = all_or ^ all_and;  // the bits that differ between values
  scratch.resize(values.size());
  std::array<std::size_t, kBuckets> start;
  for (unsigned shift = 0; shift < 64; shift += kBits) {
    if (((varying >> shift) & (kBuckets - 1)) == 0) continue;
    start.fill(0);
    for (const std::uint64_t v : values) ++start[(v >> shift) & (kBuckets - 1)];
    std::size_t sum = 0;
    for (std::size_t& s : start) sum += std::exchange(s, sum);
    for (const std::uint64_t v : values) scratch[start[(v >> shift) & (kBuckets - 1)]++] = v;
    values.swap(scratch);
  }
}

/// Brings a tree that IntegrateBatch updated up to date for reading and writing: its leaves set
/// to the log-odds the batches left beside it (MapTree::SyncLeaves, on up to `threads` threads),
/// then the inner nodes' occupancy (the maximum of their children's; lazy evaluation, no
/// pruning). Neither changes how a later update goes, so this is needed once after the last
/// batch, not after each.
inline void FinishUpdates(MapTree& tree, int threads = 1) {
  tree.SyncLeaves(threads);
  tree.updateInnerOccupancy();
}

/// What IntegrateBatch needs besides the tree: each thread's key sets and buffers, and each
/// octant's updates. Kept from batch to batch, a workspace's tables are already grown to a
/// sweep's size when the next sweep starts, so a mapper resizes them in its first sweep only.
template <typename Set>
struct BatchWorkspace {
  std::vector<BasicBeamCells<Set>> per_thread;
  /// Per thread, per octant of the root: Morton code << 1 | occupied of its cells.
  std::vector<std::array<std::vector<std::uint64_t>, 8>> split;
  /// Per octant: the threads' updates together, and a radix sort's scratch.
  std::array<std::vector<std::uint64_t>, 8> updates;
  std::array<std::vector<std::uint64_t>, 8> scratch;
  /// For a set of blocks (BlockKeySet): per thread, per octant, its blocks with their Morton
  /// codes (free blocks' codes even, occupied ones' odd).
  struct BlockRef {
    std::uint64_t code;
    const BlockKeySet::Block* block;
  };
  std::vector<std::array<std::vector<BlockRef>, 8>> block_split;
  std::array<std::vector<BlockRef>, 8> octant_blocks;

  /// Makes it ready for a batch on `threads` threads: empty sets, zero counts.
  void Reset(int threads) {
    per_thread.resize(static_cast<std::size_t>(threads));
    for (auto& cells : per_thread) cells.Clear();
    split.resize(per_thread.size());
    block_split.resize(per_thread.size());
  }
};

namespace integrate_detail {

// The threads' cells are merged without a lock: split by the root's eight octants (disjoint
// subtrees), then one thread per octant sorts its cells in Morton order (a block set's: its
// blocks, MergeBlocks), keeps one copy per cell (occupied winning) and applies the updates
// (docs/mapper.md). An update is a cell's Morton code << bits | level: `bits` 1 and level 1 for
// arc marking, kShareBits and the cell's share level for arc evidence; level 0 is free.
// Each thread's cells split by the root's octant: as updates, or a block set's as its blocks.
template <typename Set>
void SplitByOctant(BatchWorkspace<Set>& workspace, int threads, unsigned bits) {
  auto& per_thread = workspace.per_thread;
  auto& split = workspace.split;
  const std::uint64_t full = (std::uint64_t{1} << bits) - 1;
#pragma omp parallel for num_threads(threads) schedule(static, 1)
  for (int t = 0; t < threads; ++t) {
    auto& octants = split[static_cast<std::size_t>(t)];
    const auto& cells = per_thread[static_cast<std::size_t>(t)];
    for (auto& part : octants) part.clear();
    using Cells = BasicBeamCells<Set>;
    if constexpr (std::is_same_v<Set, BlockKeySet>) {
      auto& blocks = workspace.block_split[static_cast<std::size_t>(t)];
      for (auto& part : blocks) part.clear();
      for (const std::uint64_t occupied : {0, 1}) {
        for (const auto& b : (occupied != 0 ? cells.occupied : cells.free).blocks()) {
          const std::uint64_t code = MortonCode(UnpackKey(b.origin));
          blocks[code >> 45].push_back({code | occupied, &b});
        }
      }
    } else {
      for (const std::uint64_t level : {std::uint64_t{0}, full}) {
        Cells::ForEach(level != 0 ? cells.occupied : cells.free,
                       [&octants, level, bits](std::uint64_t packed) {
                         const std::uint64_t code = MortonCode(UnpackKey(packed));
                         octants[code >> 45].push_back((code << bits) | level);
                       });
      }
    }
    for (const std::uint64_t share : cells.occupied_shares) {
      const std::uint64_t code = MortonCode(UnpackKey(share >> kShareBits));
      octants[code >> 45].push_back((code << bits) | (share & kShareLevelMax));
    }
  }
}

// Octant o's cells from the threads' blocks, in Morton order, merged into `updates` (sorted,
// the shares of arc evidence only): a cell's copies adjacent, free before occupied.
template <typename Set>
void MergeBlocks(BatchWorkspace<Set>& workspace, int o, unsigned bits) {
  auto& refs = workspace.octant_blocks[static_cast<std::size_t>(o)];
  refs.clear();
  for (const auto& octants : workspace.block_split) {
    const auto& part = octants[static_cast<std::size_t>(o)];
    refs.insert(refs.end(), part.begin(), part.end());
  }
  std::sort(refs.begin(), refs.end(), [](const auto& a, const auto& b) { return a.code < b.code; });
  auto& updates = workspace.updates[static_cast<std::size_t>(o)];
  auto& merged = workspace.scratch[static_cast<std::size_t>(o)];
  merged.clear();
  const std::uint64_t full = (std::uint64_t{1} << bits) - 1;
  std::size_t share = 0;
  for (std::size_t i = 0; i < refs.size();) {
    const std::uint64_t block_code = refs[i].code & ~std::uint64_t{1};
    std::array<std::uint64_t, 8> free{}, occupied{};
    for (; i < refs.size() && (refs[i].code & ~std::uint64_t{1}) == block_code; ++i) {
      auto& words = (refs[i].code & 1) != 0 ? occupied : free;
      for (unsigned w = 0; w < 8; ++w) words[w] |= refs[i].block->bits[w];
    }
    for (unsigned w = 0; w < 8; ++w) {
      for (std::uint64_t cells = free[w] | occupied[w]; cells != 0; cells &= cells - 1) {
        const unsigned bit = static_cast<unsigned>(std::countr_zero(cells));
        const std::uint64_t code = block_code | (64 * w + bit);
        for (; share < updates.size() && (updates[share] >> bits) < code; ++share) {
          merged.push_back(updates[share]);
        }
        merged.push_back((code << bits) | ((occupied[w] >> bit) & 1 ? full : 0));
      }
    }
  }
  merged.insert(merged.end(), updates.begin() + static_cast<std::ptrdiff_t>(share), updates.end());
  updates.swap(merged);
}

// Octant o's updates from all threads, sorted, a cell's copies merged (the highest level wins:
// occupied over free), applied to `tree`'s leaves with log_odds[level]. Returns {free cells,
// occupied cells}.
template <typename Set>
std::array<std::size_t, 2> UpdateOctant(MapTree& tree, BatchWorkspace<Set>& workspace, int o,
                                        unsigned bits, std::span<const float> log_odds) {
  const auto& split = workspace.split;
  std::array<std::size_t, 2> counts{};
  auto& updates = workspace.updates[static_cast<std::size_t>(o)];
  updates.clear();
  for (const auto& octants : split) {
    const auto& part = octants[static_cast<std::size_t>(o)];
    updates.insert(updates.end(), part.begin(), part.end());
  }
  RadixSort(updates, workspace.scratch[static_cast<std::size_t>(o)]);
  const std::uint64_t full = (std::uint64_t{1} << bits) - 1;
  if constexpr (std::is_same_v<Set, BlockKeySet>) {
    MergeBlocks(workspace, o, bits);
  }
  // A cell's copies are adjacent, in increasing level: the last one is kept.
  std::size_t kept = 0;
  for (const std::uint64_t u : updates) {
    if (kept > 0 && (updates[kept - 1] >> bits) == (u >> bits)) {
      updates[kept - 1] = u;
    } else {
      updates[kept++] = u;
    }
  }
  updates.resize(kept);
  for (const std::uint64_t u : updates) counts[(u & full) != 0 ? 1 : 0] += 1;
  tree.ApplyUpdates(o, updates, bits, log_odds);
  return counts;
}

}  // namespace integrate_detail

/// The cells of a batch of beams, on `threads` threads: `cast(i, cells)` adds beam i's free and
/// occupied cells to one thread's BasicBeamCells. The threads' cells are merged (no lock per
/// key), occupied wins over free, and each cell gets one log-odds update. The result does not
/// depend on `threads` or on `Set`: a set's content does not depend on insertion order, and each
/// cell gets exactly one update. With `evidence` on, occupied cells come with share levels
/// (`occupied_shares`) and the highest share a cell gets in the batch is its update (ShareLogOdds).
/// Call FinishUpdates before reading the tree.
template <typename Set, typename Cast>
BatchStats IntegrateCells(MapTree& tree, std::span<const Beam> beams,
                          std::span<const std::vector<double>> obstacles, int threads,
                          BatchWorkspace<Set>& workspace, const ArcEvidence& evidence,
                          Cast&& cast) {
  const double start = omp_get_wtime();
  if (evidence.on()) tree.SyncLeaves(threads);  // the shares read the map's leaves
  workspace.Reset(threads);
  auto& per_thread = workspace.per_thread;
  const auto count = static_cast<std::int64_t>(beams.size());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 4)
  for (std::int64_t b = 0; b < count; ++b) {
    cast(static_cast<std::size_t>(b), per_thread[static_cast<std::size_t>(omp_get_thread_num())]);
  }
  const double cast_done = omp_get_wtime();
  const unsigned bits = evidence.on() ? kShareBits : 1;
  integrate_detail::SplitByOctant(workspace, threads, bits);
  const double split_done = omp_get_wtime();
  std::vector<float> log_odds(std::size_t{1} << bits);
  log_odds[0] = tree.getProbMissLog();
  for (std::size_t level = 1; level < log_odds.size(); ++level) {
    log_odds[level] = evidence.on() ? ShareLogOdds(tree.getProbHit(), tree.getProbHitLog(), level)
                                    : tree.getProbHitLog();
  }
  std::array<std::array<std::size_t, 2>, 8> counts{};
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (int o = 0; o < 8; ++o) {
    counts[static_cast<std::size_t>(o)] =
        integrate_detail::UpdateOctant(tree, workspace, o, bits, std::span<const float>(log_odds));
  }
  BatchStats stats;
  for (const auto& c : counts) {
    stats.free_cells += c[0];
    stats.occupied_cells += c[1];
  }
  stats.beams = beams.size();
  for (const auto& o : obstacles) stats.beams_with_obstacle += o.empty() ? 0 : 1;
  for (const auto& cells : per_thread) {
    stats.cell_visits += cells.visits;
    stats.clipped_cells += cells.clipped;
    stats.beam_free_cells += cells.beam_free_cells;
  }
  stats.cast_s = cast_done - start;
  stats.split_s = split_done - cast_done;
  stats.update_s = omp_get_wtime() - split_done;
  return stats;
}

/// IntegrateCells with each beam's cells from its H×V ray casts (CastBeam).
template <typename Set>
BatchStats IntegrateBatch(MapTree& tree, std::span<const Beam> beams,
                          std::span<const std::vector<double>> obstacles,
                          std::span<const Eigen::Vector3d> directions, double free_range_m,
                          int threads, BatchWorkspace<Set>& workspace,
                          const ArcEvidence& evidence = {}, const WaterKeys& water = {}) {
  BatchStats stats = IntegrateCells(tree, beams, obstacles, threads, workspace, evidence,
                                    [&](std::size_t i, BasicBeamCells<Set>& cells) {
                                      CastBeam(tree, beams[i], directions, obstacles[i],
                                               free_range_m, cells, evidence, water);
                                    });
  stats.ray_casts = beams.size() * directions.size();
  return stats;
}

/// IntegrateCells with each beam's cells from its exact wedge (CastBeamExact).
template <typename Set>
BatchStats IntegrateExactBatch(MapTree& tree, std::span<const Beam> beams,
                               std::span<const std::vector<double>> obstacles,
                               const SensorGeometry& sensor, double free_range_m, int threads,
                               BatchWorkspace<Set>& workspace, const ArcEvidence& evidence = {},
                               const WaterKeys& water = {}) {
  return IntegrateCells(tree, beams, obstacles, threads, workspace, evidence,
                        [&](std::size_t i, BasicBeamCells<Set>& cells) {
                          CastBeamExact(tree, sensor, beams[i], obstacles[i], free_range_m, cells,
                                        evidence, water);
                        });
}

/// The same with a workspace of its own, for a single batch.
template <typename Set>
BatchStats IntegrateBatch(MapTree& tree, std::span<const Beam> beams,
                          std::span<const std::vector<double>> obstacles,
                          std::span<const Eigen::Vector3d> directions, double free_range_m,
                          int threads) {
  BatchWorkspace<Set> workspace;
  return IntegrateBatch(tree, beams, obstacles, directions, free_range_m, threads, workspace);
}

}  // namespace sonarbench::mapping
