#include "sonarbench/sim/app/detector_study.hpp"

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sonarbench/io/mapping_yaml.hpp"
#include "sonarbench/mapping/atomic_file.hpp"
#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/app/map_log.hpp"
#include "sonarbench/sim/app/simulated_scene.hpp"
#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/report/images.hpp"
#include "sonarbench/sim/report/report.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/ray_tracer.hpp"

namespace sonarbench::sim {
namespace {

using nlohmann::json;
using Detection = mapping::DetectionConfig;

// The echo rule of a setting, as the CSV, the plot's legend and the item's name give it.
std::string EchoRule(const Detection& d) {
  if (d.max_obstacles == 1) return "first echo";
  return std::to_string(d.max_obstacles) + " echoes, " + io::LaterEchoesName(d.later_echoes);
}

// A map of `beams` with `detection`, scored against the truth and what a perfect sensor sees.
MapMetrics MapAndScore(const mapping::MapperConfig& base, const Detection& detection,
                       const mapping::SensorGeometry& sensor, std::span<const mapping::Beam> beams,
                       const mapping::KeySet& truth, const mapping::KeySet& observable,
                       const DirectEchoes& direct) {
  mapping::MapperConfig config = base;
  config.detection = detection;
  mapping::Mapper mapper(config, sensor);
  (void)mapper.IntegrateSweeps(beams);
  return ScoreMap(mapper.tree(), truth, observable, {}, {}, &direct);
}

json MetricsJson(const MapMetrics& m) {
  return {{"precision", m.occupied_precision},
          {"recall", m.occupied_recall},
          {"precision_1", m.precision_within[1]},
          {"recall_1", m.recall_within[1]},
          {"f1_1", m.f1_within[1]},
          {"ghost_share", m.ghost_share},
          {"ghost_arc_share", m.ghost_arc_share.value_or(NAN)},
          {"ghost_echo_share", m.ghost_echo_share.value_or(NAN)},
          {"column_precision", m.column_precision},
          {"column_recall", m.column_recall},
          {"coverage", m.coverage},
          {"occupied_cells", m.occupied_cells}};
}

const std::vector<std::string> kMetricColumns = {
    "precision",   "recall",          "precision_1",      "recall_1",         "f1_1",
    "ghost_share", "ghost_arc_share", "ghost_echo_share", "column_precision", "column_recall",
    "coverage",    "occupied_cells"};

void WriteCsv(const std::string& path, const std::vector<DetectorRow>& rows, bool with_log) {
  std::ostringstream csv;
  csv << "item,method,threshold,max_obstacles,later_echoes";
  for (const char* source : {"scene", "log"}) {
    if (std::string(source) == "log" && !with_log) continue;
    for (const std::string& c : kMetricColumns) csv << "," << source << "_" << c;
  }
  csv << "\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Detection& d = rows[i].item.detection;
    csv << i << "," << io::DetectionMethodName(d.method) << ","
        << (d.method == Detection::Method::kThreshold ? std::to_string(d.threshold) : "") << ","
        << d.max_obstacles << "," << io::LaterEchoesName(d.later_echoes);
    for (const MapMetrics* m : {&rows[i].scene, rows[i].log ? &*rows[i].log : nullptr}) {
      if (!m) continue;
      const json values = MetricsJson(*m);
      for (const std::string& c : kMetricColumns) csv << "," << values.at(c).dump();
    }
    csv << "\n";
  }
  WriteFileAtomically(path, [&](std::ostream& o) { o << csv.str(); });
}

// Precision against recall at one cell of tolerance, of the scene's maps or the log's: the
// threshold detector a series per echo rule (its thresholds' points), Canny and automatic Canny a
// series each (a point per echo rule).
void WritePlot(const std::string& path, const std::vector<DetectorRow>& rows, bool log) {
  const std::vector<cv::Scalar> colours = {
      {200, 80, 0}, {30, 30, 220}, {40, 160, 40}, {160, 40, 160}, {0, 140, 200}};
  std::map<std::string, std::size_t> order;
  std::vector<PlotSeries> series;
  for (const DetectorRow& row : rows) {
    const Detection& d = row.item.detection;
    const std::string name =
        d.method == Detection::Method::kThreshold
            ? "threshold, " + EchoRule(d)
            : std::string(io::DetectionMethodName(d.method)) + ", each echo rule";
    auto [it, added] = order.emplace(name, series.size());
    if (added) series.push_back({name, colours[series.size() % colours.size()], {}, {}});
    const MapMetrics& m = log ? *row.log : row.scene;
    PlotSeries& s = series[it->second];
    s.x.push_back(m.recall_within[1]);
    s.y.push_back(m.precision_within[1]);
    // Each point says what it is: a threshold, or an echo rule.
    s.labels.push_back(d.method == Detection::Method::kThreshold
                           ? std::to_string(static_cast<int>(d.threshold))
                       : d.max_obstacles == 1 ? "first"
                                              : io::LaterEchoesName(d.later_echoes));
  }
  WritePng(path,
           RenderLinePlot(std::string("Detectors, ") + (log ? "the log" : "the simulated scene") +
                              ": precision against recall (1 cell of tolerance)",
                          "recall (1 cell)", "precision (1 cell)", series, false, 0.0, 1.0,
                          std::pair{0.0, 1.0}));
}

}  // namespace

