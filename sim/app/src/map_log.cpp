#include "sonarbench/sim/app/map_log.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/mapping_yaml.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/io/octomap_file.hpp"
#include "sonarbench/io/text.hpp"
#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/report/images.hpp"
#include "sonarbench/sim/report/map_report.hpp"
#include "sonarbench/sim/report/report.hpp"
#include "sonarbench/sim/report/report_page.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"
#include "sonarbench/sim/report/view3d.hpp"
#include "sonarbench/sim/sonar/scene_world.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"

namespace sonarbench::sim {

std::string MatLogInDirectory(const std::string& input) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_directory(input, error) || fs::exists(fs::path(input) / "manifest.json", error)) {
    return {};
  }
  std::vector<std::string> logs;
  for (const auto& entry : fs::directory_iterator(input, error)) {
    if (entry.is_regular_file(error) && entry.path().extension() == ".mat") {
      logs.push_back(entry.path().string());
    }
  }
  if (logs.size() <= 1) return logs.empty() ? std::string() : logs.front();
  std::sort(logs.begin(), logs.end());
  std::string names;
  for (const auto& log : logs) names += "\n  " + log;
  throw InputError(input + ": not a sonarbench dataset and holds " + std::to_string(logs.size()) +
                   " .mat logs; name the one to map:" + names);
}

std::vector<std::string> LogInputFiles(const std::string& input) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_directory(input, error)) return {input};
  if (std::string log = MatLogInDirectory(input); !log.empty()) return {log};
  // A dataset: its manifest and every file of its folders (what ReadDataset and the labels'
  // readers open); the outputs a command writes beside them are not read.
  std::vector<std::string> files = {(fs::path(input) / "manifest.json").string()};
  for (const char* folder : {"beams", "images", "poses", "truth"}) {
    for (fs::recursive_directory_iterator it(fs::path(input) / folder, error), end;
         !error && it != end; it.increment(error)) {
      if (!it->is_directory(error)) files.push_back(it->path().string());
    }
  }
  return files;
}

namespace {

// Where a dataset's beams are mapped to score them against `scene`: an imported log is static at
// its own origin and goes to the scene's sonar pose, as a .mat log does; a simulated dataset keeps
// its poses and must be of that scene. Differences that still allow a score go to `warnings`.
std::optional<Eigen::Isometry3d> DatasetPlacement(const io::Dataset& dataset,
                                                  const std::string& dir, const Scene& scene,
                                                  std::vector<std::string>& warnings) {
  const nlohmann::json& m = dataset.manifest;
  const std::string source = m.value("source", "");
  // A bag whose transforms move the sonar is mapped where they put it; a static log goes to
  // the scene's sonar pose.
  const nlohmann::json log = m.value("log", nlohmann::json::object());
  if (source == "import" && log.is_object() && log.value("poses", "") == "tf, moving") {
    return std::nullopt;
  }
  if (source == "import") return StaticSonarPose(scene);
  if (source != "simulate") {
    throw InputError(dir + "/manifest.json: 'source' is " + io::Quoted(source) +
                     "; expected 'simulate' or 'import' to score it against a scene");
  }
  const nlohmann::json named = m.value("scene", nlohmann::json::object());
  const std::string name = named.is_object() ? named.value("name", "") : "";
  if (name != scene.name) {
    throw InputError(dir + ": a dataset of scene " + io::Quoted(name) + " (manifest.json); it " +
                     "cannot be scored against scene " + io::Quoted(scene.name) + " (" +
                     scene.file + "): score it against the scene it was simulated from");
  }
  const nlohmann::json seed = m.value("seed", nlohmann::json());
  const nlohmann::json truth = m.value("truth", nlohmann::json::object());
  const bool labels = truth.is_object() && truth.contains("labels");
  if (seed.is_number_unsigned() &&
      DatasetConfigHash(scene, seed.get<std::uint64_t>(), labels) != m.value("config_sha256", "")) {
    warnings.push_back(dir + " was simulated from other files than " + scene.file +
                       " and its meshes and sensor model now hold (config_sha256 differs): the "
                       "truth is the scene's as it is now");
  }
  return std::nullopt;
}

}  // namespace

