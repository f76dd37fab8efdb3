#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/app/certainty.hpp"
#include "sonarbench/sim/eval/scene_score.hpp"
#include "sonarbench/sim/sonar/scene_world.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// A recorded log run through the production mapper.
struct LogMapResult {
  std::string input;
  /// "mat" (a real .mat log) or "dataset" (a sonarbench dataset directory).
  std::string source;
  std::size_t beams = 0;
  std::size_t sweeps = 0;
  std::size_t truncated_beams = 0;
  double import_s = 0.0;
  double map_s = 0.0;
  mapping::BatchStats totals;
  std::unique_ptr<mapping::Mapper> mapper;
  std::vector<mapping::Beam> first_sweep;
  /// Every beam as mapped, from the pose it was mapped from.
  std::vector<mapping::Beam> mapped;
  /// The beams' geometry: the log's own for a dataset, else the one MapLog was given.
  mapping::SensorGeometry sensor;
  /// Every beam's pose as mapped.
  std::vector<BeamPose> poses;
  /// The map scored against a scene (ScoreLogMap), when it was.
  std::optional<SceneScore> score;
  /// The occupied cells' probability sweep by sweep, when scored (SweepCertainty).
  std::optional<CertaintyCurve> certainty;
  /// What the user should know about the score (a dataset simulated from other scene files).
  std::vector<std::string> warnings;
};

/// The `.mat` log to read when `input` is a directory that is not a dataset (no manifest.json)
/// and holds exactly one `.mat` file, as the real log's folder does; "" when `input` is a
/// dataset, a file, or a directory without one. Throws InputError when it holds several.
[[nodiscard]] std::string MatLogInDirectory(const std::string& input);

/// The files reading `input` opens (a log, the log a folder holds, or a dataset's manifest and
/// the files of its folders): what no output may overwrite.
[[nodiscard]] std::vector<std::string> LogInputFiles(const std::string& input);

/// Reads a real `.mat` log (a file, or a folder holding just one, see MatLogInDirectory) or a
/// dataset directory (io::ReadDataset; its own sensor geometry replaces `sensor`) and maps it
/// sweep by sweep (BeamsPerSweep() consecutive beams each; the last sweep may be partial). A
/// `.mat` log's vehicle is static at its own origin: with `place_in` every beam of one is mapped
/// from that scene's static sonar pose instead (StaticSonarPose, to score it against the scene);
/// a dataset's beams keep their own, but for an imported log's, which are placed the same way. A
/// simulated dataset scored against another scene than its manifest names is refused. A map that
/// would hold more than `budgets.max_cells` cells (MapCellsEstimate over the beams' poses) is
/// refused before it is made. `progress` counts the sweeps mapped. Throws InputError for input that
/// is not a readable log.
[[nodiscard]] LogMapResult MapLog(const std::string& input, const mapping::SensorGeometry& sensor,
                                  const mapping::MapperConfig& config,
                                  const Scene* place_in = nullptr, const Budgets& budgets = {},
                                  const StageProgress& progress = {});

/// The static sonar pose of `scene` (its first beam's), where a `.mat` log of the place is mapped
/// to score it against the scene. Throws InputError when the scene's sonar moves: a static log
/// cannot be placed along a trajectory.
[[nodiscard]] Eigen::Isometry3d StaticSonarPose(const Scene& scene);

/// Scores `result`'s map against `scene` as `sonarbench run` scores a simulated one
/// (ScoreAgainstScene), from the poses the log's beams were mapped from and over the log's own
/// beam geometry, in the scene's `world` (built here when null).
[[nodiscard]] SceneScore ScoreLogMap(const LogMapResult& result, const Scene& scene,
                                     const SceneWorld* world = nullptr);

/// The files WriteLogMapOutputs writes, relative to its `out_dir`.
inline const std::vector<std::string> kLogMapOutputFiles = {
    "map.bt",    "map.ot",  "map_top.png", "map_side.png", "certainty.png", "certainty.csv",
    "polar.png", "fan.png", "report.html", "junit.xml",    "report.json"};

/// Writes `map.bt`, `map.ot`, `map_top.png`, `polar.png`, `fan.png`, `report.html`, with
/// `scene` and a verdict (the map scored against it) `junit.xml` and `map_side.png` (the map
/// images then against the truth) and, with a certainty curve, `certainty.csv` and `.png`, and
/// `report.json` (the scores under "metrics", verdict and criteria if scored, and the sha256 of the
/// others under "files_sha256") into `out_dir`, each atomically, the report last.
void WriteLogMapOutputs(const std::string& out_dir, const LogMapResult& result,
                        const Scene* scene = nullptr);

}  // namespace sonarbench::sim