std::vector<DetectorItem> DetectorStudyItems(const Detection& base) {
  std::vector<DetectorItem> items;
  auto add = [&](Detection d) {
    for (const int rule : {0, 1, 2}) {
      d.max_obstacles = rule == 0 ? 1 : 2;
      d.later_echoes =
          rule == 2 ? Detection::LaterEchoes::kSupported : Detection::LaterEchoes::kStrongest;
      std::ostringstream name;
      name << io::DetectionMethodName(d.method);
      if (d.method == Detection::Method::kThreshold) name << ' ' << d.threshold;
      name << ", " << EchoRule(d);
      items.push_back({name.str(), d});
    }
  };
  for (int threshold = 70; threshold <= 150; threshold += 20) {
    Detection d = base;
    d.method = Detection::Method::kThreshold;
    d.threshold = threshold;
    add(d);
  }
  for (const auto method : {Detection::Method::kCanny, Detection::Method::kAutoCanny}) {
    Detection d = base;
    d.method = method;
    add(d);
  }
  return items;
}

std::vector<DetectorRow> RunDetectorStudy(const Scene& scene, const DetectorStudyOptions& options) {
  const std::vector<DetectorItem> items =
      options.items.empty() ? DetectorStudyItems(scene.mapping.detection) : options.items;
  mapping::MapperConfig base = scene.mapping;
  base.threads = options.threads;
  // The log first (bad input fails before the simulation): read and placed once as `map --score`
  // does, its truth, observable cells and direct echoes kept.
  std::optional<LogMapResult> log;
  std::optional<SceneScore> log_score;
  if (!options.log.empty()) {
    log = MapLog(options.log, scene.sensor.geometry, base, &scene, scene.budgets);
    log_score = ScoreLogMap(*log, scene);
  }
  const std::vector<TriangleMesh> meshes = BuildSceneMeshes(scene);
  const RayTracer tracer(meshes);
  const SimulatedScene simulated =
      SimulateForScoring(scene, meshes, tracer, options.seed.value_or(scene.seed), options.threads);

  std::vector<DetectorRow> rows;
  for (const DetectorItem& item : items) {
    DetectorRow row{item,
                    MapAndScore(base, item.detection, scene.sensor.geometry, simulated.beams,
                                simulated.truth, simulated.observable, simulated.direct),
                    std::nullopt};
    if (log) {
      row.log = MapAndScore(base, item.detection, log->sensor, log->mapped, log_score->truth,
                            log_score->observable, log_score->direct);
    }
    rows.push_back(std::move(row));
    if (options.progress) options.progress(rows.size(), items.size());
  }
  return rows;
}

void WriteDetectorStudy(const std::string& dir, const Scene& scene,
                        const DetectorStudyOptions& options, const std::vector<DetectorRow>& rows) {
  const std::filesystem::path root(dir);
  const bool with_log = !rows.empty() && rows.front().log.has_value();
  WriteCsv((root / "detectors.csv").string(), rows, with_log);
  WritePlot((root / "precision_vs_recall_scene.png").string(), rows, false);
  if (with_log) WritePlot((root / "precision_vs_recall_log.png").string(), rows, true);
  json items = json::array();
  for (const DetectorRow& row : rows) {
    const Detection& d = row.item.detection;
    json item = {{"name", row.item.name},
                 {"method", io::DetectionMethodName(d.method)},
                 {"threshold", d.threshold},
                 {"max_obstacles", d.max_obstacles},
                 {"later_echoes", io::LaterEchoesName(d.later_echoes)},
                 {"scene", MetricsJson(row.scene)}};
    if (row.log) item["log"] = MetricsJson(*row.log);
    items.push_back(item);
  }
  json study = ReportHeader();
  study.update({{"scene", {{"name", scene.name}, {"file", scene.file}}},
                {"seed", options.seed.value_or(scene.seed)},
                {"log", options.log.empty() ? json() : json(options.log)},
                {"resolution_m", scene.mapping.resolution_m},
                {"items", items}});
  WriteJson((root / "study.json").string(), study);
}

}  // namespace sonarbench::sim
