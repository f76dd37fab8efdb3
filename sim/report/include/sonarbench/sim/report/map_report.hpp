#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "sonarbench/sim/eval/scene_score.hpp"
#include "sonarbench/sim/report/report_page.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// junit.xml of a scored map: ScoredJunitXml's arguments but the verdict.
struct JunitCase {
  std::string name;  ///< the first test case: "scenario", "score" or "map"
  std::string note;  ///< its system-out
  std::vector<std::pair<std::string, std::string>> properties;
  double seconds = 0.0;
};

/// The report of a map, scored against a scene or not, as `run`, `score` and `map` write it.
struct MapReport {
  std::string title;              ///< report.html's <title>, before " PASS" or " FAIL"
  std::string heading;            ///< its <h1>
  std::string intro_html;         ///< what was mapped, before the criteria
  std::string view3d_html;        ///< the 3D view (View3dHtml), after the metrics
  std::string after_scores_html;  ///< after the 3D view (the run's timings)
  std::vector<ReportImage> images;
  nlohmann::json json;             ///< report.json but for the scores and files_sha256
  std::vector<std::string> files;  ///< what the command wrote beside, covered by files_sha256
  const Scene* scene = nullptr;    ///< the scene scored against, with `score`
  const SceneScore* score = nullptr;
  JunitCase junit;  ///< with `score`
};

/// Writes into `out_dir`, each file atomically: the images; with a score, junit.xml; report.html
/// (the verdict, `intro_html`, criteria and metrics, the 3D view, `after_scores_html`, the
/// images embedded); and, last, report.json: `json` with the verdict, criteria and metrics, and the
/// sha256 of `files`, the images, junit.xml and report.html.
void WriteMapReport(const std::string& out_dir, const MapReport& report);

}  // namespace sonarbench::sim
