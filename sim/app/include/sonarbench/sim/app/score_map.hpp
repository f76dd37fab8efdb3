#pragma once

#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "sonarbench/io/octomap_file.hpp"
#include "sonarbench/sim/eval/scene_score.hpp"
#include "sonarbench/sim/world/budget.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// A map file, written by any mapper, scored against a scene.
struct MapFileScore {
  std::string map_file;
  io::OcTreeFileInfo file;
  std::unique_ptr<octomap::OcTree> map;
  SceneScore score;
  /// The frame check: the box the scene's sonar reaches (its positions' box grown by its range)
  /// [m], and the share of the map's occupied cells whose centres lie in it.
  Eigen::Vector3d reach_lo_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d reach_hi_m = Eigen::Vector3d::Zero();
  double occupied_in_reach = 1.0;
  /// The sonar's position at the scene's first beam [m], where the side view is cut.
  Eigen::Vector3d sonar_start_m = Eigen::Vector3d::Zero();
  double read_s = 0.0;
};

/// The least share of a map's occupied cells that must lie within the scene sonar's reach.
inline constexpr double kMinOccupiedInReach = 0.5;
/// Above this ghost share the verdict warns that the map may be in another frame.
inline constexpr double kGhostShareWarning = 0.8;

/// Reads `map_file` (ReadOcTreeFile, at most `budgets.max_cells` cells) and scores it against
/// `scene` as `run` scores its own map: the scene's surfaces voxelised at the map's resolution,
/// the cells a perfect sensor sees from every beam of the scene's trajectory, the scene's
/// criteria. Throws InputError, before building anything large, when the scene's truth at the
/// map's resolution would exceed `budgets.max_cells` or reach past the ±32768 cells a map of that
/// resolution addresses, and when under kMinOccupiedInReach of the map's occupied cells lie in
/// the box the scene's sonar reaches: a map in another frame (another origin, axes or units).
/// A map past kGhostShareWarning gets a warning in its verdict: a smaller offset shows as ghosts.
[[nodiscard]] MapFileScore ScoreMapFile(const std::string& map_file, const Scene& scene,
                                        const Budgets& budgets, const StageProgress& progress = {});

/// ScoreMapFile's scoring of a map already read (`info` as ReadOcTreeFile gives it; `map_file`
/// names it in messages and reports), its read time counted from `read_start`.
[[nodiscard]] MapFileScore ScoreMapTree(
    std::unique_ptr<octomap::OcTree> map, const std::string& map_file,
    const io::OcTreeFileInfo& info, const Scene& scene, const Budgets& budgets,
    const StageProgress& progress = {},
    std::chrono::steady_clock::time_point read_start = std::chrono::steady_clock::now());

/// The files WriteMapFileScoreOutputs writes, relative to its `out_dir`, the record first.
inline const std::vector<std::string> kMapFileScoreOutputFiles = {
    "report.json", "junit.xml", "report.html", "map_top.png", "map_side.png"};

/// Writes into `out_dir`, each file atomically: map_top.png and map_side.png (the map against the
/// truth), junit.xml and report.html as `run` writes them, and, last, report.json: the scene, the
/// map file (format, resolution, nodes), the frame check, metrics, verdict, criteria, timing and
/// the sha256 of the other files.
void WriteMapFileScoreOutputs(const std::string& out_dir, const Scene& scene,
                              const MapFileScore& score);

}  // namespace sonarbench::sim
