#include "sonarbench/sim/app/detector_study.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <span>
#include <sstream>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/io/mapping_yaml.hpp"
#include "sonarbench/mapping/detection.hpp"
#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/app/map_log.hpp"
#include "sonarbench/sim/app/simulated_scene.hpp"
#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/eval/verdict.hpp"
#include "sonarbench/sim/report/images.hpp"
#include "sonarbench/sim/report/report.hpp"
#include "sonarbench/sim/sonar/scene_world.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"

namespace sonarbench::sim {
namespace {

using nlohmann::json;
using Detection = mapping::DetectionConfig;

// What a setting's names say of its wall rule.
std::string WallsSuffix(const Detection& d) {
  return d.behind_walls == Detection::BehindWalls::kRefuse ? ", nothing behind walls" : "";
}

// The echo rule of a setting, as the CSV, the plot's legend and the item's name give it.
std::string EchoRule(const Detection& d) {
  const std::string walls = WallsSuffix(d);
  if (d.max_obstacles == 1) return "first echo" + walls;
  return std::to_string(d.max_obstacles) + " echoes, " + io::LaterEchoesName(d.later_echoes) +
         walls;
}

// Beams to map by sweep, each sweep detected whole (the walls fitted on all its first echoes) and
// its beams within the head angles studied integrated as one batch.
struct Batches {
  std::vector<mapping::Beam> beams;
  std::vector<std::size_t> sizes;
  std::vector<bool> scored;  // a beam's: within the head angles studied
};

// `beams` batched by the sweeps of `per_sweep` consecutive beams, each marked scored when
// `heads` keeps it (all without it); `keep` is called with each scored beam's index.
Batches SelectBeams(std::span<const mapping::Beam> beams, std::size_t per_sweep,
                    const std::optional<std::pair<double, double>>& heads,
                    const std::function<void(std::size_t)>& keep = {}) {
  Batches out;
  out.beams.assign(beams.begin(), beams.end());
  for (std::size_t first = 0; first < beams.size(); first += per_sweep) {
    out.sizes.push_back(std::min(per_sweep, beams.size() - first));
  }
  for (std::size_t b = 0; b < beams.size(); ++b) {
    out.scored.push_back(!heads || InHeads(beams[b].head_angle_rad, *heads));
    if (out.scored.back() && keep) keep(b);
  }
  return out;
}

// Calls `use` with each sweep's scored beams and their echoes, detected on the whole sweep; a
// beam heard only through a wall is left out, as the mapper leaves it (Mapper::Integrate).
void ForEachScoredSweep(
    const Batches& batches, const mapping::SensorGeometry& sensor, const Detection& detection,
    const std::function<void(std::span<const mapping::Beam>, std::span<const std::vector<double>>,
                             std::span<const std::size_t>)>& use) {
  const std::span<const mapping::Beam> all(batches.beams);
  std::size_t first = 0;
  for (const std::size_t size : batches.sizes) {
    std::vector<bool> through;
    std::vector<std::vector<double>> echoes =
        mapping::DetectObstacles(all.subspan(first, size), sensor, detection, &through);
    std::vector<mapping::Beam> beams;
    std::vector<std::vector<double>> kept;
    std::vector<std::size_t> index;
    for (std::size_t b = 0; b < size; ++b) {
      if (!batches.scored[first + b] || through[b]) continue;
      beams.push_back(all[first + b]);
      kept.push_back(std::move(echoes[b]));
      index.push_back(first + b);
    }
    if (!beams.empty()) use(beams, kept, index);
    first += size;
  }
}

// A map of `batches` with `detection`, scored against the truth and what a perfect sensor sees.
MapMetrics MapAndScore(const mapping::MapperConfig& base, const Detection& detection,
                       const mapping::SensorGeometry& sensor, const Batches& batches,
                       const mapping::KeySet& truth, const mapping::KeySet& observable,
                       const DirectEchoes& direct) {
  mapping::MapperConfig config = base;
  config.detection = detection;
  mapping::Mapper mapper(config, sensor);
  ForEachScoredSweep(batches, sensor, detection,
                     [&](auto beams, auto echoes, auto) { (void)mapper.Integrate(beams, echoes); });
  return ScoreMap(mapper.tree(), truth, observable, {}, {}, &direct);
}

// The path an echo starting at `bin` came by: the one most of its first three bins have (the
// first bin's among equals), from each bin's dominant path.
std::size_t PathOfEcho(const std::vector<std::uint8_t>& paths, std::size_t bin) {
  constexpr std::size_t kEchoBins = 3;
  std::array<int, kEchoPaths> votes{};
  for (std::size_t k = bin; k < std::min(paths.size(), bin + kEchoBins); ++k) ++votes[paths[k]];
  std::size_t path = paths[bin];
  for (std::size_t p = 0; p < kEchoPaths; ++p) {
    if (votes[p] > votes[path]) path = p;
  }
  return path;
}

// The echoes `detection` finds in `batches`' scored beams (the simulated scene's, one entry of
// `bin_paths` a beam) by the path they came by (PathOfEcho).
EchoPathCounts CountEchoPaths(const Detection& detection, const mapping::SensorGeometry& sensor,
                              const Batches& batches,
                              const std::vector<std::vector<std::uint8_t>>& bin_paths) {
  EchoPathCounts counts;
  ForEachScoredSweep(batches, sensor, detection, [&](auto, auto echoes, auto index) {
    for (std::size_t b = 0; b < echoes.size(); ++b) {
      const std::vector<std::uint8_t>& paths = bin_paths[index[b]];
      for (std::size_t e = 0; e < echoes[b].size(); ++e) {
        const auto bin = static_cast<std::size_t>(echoes[b][e] / sensor.bin_size_m);
        if (bin < paths.size()) ++(e == 0 ? counts.first : counts.later)[PathOfEcho(paths, bin)];
      }
    }
  });
  return counts;
}

json PathCountsJson(const std::array<std::size_t, kEchoPaths>& counts) {
  json out = json::object();
  for (std::size_t p = 0; p < kEchoPaths; ++p) out[std::string(kEchoPathNames[p])] = counts[p];
  return out;
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
  csv << "item,method,threshold,max_obstacles,later_echoes,behind_walls";
  for (const char* source : {"scene", "log"}) {
    if (std::string(source) == "log" && !with_log) continue;
    for (const std::string& c : kMetricColumns) csv << "," << source << "_" << c;
  }
  csv << "\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Detection& d = rows[i].item.detection;
    csv << i << "," << io::DetectionMethodName(d.method) << ","
        << (d.method == Detection::Method::kThreshold ? std::to_string(d.threshold) : "") << ","
        << d.max_obstacles << "," << io::LaterEchoesName(d.later_echoes) << ","
        << io::BehindWallsName(d.behind_walls);
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
// threshold detector a series per echo rule (its thresholds' points), each other detector a
// series (a point per echo rule); each twice, with echoes behind walls kept and refused.
void WritePlot(const std::string& path, const std::vector<DetectorRow>& rows, bool log) {
  const std::vector<cv::Scalar> colours = {{200, 80, 0},   {30, 30, 220}, {40, 160, 40},
                                           {160, 40, 160}, {0, 140, 200}, {120, 120, 120},
                                           {0, 0, 0},      {90, 60, 30}};
  std::map<std::string, std::size_t> order;
  std::vector<PlotSeries> series;
  for (const DetectorRow& row : rows) {
    const Detection& d = row.item.detection;
    const std::string name =
        d.method == Detection::Method::kThreshold
            ? "threshold, " + EchoRule(d)
            : std::string(io::DetectionMethodName(d.method)) + ", each echo rule" + WallsSuffix(d);
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

double Spearman(const std::vector<double>& a, const std::vector<double>& b) {
  const auto ranks = [](const std::vector<double>& x) {
    std::vector<std::size_t> order(x.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](auto i, auto j) { return x[i] < x[j]; });
    std::vector<double> rank(x.size());
    for (std::size_t i = 0; i < order.size();) {
      std::size_t j = i;
      while (j + 1 < order.size() && x[order[j + 1]] == x[order[i]]) ++j;
      for (std::size_t k = i; k <= j; ++k) rank[order[k]] = 0.5 * static_cast<double>(i + j);
      i = j + 1;
    }
    return rank;
  };
  const std::vector<double> ra = ranks(a), rb = ranks(b);
  const double n = static_cast<double>(a.size());
  double ma = 0.0, mb = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ma += ra[i] / n;
    mb += rb[i] / n;
  }
  double cov = 0.0, va = 0.0, vb = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    cov += (ra[i] - ma) * (rb[i] - mb);
    va += (ra[i] - ma) * (ra[i] - ma);
    vb += (rb[i] - mb) * (rb[i] - mb);
  }
  return va > 0.0 && vb > 0.0 ? cov / std::sqrt(va * vb) : NAN;
}

std::vector<Agreement> StudyAgreement(const std::vector<DetectorRow>& rows) {
  std::vector<Agreement> out;
  if (rows.empty() || !rows.front().log) return out;
  for (const auto& [figure, metric] : kAgreementFigures) {
    std::vector<double> sim, log;
    for (const DetectorRow& row : rows) {
      sim.push_back(MetricValue(row.scene, metric));
      log.push_back(MetricValue(*row.log, metric));
    }
    Agreement a{figure, Spearman(sim, log), 0.0, 0.0};
    for (std::size_t i = 0; i < sim.size(); ++i) {
      const double d = std::abs(sim[i] - log[i]);
      a.mean_abs_difference += d / static_cast<double>(sim.size());
      a.max_abs_difference = std::max(a.max_abs_difference, d);
    }
    out.push_back(a);
  }
  return out;
}

std::size_t BestF1Row(const std::vector<DetectorRow>& rows, bool log) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const double f = log ? rows[i].log->f1_within[1] : rows[i].scene.f1_within[1];
    const double b = log ? rows[best].log->f1_within[1] : rows[best].scene.f1_within[1];
    if (f > b) best = i;
  }
  return best;
}

