#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// One setting of the study: the mapper's horizontal and vertical ray divisions per beam, or its
/// exact mode (group "exact", divisions 0).
struct StudyItem {
  std::string group;  ///< "horizontal", "vertical", "grid" or "exact"
  int rays_horizontal = 0;
  int rays_vertical = 0;
};

/// The study's work items, always in this order (item i is items()[i]): horizontal divisions
/// 1..64 (powers of two) at 64 vertical; vertical 1..128 at 32 horizontal; and the grid
/// {4..64} x {8..128}; then the exact mode.
[[nodiscard]] std::vector<StudyItem> DivisionsStudyItems();

struct StudyOptions {
  /// The settings to study; empty means DivisionsStudyItems().
  std::vector<StudyItem> items;
  std::optional<std::uint64_t> seed;
  /// Overrides the scene's sweeps (fewer make a quicker study).
  std::optional<int> sweeps;
  /// Beams of the first sweep whose exact volume is measured (evenly spaced in head angle).
  int coverage_beams = 20;
  int threads = 0;
  bool force = false;
  Shard shard;
  std::function<void(std::size_t done, std::size_t total)> progress;
};

struct StudySummary {
  std::size_t items_total = 0;
  std::size_t items_written = 0;
  std::size_t items_skipped = 0;
  /// divisions.csv and the plots written: every item present.
  bool complete = false;
};

/// The seed paper's coverage-vs-divisions study (its figures 9 and 10) on a scene. The scene is
/// simulated once; for each item the beams are mapped with those divisions (map metrics against
/// the truth, and the mapping time), and the coverage of the exact beam volume is measured on
/// `coverage_beams` beams, each out to its true axis range (ExactWedgeCells, MeasureBeamCoverage).
/// Each item is written as DIR/items/item_NNN.json (atomically; a rerun skips those present and
/// refuses those of another configuration unless `force`); a `shard` does items i with
/// i mod N = K - 1. Once all items are present: DIR/divisions.csv, coverage_vs_divisions.png,
/// time_vs_divisions.png and study.json.
StudySummary RunDivisionsStudy(const Scene& scene, const std::string& dir,
                               const StudyOptions& options);

}  // namespace sonarbench::sim
