#include "sonarbench/sim/app/score_map.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/text.hpp"
#include "sonarbench/sim/report/map_report.hpp"
#include "sonarbench/sim/report/report.hpp"
#include "sonarbench/sim/report/report_page.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"
#include "sonarbench/sim/report/view3d.hpp"
#include "sonarbench/sim/sonar/scene_world.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"

namespace sonarbench::sim {
namespace {

// OctoMap's keys address ±2^15 cells around the origin.
constexpr double kKeyHalfRange = 32768.0;

double SecondsSince(std::chrono::steady_clock::time_point& start) {
  const auto now = std::chrono::steady_clock::now();
  const double seconds = std::chrono::duration<double>(now - start).count();
  start = now;
  return seconds;
}

std::string Metres(const Eigen::Vector3d& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.2f, %.2f, %.2f)", p.x(), p.y(), p.z());
  return text;
}

std::string Percent(double share) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f%%", 100.0 * share);
  return text;
}

// Refuses a resolution at which the scene's truth is over budget, before anything is built.
void CheckTruthBudget(const std::string& map_file, double resolution_m, const Scene& scene,
                      const Budgets& budgets) {
  Scene at_map = scene;
  at_map.mapping.resolution_m = resolution_m;
  const double cells = EstimateScene(at_map).truth_cells;
  if (!(cells <= budgets.max_cells)) {
    throw InputError(map_file + ": at the map's resolution " + io::Number(resolution_m) +
                     " m the ground truth of " + scene.file + " takes about " + io::Number(cells) +
                     " cells, over the limit of " + io::Number(budgets.max_cells) +
                     " (--max-cells raises it)");
  }
}

// Refuses a scene whose surfaces reach past the keys a map of `resolution_m` addresses.
void CheckKeyRange(const std::string& map_file, double resolution_m, const Scene& scene,
                   const std::vector<TriangleMesh>& meshes) {
  const double reach = kKeyHalfRange * resolution_m;
  for (const TriangleMesh& mesh : meshes) {
    for (const Eigen::Vector3f& v : mesh.vertices) {
      if (v.cast<double>().cwiseAbs().maxCoeff() < reach) continue;
      throw InputError(map_file + ": a map of resolution " + io::Number(resolution_m) +
                       " m addresses only ±" + io::Number(reach) + " m; mesh '" + mesh.name +
                       "' of " + scene.file + " reaches " + Metres(v.cast<double>()));
    }
  }
}

// The frame check: the box the sonar reaches and the share of occupied cells inside it.
void CheckFrame(MapFileScore& s, const Scene& scene, const std::vector<BeamPose>& poses) {
  const double range = scene.sensor.geometry.MaxRangeM();
  for (std::size_t b = 0; b < poses.size(); ++b) {
    const Eigen::Vector3d p = poses[b].T_world_sonar.translation();
    s.reach_lo_m = b == 0 ? p : s.reach_lo_m.cwiseMin(p);
    s.reach_hi_m = b == 0 ? p : s.reach_hi_m.cwiseMax(p);
  }
  s.reach_lo_m.array() -= range;
  s.reach_hi_m.array() += range;
  const MapCells cells = CollectMapCells(*s.map);
  std::size_t inside = 0;
  for (const octomap::OcTreeKey& key : cells.occupied) {
    const Eigen::Vector3d c(s.map->keyToCoord(key[0]), s.map->keyToCoord(key[1]),
                            s.map->keyToCoord(key[2]));
    inside +=
        (c.array() >= s.reach_lo_m.array()).all() && (c.array() <= s.reach_hi_m.array()).all();
  }
  if (cells.occupied.empty()) return;
  s.occupied_in_reach = static_cast<double>(inside) / static_cast<double>(cells.occupied.size());
  if (s.occupied_in_reach >= kMinOccupiedInReach) return;
  throw InputError(s.map_file + ": " + std::to_string(inside) + " of its " +
                   std::to_string(cells.occupied.size()) +
                   " occupied cells lie within reach of the sonar of " + scene.file + " (the box " +
                   Metres(s.reach_lo_m) + " to " + Metres(s.reach_hi_m) +
                   " m: its trajectory grown by its range); a map is scored in the scene's world "
                   "frame, in metres. Is this map in another frame?");
}

double TotalSeconds(const MapFileScore& s) {
  return s.read_s + s.score.ground_truth_s + s.score.score_s;
}