LogMapResult MapLog(const std::string& input, const mapping::SensorGeometry& sensor,
                    const mapping::MapperConfig& config, const Scene* place_in,
                    const Budgets& budgets, const StageProgress& progress) {
  LogMapResult result;
  result.input = input;
  auto start = std::chrono::steady_clock::now();
  std::vector<mapping::Beam> beams;
  mapping::SensorGeometry geometry = sensor;
  const std::string log_file = MatLogInDirectory(input);
  if (log_file.empty() && std::filesystem::is_directory(input)) {
    io::Dataset dataset = io::ReadDataset(input);
    geometry = dataset.sensor;  // a dataset carries its sensor
    const auto pose =
        place_in ? DatasetPlacement(dataset, input, *place_in, result.warnings) : std::nullopt;
    beams = std::move(dataset.beams);
    result.source = "dataset";
    if (pose) {
      for (mapping::Beam& beam : beams) beam.T_world_sonar = *pose;
    }
  } else {
    // The scene is checked before the log is read: a moving one is refused at once.
    const std::optional<Eigen::Isometry3d> pose =
        place_in ? std::optional(StaticSonarPose(*place_in)) : std::nullopt;
    io::MatLog log = io::ReadMatLog(log_file.empty() ? input : log_file);
    beams = std::move(log.beams);
    result.truncated_beams = log.truncated_beams;
    result.source = "mat";
    if (!log_file.empty()) result.input = log_file;
    if (pose) {
      for (mapping::Beam& beam : beams) beam.T_world_sonar = *pose;
    }
  }
  for (const mapping::Beam& beam : beams) {
    result.poses.push_back({beam.T_world_sonar, beam.head_angle_rad});
  }
  auto now = std::chrono::steady_clock::now();
  result.import_s = std::chrono::duration<double>(now - start).count();
  result.beams = beams.size();

  CheckBeamsMapCells(beams, geometry, config.resolution_m, budgets, input);

  start = now;
  result.sensor = geometry;
  result.mapper = std::make_unique<mapping::Mapper>(config, geometry);
  result.totals = result.mapper->IntegrateSweeps(beams, progress);
  const auto per_sweep = static_cast<std::size_t>(geometry.BeamsPerSweep());
  result.sweeps = (beams.size() + per_sweep - 1) / per_sweep;
  result.first_sweep.assign(beams.begin(),
                            beams.begin() + static_cast<long>(std::min(per_sweep, beams.size())));
  result.map_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.mapped = std::move(beams);
  return result;
}

Eigen::Isometry3d StaticSonarPose(const Scene& scene) {
  const std::size_t beams = static_cast<std::size_t>(scene.sweeps) *
                            static_cast<std::size_t>(scene.sensor.geometry.BeamsPerSweep());
  const Eigen::Isometry3d first = ScheduleBeam(scene, 0).pose.T_world_sonar;
  for (std::size_t b = 1; b < beams; ++b) {
    if (!ScheduleBeam(scene, b).pose.T_world_sonar.isApprox(first, 1e-12)) {
      throw InputError(scene.file + ": the sonar moves along the scene's trajectory (beam " +
                       std::to_string(b) +
                       "); a .mat log is static and can be scored only against a scene whose "
                       "sonar is, or simulate and map the scene as a dataset");
    }
  }
  return first;
}

SceneScore ScoreLogMap(const LogMapResult& result, const Scene& scene, const SceneWorld* world) {
  std::optional<SceneWorld> own;
  if (!world) world = &own.emplace(scene);
  return ScoreAgainstScene(result.mapper->tree(), scene, world->meshes, world->tracer, result.poses,
                           result.sensor);
}

