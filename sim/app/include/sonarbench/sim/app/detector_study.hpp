#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// One setting of the detector study: the scene's detection with these changes.
struct DetectorItem {
  std::string name;  ///< e.g. "threshold 110, 2 echoes, supported"
  mapping::DetectionConfig detection;
};

/// The study's settings, in this order: the threshold detector at thresholds 70-150 (step 20),
/// each with the first echo only, two echoes (strongest) and two echoes (supported); then Canny
/// and automatic Canny with the same three echo rules. Everything else is `base`'s.
[[nodiscard]] std::vector<DetectorItem> DetectorStudyItems(const mapping::DetectionConfig& base);

struct DetectorStudyOptions {
  /// The settings to study; empty means DetectorStudyItems(scene's detection).
  std::vector<DetectorItem> items;
  std::optional<std::uint64_t> seed;
  /// A recorded log of the scene's place (a .mat log, its folder, or a dataset), mapped as
  /// `sonarbench map LOG --scene SCENE --score` maps it, beside the simulated scene; "" for none.
  std::string log;
  int threads = 0;
  std::function<void(std::size_t done, std::size_t total)> progress;
};

/// One row of the study: a setting's map of the simulated scene and, if given, of the log, each
/// scored against the scene's surfaces (ScoreMap) as `report.json`'s metrics.
struct DetectorRow {
  DetectorItem item;
  MapMetrics scene;
  std::optional<MapMetrics> log;
};

/// Maps the scene, simulated once (the scene's seed unless `seed`), and the log, read once, with
/// each setting; the rest of the mapping section is the scene's. Throws InputError for a log that
/// cannot be read or placed in the scene (as `map --score` does).
[[nodiscard]] std::vector<DetectorRow> RunDetectorStudy(const Scene& scene,
                                                        const DetectorStudyOptions& options);

/// detectors.csv (a row per setting), precision_vs_recall_scene.png and, with a log,
/// precision_vs_recall_log.png (precision against recall at one cell of tolerance) and study.json,
/// into `dir` (a folder the caller owns, e.g. an OutputDirectory's write_root()).
void WriteDetectorStudy(const std::string& dir, const Scene& scene,
                        const DetectorStudyOptions& options, const std::vector<DetectorRow>& rows);

/// The files WriteDetectorStudy writes, the record (study.json) last.
inline const std::vector<std::string> kDetectorStudyFiles = {
    "detectors.csv", "precision_vs_recall_scene.png", "precision_vs_recall_log.png", "study.json"};

}  // namespace sonarbench::sim