// report.html's lines before the criteria: the map, the scene, the frame check.
std::string ScoreIntroHtml(const Scene& scene, const MapFileScore& s) {
  std::ostringstream html;
  html << "<p>Map <code>" << XmlEscape(s.map_file) << "</code> (." << s.file.format << ", "
       << s.file.resolution_m << " m cells, " << s.file.nodes << " nodes) against scene <code>"
       << XmlEscape(scene.file) << "</code>, sensor model <code>"
       << XmlEscape(scene.sensor_model_file) << "</code>, the truth seen from the "
       << ScenarioBeamCount(scene) << " beams of its trajectory; " << Seconds(TotalSeconds(s))
       << " s.</p>\n<p>Frame check: " << Percent(s.occupied_in_reach)
       << " of the map's occupied cells lie within the sonar's reach, the box "
       << Metres(s.reach_lo_m) << " to " << Metres(s.reach_hi_m) << " m (at least "
       << Percent(kMinOccupiedInReach) << " must).</p>\n";
  return html.str();
}

nlohmann::json Vector(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

}  // namespace

MapFileScore ScoreMapFile(const std::string& map_file, const Scene& scene, const Budgets& budgets,
                          const StageProgress& progress) {
  const auto clock = std::chrono::steady_clock::now();
  io::OcTreeFileInfo info;
  std::unique_ptr<octomap::OcTree> map = io::ReadOcTreeFile(map_file, budgets.max_cells, &info);
  return ScoreMapTree(std::move(map), map_file, info, scene, budgets, progress, clock);
}

MapFileScore ScoreMapTree(std::unique_ptr<octomap::OcTree> map, const std::string& map_file,
                          const io::OcTreeFileInfo& info, const Scene& scene,
                          const Budgets& budgets, const StageProgress& progress,
                          std::chrono::steady_clock::time_point clock) {
  MapFileScore s;
  s.map_file = map_file;
  s.map = std::move(map);
  s.file = info;
  CheckTruthBudget(map_file, s.file.resolution_m, scene, budgets);
  const std::vector<BeamPose> poses = TruePoses(scene, ScenarioBeamCount(scene));
  if (!poses.empty()) s.sonar_start_m = poses.front().T_world_sonar.translation();
  CheckFrame(s, scene, poses);
  s.read_s = SecondsSince(clock);

  const SceneWorld world(scene);
  CheckKeyRange(map_file, s.file.resolution_m, scene, world.meshes);
  s.score =
      ScoreAgainstScene(*s.map, scene, world.meshes, world.tracer, poses, scene.sensor.geometry,
                        [&progress](std::string_view stage, std::size_t done, std::size_t total) {
                          if (progress && stage == "observable") progress(done, total);
                        });
  if (s.score.metrics.ghost_share > kGhostShareWarning) {
    s.score.verdict.warnings.push_back(
        FormatMetricValue(s.score.metrics.ghost_share) +
        " of the map's occupied cells lie more than 2 "
        "cells from every surface of the scene: is the map in the scene's frame (origin, axes, "
        "metres)?");
  }
  return s;
}

void WriteMapFileScoreOutputs(const std::string& out_dir, const Scene& scene,
                              const MapFileScore& s) {
  CreateOutputDirectory(out_dir);
  MapReport r;
  r.title = "sonarbench: " + scene.name;
  r.heading = "sonarbench score: " + scene.name;
  r.intro_html = ScoreIntroHtml(scene, s);
  const MapCells cells = CollectMapCells(*s.map);
  r.images = MapTruthImages(
      *s.map, cells, s.score.truth, s.score.observable, s.score.detector_ghosts, s.sonar_start_m,
      scene.name + ", " + std::filesystem::path(s.map_file).filename().string());
  r.view3d_html =
      View3dHtml(cells, s.file.resolution_m, &s.score, SonarPath(scene, ScenarioBeamCount(scene)));
  r.scene = &scene;
  r.score = &s.score;
  r.junit = {
      "score", s.map_file, {{"scene_file", scene.file}, {"map_file", s.map_file}}, TotalSeconds(s)};
  r.json = ReportHeader();
  r.json["schema_version"] = kScenarioReportSchema;
  r.json.update({{"scene", SceneJson(scene)},
                 {"map",
                  {{"file", s.map_file},
                   {"format", s.file.format},
                   {"resolution_m", s.file.resolution_m},
                   {"nodes", s.file.nodes},
                   {"occupied_cells", s.score.metrics.occupied_cells},
                   {"free_cells", s.score.metrics.free_cells}}},
                 {"frame_check",
                  {{"reach_lo_m", Vector(s.reach_lo_m)},
                   {"reach_hi_m", Vector(s.reach_hi_m)},
                   {"occupied_in_reach", s.occupied_in_reach},
                   {"min_occupied_in_reach", kMinOccupiedInReach}}},
                 {"beams", ScenarioBeamCount(scene)},
                 {"timing",
                  {{"read_s", s.read_s},
                   {"ground_truth_s", s.score.ground_truth_s},
                   {"score_s", s.score.score_s},
                   {"total_s", TotalSeconds(s)}}},
                 {"outputs",
                  {{"map_top", "map_top.png"},
                   {"map_side", "map_side.png"},
                   {"junit", "junit.xml"},
                   {"html", "report.html"}}}});
  WriteMapReport(out_dir, r);
}

}  // namespace sonarbench::sim