json AgreementJson(const std::vector<DetectorRow>& rows, const MapGoals& goals) {
  const std::vector<Agreement> agreement = StudyAgreement(rows);
  if (agreement.empty()) return json();
  json figures = json::object();
  bool meets = true;
  for (const Agreement& a : agreement) {
    const bool ok = !std::isnan(a.spearman) && a.spearman >= goals.min_spearman &&
                    a.mean_abs_difference <= goals.max_mean_abs_difference &&
                    a.max_abs_difference <= goals.max_abs_difference;
    meets = meets && ok;
    figures[a.figure] = {{"spearman", std::isnan(a.spearman) ? json() : json(a.spearman)},
                         {"mean_abs_difference", a.mean_abs_difference},
                         {"max_abs_difference", a.max_abs_difference},
                         {"meets", ok}};
  }
  const std::size_t best_scene = BestF1Row(rows, false);
  const std::size_t best_log = BestF1Row(rows, true);
  return {{"figures", figures},
          {"best_f1_1",
           {{"scene", rows[best_scene].item.name},
            {"log", rows[best_log].item.name},
            {"same", best_scene == best_log}}},
          {"goals",
           {{"max_mean_abs_difference", goals.max_mean_abs_difference},
            {"max_abs_difference", goals.max_abs_difference},
            {"min_spearman", goals.min_spearman}}},
          {"meets", meets && best_scene == best_log}};
}

