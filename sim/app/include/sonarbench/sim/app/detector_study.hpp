#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/sonar/bin_labels.hpp"
#include "sonarbench/sim/sonar/scene_world.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// One setting of the detector study: the scene's detection with these changes.
struct SimulatedScene;

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
  /// Only the beams whose head angle lies in [first, second) degrees (0-360), of the simulated
  /// scene and of the log alike, mapped sweep by sweep and scored against what those beams see:
  /// one half of a sweep to fit a model on, the other to check it.
  std::optional<std::pair<double, double>> heads_deg;
  std::function<void(std::size_t done, std::size_t total)> progress;
  /// The scene's world, when the caller has built it already; else the study builds it.
  const SceneWorld* world = nullptr;
  /// The scene simulated at `seed` over every head angle (SimulateForScoring without heads), when
  /// the caller has it already (one simulation for several parts); else the study simulates it.
  const SimulatedScene* simulated = nullptr;
};

/// Whether `head_angle_rad` lies in [heads.first, heads.second) degrees, taken modulo 360.
[[nodiscard]] bool InHeads(double head_angle_rad, const std::pair<double, double>& heads_deg);

/// A setting's echoes on the simulated scene by the path that made them (the simulator's truth):
/// the first echo of each beam and the later ones apart, indexed by io::EchoPath. Each echo counts
/// under the path that has the most power in most of its first three bins (the first bin's on a
/// tie).
struct EchoPathCounts {
  std::array<std::size_t, kEchoPaths> first{};
  std::array<std::size_t, kEchoPaths> later{};
};

/// One row of the study: a setting's map of the simulated scene and, if given, of the log, each
/// scored against the scene's surfaces (ScoreMap) as `report.json`'s metrics, and the simulated
/// scene's echoes by path.
struct DetectorRow {
  DetectorItem item;
  MapMetrics scene;
  std::optional<MapMetrics> log;
  EchoPathCounts scene_paths;
};

/// Maps the scene, simulated once (the scene's seed unless `seed`), and the log, read once, with
/// each setting; the rest of the mapping section is the scene's. Throws InputError for a log that
/// cannot be read or placed in the scene (as `map --score` does).
[[nodiscard]] std::vector<DetectorRow> RunDetectorStudy(const Scene& scene,
                                                        const DetectorStudyOptions& options);

/// The figures the scene's maps are held to the log's by: their names in study.json and
/// fidelity.json, and the criteria metrics (MetricValue) they are.
inline constexpr std::pair<const char*, const char*> kAgreementFigures[] = {
    {"precision_1", "occupied_precision_within_1"},
    {"recall_1", "occupied_recall_within_1"},
    {"f1_1", "occupied_f1_within_1"},
    {"ghost_arc_share", "ghost_arc_share"},
    {"ghost_echo_share", "ghost_echo_share"}};

/// How closely the simulated scene's maps follow the log's over the study's settings, for one
/// figure (a MapMetrics value in [0, 1]): the Spearman rank correlation of the two columns
/// (average ranks for ties; NaN when either column is constant) and their mean and largest
/// absolute difference.
struct Agreement {
  std::string figure;  ///< "precision_1", "recall_1", "f1_1", "ghost_arc_share", "ghost_echo_share"
  double spearman = 0.0;
  double mean_abs_difference = 0.0;
  double max_abs_difference = 0.0;
};
/// The five figures above, over the rows that have a log (none: empty).
[[nodiscard]] std::vector<Agreement> StudyAgreement(const std::vector<DetectorRow>& rows);
/// The Spearman rank correlation of two equally long columns (average ranks for ties).
[[nodiscard]] double Spearman(const std::vector<double>& a, const std::vector<double>& b);
/// The index of the row with the best F1 at one cell: of the scene's maps or, with `log`, of the
/// log's (the first among equals).
[[nodiscard]] std::size_t BestF1Row(const std::vector<DetectorRow>& rows, bool log);

/// What "the simulated scene predicts the log's maps" asks of each figure of StudyAgreement.
struct MapGoals {
  double max_mean_abs_difference = 0.03;
  double max_abs_difference = 0.08;
  double min_spearman = 0.95;
};

/// StudyAgreement and BestF1Row as JSON, each figure with whether it meets `goals`, and "meets":
/// every figure does and the best setting by F1 at 1 cell is the same on both. Rows without a
/// log: null.
[[nodiscard]] nlohmann::json AgreementJson(const std::vector<DetectorRow>& rows,
                                           const MapGoals& goals = {});

/// detectors.csv (a row per setting), precision_vs_recall_scene.png and, with a log,
/// precision_vs_recall_log.png (precision against recall at one cell of tolerance) and study.json,
/// into `dir` (a folder the caller owns, e.g. an io::OutputDirectory's write_root()).
void WriteDetectorStudy(const std::string& dir, const Scene& scene,
                        const DetectorStudyOptions& options, const std::vector<DetectorRow>& rows);

/// The files WriteDetectorStudy writes, the record (study.json) last.
inline const std::vector<std::string> kDetectorStudyFiles = {
    "detectors.csv", "precision_vs_recall_scene.png", "precision_vs_recall_log.png", "study.json"};

}  // namespace sonarbench::sim
