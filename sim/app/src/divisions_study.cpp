#include "sonarbench/sim/app/divisions_study.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/output_directory.hpp"
#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/app/simulated_scene.hpp"
#include "sonarbench/sim/eval/beam_coverage.hpp"
#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/report/images.hpp"
#include "sonarbench/sim/report/report.hpp"
#include "sonarbench/sim/sonar/scene_world.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"

namespace sonarbench::sim {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::vector<PlotSeries> Plus(std::vector<PlotSeries> a, const std::vector<PlotSeries>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

std::string ItemFile(std::size_t index) {
  char name[64];
  std::snprintf(name, sizeof name, "items/item_%03zu.json", index);
  return name;
}

std::optional<json> ReadItem(const fs::path& path) {
  if (!fs::is_regular_file(path)) return std::nullopt;
  std::ifstream in(path);
  try {
    return json::parse(in);
  } catch (const json::exception& e) {
    throw InputError(path.string() + ": not a study item (" + e.what() + "); pass --force");
  }
}

// Everything the items share: the simulated beams, the truth, and the beams whose exact volume
// is measured with their true axis ranges.
struct StudyInputs {
  SimulatedScene simulated;
  struct CoverageBeam {
    mapping::Beam beam;
    double range_m = 0.0;
    WedgeCells wedge;
  };
  std::vector<CoverageBeam> coverage_beams;
};

StudyInputs PrepareInputs(const Scene& scene, const SceneWorld& world, std::uint64_t seed,
                          int coverage_beams, int threads) {
  StudyInputs in;
  in.simulated = SimulateForScoring(scene, world, seed, threads);
  const std::vector<SynthesizedBeam>& synthesized = in.simulated.synthesized;
  const octomap::OcTree key_space(scene.mapping.resolution_m);
  const auto per_sweep = static_cast<std::size_t>(scene.sensor.geometry.BeamsPerSweep());
  const std::size_t n = std::min<std::size_t>(static_cast<std::size_t>(coverage_beams),
                                              std::min(per_sweep, synthesized.size()));
  for (std::size_t i = 0; i < n; ++i) {
    const SynthesizedBeam& s = synthesized[i * std::min(per_sweep, synthesized.size()) / n];
    const double range = s.truth.axis_hit_range_m.value_or(scene.sensor.geometry.MaxRangeM());
    in.coverage_beams.push_back(
        {s.beam, range, ExactWedgeCells(s.beam, scene.sensor.geometry, range, key_space)});
  }
  return in;
}

json RunItem(const Scene& scene, const StudyInputs& in, const StudyItem& item, int threads) {
  const bool exact = item.group == "exact";
  mapping::MapperConfig config = scene.mapping;
  config.integration = exact ? mapping::Integration::kExact : mapping::Integration::kRays;
  config.rays_horizontal = exact ? config.rays_horizontal : item.rays_horizontal;
  config.rays_vertical = exact ? config.rays_vertical : item.rays_vertical;
  config.threads = threads;
  const auto start = std::chrono::steady_clock::now();
  mapping::Mapper mapper(config, scene.sensor.geometry);
  const mapping::BatchStats totals = mapper.IntegrateSweeps(in.simulated.beams);
  const double map_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const MapMetrics m = ScoreMap(mapper.tree(), in.simulated.truth, in.simulated.observable);

  std::size_t wedge = 0, undecided = 0, covered = 0, visited = 0, visits = 0, outside = 0;
  double lower_num = 0, upper_num = 0;
  for (const auto& b : in.coverage_beams) {
    const BeamCoverage c =
        exact ? MeasureExactBeamCoverage(b.beam, scene.sensor.geometry, b.range_m, mapper.tree(),
                                         b.wedge)
              : MeasureBeamCoverage(b.beam, scene.sensor.geometry, b.range_m, item.rays_horizontal,
                                    item.rays_vertical, mapper.tree(), b.wedge);
    wedge += c.wedge_cells;
    undecided += c.undecided_cells;
    covered += c.covered_cells;
    visited += c.visited_cells;
    visits += c.visits;
    outside += c.visited_outside;
    lower_num += c.coverage_lower * static_cast<double>(c.wedge_cells);
    upper_num += c.coverage_upper * static_cast<double>(c.wedge_cells);
  }
  auto ratio = [](double n, double d) { return d == 0 ? 0.0 : n / d; };
  return {{"group", item.group},
          {"rays_horizontal", item.rays_horizontal},
          {"rays_vertical", item.rays_vertical},
          {"beam_coverage", ratio(static_cast<double>(covered), static_cast<double>(wedge))},
          {"beam_coverage_lower", ratio(lower_num, static_cast<double>(wedge))},
          {"beam_coverage_upper", ratio(upper_num, static_cast<double>(wedge))},
          {"wedge_cells", wedge},
          {"undecided_cells", undecided},
          {"covered_cells", covered},
          {"visited_outside_cells", outside},
          {"visits_per_cell", ratio(static_cast<double>(visits), static_cast<double>(visited))},
          {"map_precision", m.occupied_precision},
          {"map_recall", m.occupied_recall},
          {"map_coverage", m.coverage},
          {"ray_casts", totals.ray_casts},
          {"cell_visits", totals.cell_visits},
          {"map_s", map_s}};
}

// coverage_vs_divisions.png and time_vs_divisions.png.
void WritePlots(const fs::path& root, const std::vector<json>& items) {
  auto series = [&](const std::string& group, const char* axis, const char* value,
                    const std::string& name, cv::Scalar colour) {
    PlotSeries s{name, colour, {}, {}};
    for (const json& item : items) {
      if (item["group"] != group) continue;
      s.x.push_back(item[axis].get<double>());
      s.y.push_back(item[value].get<double>());
    }
    return s;
  };
  const cv::Scalar blue(200, 80, 0), red(30, 30, 220), green(40, 160, 40), purple(160, 40, 160),
      grey(70, 70, 70);
  // The exact item, if studied, as a level line across the plot.
  auto exact_line = [&](const char* value, const std::string& name, cv::Scalar colour, double x0,
                        double x1) {
    std::vector<PlotSeries> line;
    for (const json& item : items) {
      if (item["group"] != "exact") continue;
      const double y = item[value].get<double>();
      line.push_back({name, colour, {x0, x1}, {y, y}});
    }
    return line;
  };
  WritePng((root / "coverage_vs_divisions.png").string(),
           RenderLinePlot("Beam-volume coverage and map recall against ray divisions", "divisions",
                          "fraction",
                          Plus(exact_line("map_recall", "map recall, exact", grey, 1.0, 128.0),
                               {series("horizontal", "rays_horizontal", "beam_coverage",
                                       "beam volume, H (V = 64)", blue),
                                series("vertical", "rays_vertical", "beam_coverage",
                                       "beam volume, V (H = 32)", red),
                                series("horizontal", "rays_horizontal", "map_recall",
                                       "map recall, H (V = 64)", green),
                                series("vertical", "rays_vertical", "map_recall",
                                       "map recall, V (H = 32)", purple)}),
                          true, 0.0, 1.0));
  PlotSeries time{"rays, all items", blue, {}, {}};
  std::vector<std::pair<double, double>> points;
  for (const json& item : items) {
    if (item["group"] == "exact") continue;
    points.emplace_back(item["rays_horizontal"].get<double>() * item["rays_vertical"].get<double>(),
                        item["map_s"].get<double>());
  }
  std::sort(points.begin(), points.end());
  for (const auto& [x, y] : points) {
    time.x.push_back(x);
    time.y.push_back(y);
  }
  const double fewest_rays = points.empty() ? 1.0 : points.front().first;
  const double most_rays = points.empty() ? 2.0 : std::max(2.0 * fewest_rays, points.back().first);
  WritePng((root / "time_vs_divisions.png").string(),
           RenderLinePlot("Mapping time against rays per beam (H x V)", "rays per beam", "seconds",
                          Plus(exact_line("map_s", "exact", grey, fewest_rays, most_rays), {time}),
                          true, 0.0));
}

// divisions.csv, the plots and study.json.
void WriteOutputs(const fs::path& root, const std::vector<json>& items, const json& header) {
  std::ostringstream csv;
  const char* columns[] = {"group",         "rays_horizontal",     "rays_vertical",
                           "beam_coverage", "beam_coverage_lower", "beam_coverage_upper",
                           "wedge_cells",   "undecided_cells",     "visits_per_cell",
                           "map_precision", "map_recall",          "map_coverage",
                           "ray_casts",     "cell_visits",         "map_s"};
  for (std::size_t c = 0; c < std::size(columns); ++c) csv << (c ? "," : "") << columns[c];
  csv << "\n";
  for (const json& item : items) {
    for (std::size_t c = 0; c < std::size(columns); ++c) {
      const json& v = item.at(columns[c]);
      csv << (c ? "," : "") << (v.is_string() ? v.get<std::string>() : v.dump());
    }
    csv << "\n";
  }
  WriteFileAtomically((root / "divisions.csv").string(), [&](std::ostream& o) { o << csv.str(); });
  WritePlots(root, items);
  json study = header;
  study["items"] = items;
  WriteJson((root / "study.json").string(), study);
}

}  // namespace

std::vector<StudyItem> DivisionsStudyItems() {
  std::vector<StudyItem> items;
  for (int h = 1; h <= 64; h *= 2) items.push_back({"horizontal", h, 64});
  for (int v = 1; v <= 128; v *= 2) items.push_back({"vertical", 32, v});
  for (int h = 4; h <= 64; h *= 2) {
    for (int v = 8; v <= 128; v *= 2) items.push_back({"grid", h, v});
  }
  items.push_back({"exact", 0, 0});
  return items;
}

namespace {

// The study's claim on its output folder: its files, each item's, study.json last.
io::OutputClaim StudyClaim(const Scene& scene, const std::string& config, std::size_t item_count,
                           bool force) {
  io::OutputClaim claim;
  claim.command = "sweep";
  claim.config_sha256 = config;
  claim.mode = io::OutputMode::kResume;
  claim.files = {"divisions.csv", "coverage_vs_divisions.png", "time_vs_divisions.png",
                 "study.json"};
  for (std::size_t i = 0; i < item_count; ++i) claim.files.push_back(ItemFile(i));
  claim.record = "study.json";
  claim.inputs = SceneInputFiles(scene);
  claim.force = force;
  return claim;
}

// Every item's result, once all shards wrote theirs; none while some are still due.
std::optional<std::vector<json>> CollectItems(const fs::path& root, std::size_t item_count,
                                              const std::string& config) {
  std::vector<json> results;
  for (std::size_t i = 0; i < item_count; ++i) {
    const auto item = ReadItem(root / ItemFile(i));
    if (!item) return std::nullopt;  // other shards' items are still due
    if (item->value("config_sha256", "") != config) {
      throw InputError((root / ItemFile(i)).string() +
                       ": from a study of another configuration; pass --force to start over");
    }
    results.push_back(*item);
  }
  return results;
}

// Runs this shard's items that `root/items/` does not hold yet, each written as it finishes;
// an item file of another configuration is refused. Counts them in `summary`.
void RunShardItems(const Scene& scene, const SceneWorld& world, std::uint64_t seed,
                   const std::vector<StudyItem>& items, const std::string& config,
                   const fs::path& root, const StudyOptions& options, StudySummary& summary) {
  std::vector<std::size_t> mine;
  for (std::size_t i = static_cast<std::size_t>(options.shard.index); i < items.size();
       i += static_cast<std::size_t>(options.shard.count))
    mine.push_back(i);
  std::optional<StudyInputs> inputs;
  std::size_t done = 0;
  for (const std::size_t i : mine) {
    const fs::path file = root / ItemFile(i);
    if (const auto existing = ReadItem(file)) {
      if (existing->value("config_sha256", "") != config) {
        throw InputError(file.string() +
                         ": from a study of another configuration; pass --force "
                         "to start over");
      }
      ++summary.items_skipped;
    } else {
      if (!inputs) {
        inputs = PrepareInputs(scene, world, seed, options.coverage_beams, options.threads);
      }
      json result = RunItem(scene, *inputs, items[i], options.threads);
      result["index"] = i;
      result["config_sha256"] = config;
      WriteJson(file.string(), result);
      ++summary.items_written;
    }
    if (options.progress) options.progress(++done, mine.size());
  }
}

}  // namespace

StudySummary RunDivisionsStudy(const Scene& original, const std::string& dir,
                               const StudyOptions& options) {
  Scene scene = original;
  if (options.sweeps) scene.sweeps = *options.sweeps;
  const std::uint64_t seed = options.seed.value_or(scene.seed);
  const std::string config =
      io::Sha256(SceneConfigHash(scene, seed) + "/sweeps " + std::to_string(scene.sweeps) +
                 "/coverage_beams " + std::to_string(options.coverage_beams) + "/items " +
                 std::to_string(options.items.size()));
  CheckOutputDirectory(dir);
  // The meshes' preflight before the directory is made: bad input leaves none.
  const SceneWorld world(scene);
  const std::vector<StudyItem> items =
      options.items.empty() ? DivisionsStudyItems() : options.items;
  const io::OutputClaim claim = StudyClaim(scene, config, items.size(), options.force);
  const io::OutputDirectory out(dir, claim);
  const fs::path& root = out.root();
  fs::create_directories(root / "items");

  StudySummary summary;
  summary.items_total = items.size();
  RunShardItems(scene, world, seed, items, config, root, options, summary);

  const std::optional<std::vector<json>> results = CollectItems(root, items.size(), config);
  if (!results) return summary;
  json header = ReportHeader();
  header.update({{"scene", {{"name", scene.name}, {"file", scene.file}}},
                 {"seed", seed},
                 {"sweeps", scene.sweeps},
                 {"resolution_m", scene.mapping.resolution_m},
                 {"coverage_beams", options.coverage_beams},
                 {"config_sha256", config},
                 {"threads", options.threads}});
  WriteOutputs(root, *results, header);
  summary.complete = true;
  return summary;
}

}  // namespace sonarbench::sim
