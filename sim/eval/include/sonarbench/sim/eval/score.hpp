#pragma once

#include <octomap/OcTree.h>

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "sonarbench/mapping/beam_cells.hpp"
#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/world/mesh.hpp"

namespace sonarbench::sim {

/// Distances [m] from one set of points to another surface: mean, 95th percentile and maximum
/// (the one-sided Hausdorff distance), over `count` points; all 0 when `count` is 0.
struct DistanceStats {
  std::size_t count = 0;
  double mean_m = 0.0;
  double p95_m = 0.0;
  double max_m = 0.0;
};

/// How a map compares with the ground truth. Cells are leaf cells at the map's resolution; a
/// pruned inner node counts as all the leaf cells it stands for. Unknown cells (never updated)
/// are neither occupied nor free: they lower coverage and recall, never precision.
struct MapMetrics {
  std::size_t truth_cells = 0;              ///< cells any mesh surface crosses
  std::size_t observable_cells = 0;         ///< truth cells a perfect sensor could see
  std::size_t occupied_cells = 0;           ///< cells the map holds occupied
  std::size_t free_cells = 0;               ///< cells the map holds free
  std::size_t true_positive_cells = 0;      ///< occupied ∩ truth
  std::size_t observed_occupied_cells = 0;  ///< occupied ∩ observable
  std::size_t known_observable_cells = 0;   ///< (occupied ∪ free) ∩ observable

  /// true positives / occupied (0 when the map has no occupied cell).
  double occupied_precision = 0.0;
  /// occupied ∩ observable / observable (0 when nothing was observable).
  double occupied_recall = 0.0;
  /// Harmonic mean of precision and recall (0 when both are 0).
  double occupied_f1 = 0.0;
  /// The same with a tolerance of k cells (k = 0, 1, 2; index k): an occupied cell counts when a
  /// truth cell lies within k cells of it (Chebyshev distance, the (2k + 1)³ block around it),
  /// an observable cell when an occupied one does. Index 0 is occupied_precision/recall/f1.
  std::array<double, 3> precision_within{};
  std::array<double, 3> recall_within{};
  std::array<double, 3> f1_within{};
  /// Occupied cells more than 2 cells from every truth cell / occupied: the ghosts' share,
  /// 1 - precision_within[2] (0 for an empty map).
  double ghost_share = 0.0;
  /// The ghosts split, when the scorer knows the beams' direct echoes (absent otherwise): those on
  /// the arc of an echo a surface returns directly (DirectEchoes::Explains: where on its arc a
  /// sonar cannot tell), and the rest, at ranges where no surface answers directly in any beam
  /// holding them (multipath, round trips, sidelobes, noise). Shares of occupied; their sum is
  /// ghost_share.
  std::optional<double> ghost_arc_share;
  std::optional<double> ghost_echo_share;
  /// The same split by the direct echoes the simulator's labels name (LabelledDirectBeam), for a
  /// simulated run: arc and echo shares, a check of the geometric split.
  std::optional<std::pair<double, double>> labelled_ghost_split;
  /// Top down, over (x, y) columns of cells: columns holding an occupied cell that hold a truth
  /// cell / columns holding an occupied cell; columns of observable cells that hold an occupied
  /// cell / columns of observable cells. Fair to a static sonar, whose echo's elevation on its
  /// arc is unknown.
  double column_precision = 0.0;
  double column_recall = 0.0;
  /// known ∩ observable / observable: the share of visible surface the map has any belief about.
  double coverage = 0.0;
  /// (occupied ∪ free) ∩ truth / truth: the same against every surface cell, seen or not.
  double coverage_absolute = 0.0;
  /// Free cells that lie on a surface, and 1 - that / free: how often "free" is wrong.
  std::size_t free_on_surface_cells = 0;
  double free_accuracy = 0.0;
  /// From each occupied cell's centre to the nearest mesh triangle (exact point-triangle
  /// distance), and from each observable surface cell's centre to the nearest occupied cell's.
  DistanceStats map_to_mesh;
  DistanceStats mesh_to_map;
  /// Recall per truth mesh (scene order; only when meshes are given): of the observable cells that
  /// mesh's own surface crosses, the share mapped occupied. An object on a floor is judged by
  /// its own cells, not lost among the floor's.
  struct MeshRecall {
    std::string name;
    std::size_t observable_cells = 0;
    std::size_t observed_occupied_cells = 0;
    double recall = 0.0;
  };
  std::vector<MeshRecall> per_mesh;
};

/// Scores `map` against the surface cells `truth` and the subset `observable` a perfect sensor
/// could see (cells of `observable` outside `truth` are ignored); `meshes` give the exact surface
/// for distances (none: distances are not computed); meshes that are not `truth` are left out;
/// `direct` splits the ghosts (none: ghost_arc_share and ghost_echo_share stay absent), and the
/// detector's ghosts' cells go to `detector_ghosts` when given.
/// `progress` counts its passes: the counts, each mesh's recall, the two distances.
[[nodiscard]] MapMetrics ScoreMap(const octomap::OcTree& map, const mapping::KeySet& truth,
                                  const mapping::KeySet& observable,
                                  std::span<const TriangleMesh> meshes = {},
                                  const StageProgress& progress = {},
                                  const DirectEchoes* direct = nullptr,
                                  mapping::KeySet* detector_ghosts = nullptr);

/// The ghosts of `map` (occupied, more than 2 cells from every `truth` cell) on an echo of
/// `direct`'s arc and the others, as shares of its occupied cells.
[[nodiscard]] std::pair<double, double> SplitGhostsBy(const octomap::OcTree& map,
                                                      const mapping::KeySet& truth,
                                                      const DirectEchoes& direct);

/// Whether `cells` holds a cell within `k` cells (Chebyshev) of `key`: how the metrics' tolerances
/// count (MapMetrics::precision_within).
[[nodiscard]] bool AnyWithin(const mapping::KeySet& cells, const octomap::OcTreeKey& key, int k);

/// Leaf cells of `map` at its finest resolution, split by occupancy.
struct MapCells {
  mapping::KeySet occupied;
  mapping::KeySet free;
};
[[nodiscard]] MapCells CollectMapCells(const octomap::OcTree& map);
/// The same cells of a mapper's map, from its leaves (the tree need not be built).
[[nodiscard]] MapCells CollectMapCells(const mapping::Mapper& mapper);

}  // namespace sonarbench::sim