namespace {

// report.html's lines before the criteria: what was mapped, the mapping, the scene, warnings.
std::string LogMapIntroHtml(const LogMapResult& result, const Scene* scene, const MapCells& cells) {
  std::ostringstream html;
  const auto& t = result.totals;
  html << TableHtml("Log and map",
                    {{"input", result.input},
                     {"kind", result.source == "mat" ? ".mat log" : "dataset"},
                     {"beams", std::to_string(result.beams)},
                     {"truncated beams", std::to_string(result.truncated_beams)},
                     {"sweeps", std::to_string(result.sweeps)},
                     {"beams with an obstacle", std::to_string(t.beams_with_obstacle)},
                     {"occupied cells", std::to_string(cells.occupied.size())},
                     {"free cells", std::to_string(cells.free.size())},
                     {"resolution [m]", FormatMetricValue(result.mapper->config().resolution_m)},
                     {"import [s]", Seconds(result.import_s)},
                     {"map [s]", Seconds(result.map_s)}},
                    false);
  html << MappingHtml(result.mapper->config());
  if (scene) html << "<p>Scored against scene <code>" << XmlEscape(scene->file) << "</code>.</p>\n";
  for (const std::string& warning : result.warnings) {
    html << "<p class=\"acceptable\">" << XmlEscape(warning) << "</p>\n";
  }
  return html.str();
}

// report.json of a mapped log, but for its scores and the files' hashes.
nlohmann::json LogMapReportJson(const LogMapResult& result, const MapCells& cells) {
  const auto& t = result.totals;
  const auto& c = result.mapper->config();
  nlohmann::json report = ReportHeader();
  report.update({{"input", result.input},
                 {"input_kind", result.source},
                 {"beams", result.beams},
                 {"sweeps", result.sweeps},
                 {"truncated_beams", result.truncated_beams},
                 {"mapping", MapperConfigJson(c)},
                 {"map",
                  {{"occupied_cells", cells.occupied.size()},
                   {"free_cells", cells.free.size()},
                   {"beams_with_obstacle", t.beams_with_obstacle},
                   {"ray_casts", t.ray_casts},
                   {"cell_visits", t.cell_visits},
                   {"cell_updates", t.free_cells + t.occupied_cells},
                   {"visits_per_updated_cell",
                    t.free_cells + t.occupied_cells == 0
                        ? 0.0
                        : static_cast<double>(t.cell_visits) /
                              static_cast<double>(t.free_cells + t.occupied_cells)}}},
                 {"timing", {{"import_s", result.import_s}, {"map_s", result.map_s}}},
                 {"outputs",
                  {{"map", "map.bt"},
                   {"map_full", "map.ot"},
                   {"map_top", "map_top.png"},
                   {"polar", "polar.png"},
                   {"fan", "fan.png"},
                   {"html", "report.html"}}}});
  return report;
}

// The seed paper's figure 12: the occupied cells' mean probability against sweeps.
ReportImage CertaintyImage(const CertaintyCurve& curve, const std::string& name) {
  std::vector<double> sweeps;
  for (std::size_t s = 1; s <= curve.true_mean.size(); ++s)
    sweeps.push_back(static_cast<double>(s));
  const std::vector<PlotSeries> series = {
      {"on a surface (" + std::to_string(curve.true_cells) + " cells)",
       {60, 160, 60},
       sweeps,
       curve.true_mean},
      {"off every surface (" + std::to_string(curve.false_cells) + " cells)",
       {40, 40, 220},
       sweeps,
       curve.false_mean}};
  return {"certainty.png",
          "The cells the final map holds occupied, those on a scene surface and the others: their "
          "mean occupancy probability after each sweep (the seed paper's figure 12; "
          "certainty.csv).",
          EncodePng(RenderLinePlot(name + ": certainty against sweeps", "sweeps",
                                   "mean occupancy probability", series, false, 0.0, 1.0))};
}

// The map's images: against the truth when `scene`, else from above.
std::vector<ReportImage> MapImages(const LogMapResult& result, const Scene* scene,
                                   const std::string& name, const MapCells& cells) {
  if (scene) {
    Eigen::Vector3d sonar = Eigen::Vector3d::Zero();
    if (!result.poses.empty()) sonar = result.poses.front().T_world_sonar.translation();
    return MapTruthImages(result.mapper->tree(), cells, result.score->truth,
                          result.score->observable, result.score->detector_ghosts, sonar,
                          scene->name + ", " + name);
  }
  MapView top;
  top.resolution_m = result.mapper->config().resolution_m;
  top.title = name + ": map from above";
  return {{"map_top.png",
           "Occupied cells from above (white), free cells grey, whole pixels per column.",
           EncodePng(RenderMapView(cells, {}, {}, top))}};
}

// map.bt and map.ot, the map's cells and images, and the first sweep's images, side by side on
// the mapper's threads: the map's images, then polar.png and fan.png.
std::vector<ReportImage> WriteMapAndImages(const std::filesystem::path& dir,
                                           const LogMapResult& result, const Scene* scene,
                                           const std::string& name, MapCells& cells) {
  std::vector<ReportImage> images;
  ReportImage polar, fan;
  // The truth images walk the tree: built first, it may be read by the tasks at once. The rest
  // reads the map's leaves alone.
  if (scene) (void)result.mapper->tree();
  const std::function<void()> tasks[] = {
      [&] { fan = FanImage(result.first_sweep, name); },
      [&] {
        cells = CollectMapCells(*result.mapper);
        images = MapImages(result, scene, name, cells);
      },
      [&] { io::WriteMapFile(*result.mapper, (dir / "map.ot").string(), io::MapFormat::kFull); },
      [&] { io::WriteMapFile(*result.mapper, (dir / "map.bt").string(), io::MapFormat::kBinary); },
      [&] { polar = PolarImage(result.first_sweep, name); }};
  RunTasks(result.mapper->config().threads, tasks);
  images.push_back(std::move(polar));
  images.push_back(std::move(fan));
  return images;
}

}  // namespace