bool InHeads(double head_angle_rad, const std::pair<double, double>& heads_deg) {
  double deg = std::fmod(head_angle_rad * 180.0 / std::numbers::pi, 360.0);
  if (deg < 0.0) deg += 360.0;
  return deg >= heads_deg.first && deg < heads_deg.second;
}

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
  // Every detector and echo rule with the echoes behind walls kept, then with them refused.
  for (const auto walls : {Detection::BehindWalls::kKeep, Detection::BehindWalls::kRefuse}) {
    Detection d = base;
    d.behind_walls = walls;
    for (int threshold = 70; threshold <= 150; threshold += 20) {
      d.method = Detection::Method::kThreshold;
      d.threshold = threshold;
      add(d);
    }
    for (const auto method : {Detection::Method::kCanny, Detection::Method::kAutoCanny,
                              Detection::Method::kCaCfar, Detection::Method::kOsCfar}) {
      d.method = method;
      add(d);
    }
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
  Batches log_beams;
  if (!options.log.empty()) {
    log = MapLog(options.log, scene.sensor.geometry, base, &scene, scene.budgets);
    std::vector<BeamPose> poses;
    log_beams =
        SelectBeams(log->mapped, static_cast<std::size_t>(log->sensor.BeamsPerSweep()),
                    options.heads_deg, [&](std::size_t b) { poses.push_back(log->poses[b]); });
    log->poses = std::move(poses);
  }
  std::optional<SceneWorld> own_world;
  const SceneWorld& world = options.world ? *options.world : own_world.emplace(scene);
  if (log) log_score = ScoreLogMap(*log, scene, &world);
  std::optional<SimulatedScene> own_simulation;
  if (!options.simulated) {
    own_simulation.emplace(SimulateForScoring(scene, world, options.seed.value_or(scene.seed),
                                              options.threads, options.heads_deg));
  }
  const SimulatedScene& simulated = options.simulated ? *options.simulated : *own_simulation;
  // The cells seen from the chosen head angles: the simulation's own unless it saw from all.
  std::optional<ObservedCells> part;
  if (options.simulated && options.heads_deg) {
    part = ObservedFrom(scene, world, simulated.synthesized.size(), options.heads_deg);
  }
  const mapping::KeySet& observable = part ? part->observable : simulated.observable;
  const DirectEchoes& direct = part ? part->direct : simulated.direct;
  const Batches sim_beams =
      SelectBeams(simulated.beams, static_cast<std::size_t>(scene.sensor.geometry.BeamsPerSweep()),
                  options.heads_deg);

  std::vector<DetectorRow> rows;
  for (const DetectorItem& item : items) {
    DetectorRow row{
        item,
        MapAndScore(base, item.detection, scene.sensor.geometry, sim_beams, simulated.truth,
                    observable, direct),
        std::nullopt,
        CountEchoPaths(item.detection, scene.sensor.geometry, sim_beams, simulated.bin_paths)};
    if (log) {
      row.log = MapAndScore(base, item.detection, log->sensor, log_beams, log_score->truth,
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
                 {"behind_walls", io::BehindWallsName(d.behind_walls)},
                 {"scene", MetricsJson(row.scene)},
                 {"scene_echo_paths",
                  {{"first", PathCountsJson(row.scene_paths.first)},
                   {"later", PathCountsJson(row.scene_paths.later)}}}};
    if (row.log) item["log"] = MetricsJson(*row.log);
    items.push_back(item);
  }
  json study = ReportHeader();
  study.update({{"scene", {{"name", scene.name}, {"file", scene.file}}},
                {"seed", options.seed.value_or(scene.seed)},
                {"log", options.log.empty() ? json() : json(options.log)},
                {"resolution_m", scene.mapping.resolution_m},
                {"heads_deg", options.heads_deg ? json::array({options.heads_deg->first,
                                                               options.heads_deg->second})
                                                : json()},
                {"items", items}});
  if (with_log) study["agreement"] = AgreementJson(rows);
  WriteJson((root / "study.json").string(), study);
}

}  // namespace sonarbench::sim