void WriteLogMapOutputs(const std::string& out_dir, const LogMapResult& result,
                        const Scene* scene) {
  namespace fs = std::filesystem;
  CreateOutputDirectory(out_dir);
  const fs::path dir(out_dir);
  const std::string name = fs::path(result.input).filename().string();
  const bool scored = scene && result.score;
  MapCells cells;
  MapReport r;
  r.images = WriteMapAndImages(dir, result, scored ? scene : nullptr, name, cells);
  r.files = {"map.bt", "map.ot"};
  r.json = LogMapReportJson(result, cells);
  if (scored) {
    r.scene = scene;
    r.score = &*result.score;
    r.junit = {"map",
               result.input,
               {{"scene_file", scene->file}, {"input", result.input}},
               result.import_s + result.map_s};
    r.json["outputs"]["junit"] = "junit.xml";
    r.json["outputs"]["map_side"] = "map_side.png";
    if (result.certainty) {
      r.images.push_back(CertaintyImage(*result.certainty, scene->name + ", " + name));
      WriteFileAtomically((dir / "certainty.csv").string(),
                          [&](std::ostream& out) { out << CertaintyCsv(*result.certainty); });
      r.files.push_back("certainty.csv");
      r.json["outputs"]["certainty"] = {"certainty.csv", "certainty.png"};
    }
  }
  if (!result.warnings.empty()) r.json["warnings"] = result.warnings;
  r.title = "sonarbench map: " + name;
  r.heading = "sonarbench map: " + name + (scored ? " against " + scene->name : "");
  r.intro_html = LogMapIntroHtml(result, scored ? scene : nullptr, cells);
  std::vector<Eigen::Vector3d> path;
  for (std::size_t b = 0; b < result.poses.size(); b += 10) {
    path.push_back(result.poses[b].T_world_sonar.translation());
  }
  r.view3d_html = View3dHtml(cells, result.mapper->config().resolution_m,
                             scored ? &*result.score : nullptr, path);
  WriteMapReport(out_dir, r);
}

}  // namespace sonarbench::sim
