// sonarbench: the command-line front end. Exit status: 0 success, 1 a scenario's criteria failed,
// 2 bad input, 3 internal error.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>

#include "sonarbench/io/mapping_yaml.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/mapping/atomic_file.hpp"
#include "sonarbench/mapping/error.hpp"
#include "sonarbench/sim/dataset_writer.hpp"
#include "sonarbench/sim/divisions_study.hpp"
#include "sonarbench/sim/fidelity.hpp"
#include "sonarbench/sim/map_log.hpp"
#include "sonarbench/sim/mesh.hpp"
#include "sonarbench/sim/output_directory.hpp"
#include "sonarbench/sim/report.hpp"
#include "sonarbench/sim/scenario.hpp"
#include "sonarbench/sim/scenario_report.hpp"
#include "sonarbench/sim/scene.hpp"
#include "sonarbench/sim/simulation.hpp"

namespace {

constexpr int kExitCriteriaFailed = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitInternalError = 3;

struct RunArgs {
  sonarbench::sim::Budgets budgets;
  std::string scene;
  std::string out = "out";
  std::optional<std::uint64_t> seed;
  int threads = 0;
  bool no_progress = false;
};

// One self-overwriting progress line on stderr (stage, sweeps done, rate, time left), shown only
// on an interactive terminal outside CI, at most five times a second.
class ProgressLine {
 public:
  explicit ProgressLine(bool enabled) : enabled_(enabled) {}
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;
  ~ProgressLine() { Clear(); }

  static bool WantedFor(bool disabled_by_user) {
    return !disabled_by_user && isatty(STDERR_FILENO) == 1 && std::getenv("CI") == nullptr;
  }

  void Update(std::string_view stage, std::size_t done, std::size_t total) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (stage != stage_) {
      // A stage starts when the previous one reported its last sweep (or when the run began).
      stage_ = stage;
      stage_start_ = last_event_;
    } else if (done < total && now - last_print_ < std::chrono::milliseconds(200)) {
      last_event_ = now;
      return;
    }
    last_event_ = now;
    last_print_ = now;
    const double elapsed = std::chrono::duration<double>(now - stage_start_).count();
    const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
    char line[160];
    std::snprintf(line, sizeof line, "\r%-10s %zu/%zu  %.0f s left   ", std::string(stage).c_str(),
                  done, total, rate > 0 ? static_cast<double>(total - done) / rate : 0.0);
    std::cerr << line << std::flush;
    shown_ = true;
  }

  void Clear() {
    if (shown_) std::cerr << "\r" << std::string(60, ' ') << "\r" << std::flush;
    shown_ = false;
  }

 private:
  bool enabled_;
  bool shown_ = false;
  std::string stage_;
  std::chrono::steady_clock::time_point stage_start_;
  std::chrono::steady_clock::time_point last_event_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_print_;
};

// The scene at `path`, to be built within `budgets`.
sonarbench::sim::Scene LoadScene(const std::string& path, const sonarbench::sim::Budgets& budgets) {
  sonarbench::sim::Scene scene = sonarbench::sim::LoadScene(path);
  scene.budgets = budgets;
  return scene;
}

// "occupied precision P (tp/occupied), recall R (..), coverage C (..)": a map's scores.
std::string MetricsLine(const sonarbench::sim::MapMetrics& m) {
  std::ostringstream line;
  line << "occupied precision " << m.occupied_precision << " (" << m.true_positive_cells << "/"
       << m.occupied_cells << "), recall " << m.occupied_recall << " (" << m.observed_occupied_cells
       << "/" << m.observable_cells << "), coverage " << m.coverage << " ("
       << m.known_observable_cells << "/" << m.observable_cells << ")";
  return line.str();
}

void PrintSummary(const sonarbench::sim::Scene& scene, const sonarbench::sim::ScenarioResult& r,
                  const std::string& out) {
  const auto& t = r.timings;
  const auto& v = r.verdict;
  std::cout << "beams " << r.beams << ", seed " << r.seed << ", threads " << r.threads << "\n"
            << MetricsLine(r.metrics) << "\n"
            << "timing [s]: scene " << t.build_scene_s << ", simulate " << t.simulate_s << ", map "
            << t.map_s << ", ground truth " << t.ground_truth_s << ", score " << t.score_s << "\n"
            << "wrote " << out << "/report.json, junit.xml, report.html, map.bt and images\n";
  std::size_t met = 0;
  for (const auto& c : v.results) met += c.status != sonarbench::sim::CriterionStatus::kFail;
  for (const auto& mesh : r.meshes) {
    if (mesh.check.zero_area_triangles > 0) {
      std::cout << "warning: mesh '" << mesh.name << "': " << mesh.check.zero_area_triangles
                << " zero-area triangles dropped\n";
    }
    if (mesh.check.non_manifold_edges > 0) {
      std::cout << "warning: mesh '" << mesh.name << "': " << mesh.check.non_manifold_edges
                << " non-manifold edges (three or more triangles share them)\n";
    }
  }
  for (const auto& w : v.warnings) std::cout << "warning: " << w << "\n";
  std::cout << (v.passed ? "PASS " : "FAIL ") << scene.name << ": " << met << "/"
            << v.results.size() << " criteria met"
            << (v.expect_fail ? " (the scene expects a failure)" : "") << "\n";
  for (const auto& reason : v.reasons) std::cout << "  " << reason << "\n";
}

// What a one-shot command (run, map, fidelity) claims in its --out: `files`, `record` last; the
// files it reads are never written or removed.
sonarbench::sim::OutputClaim OneShotClaim(std::string command, std::vector<std::string> files,
                                          std::vector<std::string> inputs) {
  namespace sim = sonarbench::sim;
  std::erase(inputs, std::string());
  std::string what = command;
  for (const std::string& input : inputs) what += "\n" + input;
  sim::OutputClaim claim;
  claim.command = std::move(command);
  claim.config_sha256 = sonarbench::mapping::Sha256(what);
  claim.mode = sim::OutputMode::kReplace;
  claim.record = files.front();
  claim.files = std::move(files);
  claim.inputs = std::move(inputs);
  return claim;
}

struct MapArgs {
  bool no_progress = false;
  sonarbench::sim::Budgets budgets;
  std::string input;
  std::string out = "out/map";
  std::string scene;
  std::string sensor;
  std::string mapping;
  bool score = false;
  int threads = 0;
};

int Map(const MapArgs& args) {
  sonarbench::CheckOutputDirectory(args.out);
  sonarbench::mapping::SensorGeometry sensor;
  sonarbench::mapping::MapperConfig config;
  if (!args.scene.empty()) {
    const sonarbench::sim::Scene scene = LoadScene(args.scene, args.budgets);
    sensor = scene.sensor.geometry;
    config = scene.mapping;
  }
  if (!args.sensor.empty()) sensor = sonarbench::sim::LoadSensorModel(args.sensor).geometry;
  if (!args.mapping.empty()) {
    sonarbench::YamlReader reader = sonarbench::YamlReader::FromFile(args.mapping);
    config = sonarbench::mapping::ReadMapperConfig(reader);
    reader.ThrowIfErrors();
  }
  config.threads = args.threads;
  // A .mat log scored against the scene is mapped from the scene's sonar pose.
  std::optional<sonarbench::sim::Scene> scene;
  if (args.score) {
    scene = LoadScene(args.scene, args.budgets);
    sonarbench::sim::CheckBudgets(*scene, args.budgets);
  }
  std::vector<std::string> files = sonarbench::sim::kLogMapOutputFiles;
  std::rotate(files.begin(), files.end() - 1, files.end());  // the record, report.json, first
  sonarbench::sim::OutputDirectory out(
      args.out, OneShotClaim("map", files, {args.input, args.scene, args.sensor, args.mapping}));
  ProgressLine progress(ProgressLine::WantedFor(args.no_progress));
  auto result = sonarbench::sim::MapLog(
      args.input, sensor, config, scene ? &*scene : nullptr, args.budgets,
      [&](std::size_t done, std::size_t total) { progress.Update("map", done, total); });
  progress.Clear();
  if (scene) result.metrics = sonarbench::sim::ScoreLogMap(result, *scene);
  sonarbench::sim::WriteLogMapOutputs(out.write_root().string(), result);
  out.Commit();
  const auto& t = result.totals;
  std::cout << result.beams << " beams (" << result.truncated_beams << " truncated) in "
            << result.sweeps << " sweeps; " << t.beams_with_obstacle << " with an obstacle\n";
  for (const std::string& warning : result.warnings) std::cout << "warning: " << warning << "\n";
  if (result.metrics)
    std::cout << "against " << args.scene << ": " << MetricsLine(*result.metrics) << "\n";
  std::cout << "timing [s]: import " << result.import_s << ", map " << result.map_s << "\n"
            << "wrote " << args.out
            << "/report.json, map.bt, map.ot, map_top.png, polar.png, fan.png\n";
  return 0;
}

struct FidelityArgs {
  bool no_progress = false;
  sonarbench::sim::Budgets budgets;
  std::string scene;
  std::string log;
  std::string out = "out/fidelity";
  std::optional<std::uint64_t> seed;
  int threads = 0;
  double wall_min_range_m = 1.6;
};

// One line of `sonarbench fidelity`'s summary: FidelityReport::HeadAngleCells of both runs.
std::string HeadAngleLine(const std::string& what,
                          const sonarbench::sim::FidelityReport::HeadAngleCells& simulated,
                          const sonarbench::sim::FidelityReport::HeadAngleCells& real) {
  std::ostringstream line;
  line << what << " (bins " << real.first_bin << "-" << real.last_bin << "): mean sim "
       << simulated.mean << ", real " << real.mean << "; ping to ping sim " << simulated.ping_spread
       << ", real " << real.ping_spread << "; across head angles sim " << simulated.angle_spread
       << ", real " << real.angle_spread << ", correlated at 1/"
       << sonarbench::sim::FidelityReport::kRingingFarStep << " head steps sim "
       << simulated.angle_correlation[0] << "/" << simulated.angle_correlation[1] << ", real "
       << real.angle_correlation[0] << "/" << real.angle_correlation[1] << "\n";
  return line.str();
}

// Values as "a/b/c", to one decimal.
template <std::size_t N>
std::string Slashed(const std::array<double, N>& values) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(1);
  for (std::size_t i = 0; i < N; ++i) text << (i > 0 ? "/" : "") << values[i];
  return text.str();
}

int Fidelity(const FidelityArgs& args) {
  namespace sim = sonarbench::sim;
  sonarbench::CheckOutputDirectory(args.out);
  const sim::Scene scene = LoadScene(args.scene, args.budgets);
  if (const double range = scene.sensor.geometry.MaxRangeM(); args.wall_min_range_m >= range) {
    std::ostringstream message;
    message << "--wall-min-range " << args.wall_min_range_m << ": expected less than the sonar's "
            << range << " m range (no echo lies past it)";
    throw sonarbench::InputError(message.str());
  }
  const sonarbench::mapping::MatLog log = sonarbench::mapping::ReadMatLog(args.log);
  const auto meshes = sim::BuildSceneMeshes(scene);
  std::vector<std::string> inputs = sim::SceneInputFiles(scene);
  inputs.push_back(args.log);
  sim::OutputDirectory out(args.out, OneShotClaim("fidelity", sim::kFidelityOutputFiles, inputs));
  const sim::RayTracer tracer(meshes);
  ProgressLine progress(ProgressLine::WantedFor(args.no_progress));
  const auto synthesized = sim::SimulateScene(
      scene, tracer, args.seed.value_or(scene.seed), args.threads,
      [&](std::size_t done, std::size_t total) { progress.Update("simulate", done, total); });
  progress.Clear();
  const std::vector<sonarbench::mapping::Beam> beams = sim::BeamsOf(synthesized);
  const auto& g = scene.sensor.geometry;
  const auto report = sim::CompareWithLog(beams, log.beams, g, args.wall_min_range_m);
  const auto per_sweep = static_cast<std::size_t>(g.BeamsPerSweep());
  const std::span<const sonarbench::mapping::Beam> sim_all(beams);
  const std::span<const sonarbench::mapping::Beam> real_all(log.beams);
  sim::WriteFidelityOutputs(
      out.write_root().string(), report, sim_all.first(std::min(per_sweep, sim_all.size())),
      real_all.first(std::min(per_sweep, real_all.size())), g, args.scene, args.log);
  out.Commit();
  std::cout << "mean intensity vs range: correlation " << report.profile_correlation_all
            << " (all bins), " << report.profile_correlation_usable
            << " (past self-reflection); mean |difference| " << report.profile_mean_abs_difference
            << " (past self-reflection)\n"
            << "mean intensity by range [m], sim / real:";
  const auto show = [](const std::optional<double>& v) {
    std::ostringstream text;
    if (v) {
      text << std::fixed << std::setprecision(1) << *v;
    } else {
      text << "none";
    }
    return text.str();
  };
  // Each band as "from-to sim / real".
  const auto by_band = [&](const sim::FidelityReport::RangeBands& sim_values,
                           const sim::FidelityReport::RangeBands& real_values) {
    std::ostringstream text;
    for (std::size_t b = 0; b < sim::FidelityReport::kRangeBandsM.size(); ++b) {
      text << (b == 0 ? " " : ", ") << sim::FidelityReport::kRangeBandsM[b][0] << "-"
           << sim::FidelityReport::kRangeBandsM[b][1] << " " << show(sim_values[b]) << " / "
           << show(real_values[b]);
    }
    return text.str();
  };
  std::cout << by_band(report.sim_band_means, report.real_band_means) << "\n"
            << "wall range: median difference " << report.median_wall_difference_bins
            << " bins over " << report.wall_angles_compared << " head angles\n"
            << "wall echo intensity, 10th/50th/90th percentile over beams: sim "
            << report.sim_wall_peak[0] << "/" << report.sim_wall_peak[1] << "/"
            << report.sim_wall_peak[2] << ", real " << report.real_wall_peak[0] << "/"
            << report.real_wall_peak[1] << "/" << report.real_wall_peak[2]
            << "; behind it (16-120 bins), mean |difference| "
            << report.wall_tail_mean_abs_difference << "\n"
            << "behind the walls (mean " << sim::FidelityReport::kBehindFirst << "-"
            << sim::FidelityReport::kBehindLast << " bins past the strongest echo), beams within "
            << sim::FidelityReport::kSquareDeg << " deg of a side's normal / "
            << sim::FidelityReport::kCornerFromDeg << "-45 deg off it: sim "
            << report.sim_behind_walls[0] << " / " << report.sim_behind_walls[1] << ", real "
            << report.real_behind_walls[0] << " / " << report.real_behind_walls[1]
            << "; within it, by side (0/90/180/270 deg): sim "
            << Slashed(report.sim_behind_walls_by_side) << ", real "
            << Slashed(report.real_behind_walls_by_side) << "\n"
            << "wall echo's front (20 bins before the strongest, over the beams whose strongest "
               "echo is the simulated wall: sim "
            << report.sim_direct_wall_beams << ", real " << report.real_direct_wall_beams
            << " beams): mean |difference| " << report.wall_front_mean_abs_difference << "\n"
            << "second trip (around twice the strongest echo's bin, offsets -30..+10): excess "
               "over its flanks sim "
            << report.sim_second_trip_excess << " (" << report.sim_second_trip_beams
            << " beams), real " << report.real_second_trip_excess << " ("
            << report.real_second_trip_beams
            << " beams) [intensity x bins]; profile mean |difference| "
            << report.second_trip_mean_abs_difference << "\n"
            << "intensity histograms: intersection " << report.histogram_intersection
            << "; values held: sim " << report.sim_values << ", real " << report.real_values
            << ", sim's never in the real log " << report.sim_values_not_real << "\n"
            << "range correlation at 1/2/3 bins (far half): sim " << report.sim_range_correlation[1]
            << "/" << report.sim_range_correlation[2] << "/" << report.sim_range_correlation[3]
            << ", real " << report.real_range_correlation[1] << "/"
            << report.real_range_correlation[2] << "/" << report.real_range_correlation[3] << "\n"
            << "beam-to-beam correlation at 1/2/3 head steps (far half): sim "
            << report.sim_beam_correlation[1] << "/" << report.sim_beam_correlation[2] << "/"
            << report.sim_beam_correlation[3] << ", real " << report.real_beam_correlation[1] << "/"
            << report.real_beam_correlation[2] << "/" << report.real_beam_correlation[3] << "\n"
            << "fine texture (less each bin's mean over +-" << sim::FidelityReport::kLocalReach
            << " bins): range correlation at 1/2/3 bins sim "
            << report.sim_local_range_correlation[1] << "/" << report.sim_local_range_correlation[2]
            << "/" << report.sim_local_range_correlation[3] << ", real "
            << report.real_local_range_correlation[1] << "/"
            << report.real_local_range_correlation[2] << "/"
            << report.real_local_range_correlation[3] << "; across 1/2/3 head steps sim "
            << report.sim_local_beam_correlation[1] << "/" << report.sim_local_beam_correlation[2]
            << "/" << report.sim_local_beam_correlation[3] << ", real "
            << report.real_local_beam_correlation[1] << "/" << report.real_local_beam_correlation[2]
            << "/" << report.real_local_beam_correlation[3] << "; contrast sim "
            << report.sim_local_contrast << ", real " << report.real_local_contrast << "\n"
            << "sweep-to-sweep spread per head angle and bin: sim " << report.sim_sweep_spread
            << ", real " << report.real_sweep_spread << "; by range [m], sim / real:"
            << by_band(report.sim_sweep_spread_by_band, report.real_sweep_spread_by_band) << "\n"
            << HeadAngleLine("self-reflection", report.sim_ringing, report.real_ringing)
            << HeadAngleLine("near range past it", report.sim_near_range, report.real_near_range)
            << "wrote " << args.out << "/fidelity.json\n";
  return 0;
}

// The --shard option's value, else a SLURM array job's shard, else the whole run.
sonarbench::sim::Shard ResolveShard(const std::string& option) {
  if (!option.empty()) return sonarbench::sim::ParseShard(option);
  return sonarbench::sim::ShardFromSlurm().value_or(sonarbench::sim::Shard{});
}

struct SimulateArgs {
  sonarbench::sim::Budgets budgets;
  std::string scene;
  std::string out;
  std::optional<std::uint64_t> seed;
  int threads = 0;
  bool force = false;
  std::string shard;
  bool no_progress = false;
};

int Simulate(const SimulateArgs& args) {
  namespace sim = sonarbench::sim;
  const sim::Scene scene = LoadScene(args.scene, args.budgets);
  sim::DatasetOptions options;
  options.seed = args.seed;
  options.threads = args.threads;
  options.force = args.force;
  options.shard = ResolveShard(args.shard);
  ProgressLine progress(ProgressLine::WantedFor(args.no_progress));
  options.progress = [&](std::size_t done, std::size_t total) {
    progress.Update("simulate", done, total);
  };
  const sim::DatasetSummary summary = sim::SimulateDataset(scene, args.out, options);
  progress.Clear();
  if (summary.already_complete) {
    std::cout << args.out
              << ": already a complete dataset of this configuration; nothing to do "
                 "(--force rewrites it)\n";
    return 0;
  }
  std::cout << "shard " << options.shard.index + 1 << "/" << options.shard.count << ": wrote "
            << summary.sweeps_written << " sweeps, skipped " << summary.sweeps_skipped
            << " already complete, of " << summary.sweeps_total << "\n";
  if (summary.complete) {
    std::cout << "wrote " << args.out << "/manifest.json (config "
              << summary.config_sha256.substr(0, 12) << ")\n";
  } else {
    std::cout << "other shards' sweeps are still missing: the last shard to finish, or a rerun "
                 "without --shard, writes the poses, truth/occupancy.bt and manifest.json\n";
  }
  return 0;
}

struct SweepArgs {
  sonarbench::sim::Budgets budgets;
  std::string scene;
  std::string out;
  std::optional<std::uint64_t> seed;
  std::optional<int> sweeps;
  int coverage_beams = 20;
  int threads = 0;
  bool force = false;
  std::string shard;
  bool no_progress = false;
};

int Sweep(const SweepArgs& args) {
  namespace sim = sonarbench::sim;
  sonarbench::CheckOutputDirectory(args.out);
  const sim::Scene scene = LoadScene(args.scene, args.budgets);
  sim::StudyOptions options;
  options.seed = args.seed;
  options.sweeps = args.sweeps;
  options.coverage_beams = args.coverage_beams;
  options.threads = args.threads;
  options.force = args.force;
  options.shard = ResolveShard(args.shard);
  ProgressLine progress(ProgressLine::WantedFor(args.no_progress));
  options.progress = [&](std::size_t done, std::size_t total) {
    progress.Update("study", done, total);
  };
  const sim::StudySummary summary = sim::RunDivisionsStudy(scene, args.out, options);
  progress.Clear();
  std::cout << "shard " << options.shard.index + 1 << "/" << options.shard.count << ": ran "
            << summary.items_written << " items, skipped " << summary.items_skipped
            << " already done, of " << summary.items_total << "\n";
  if (summary.complete) {
    std::cout << "wrote " << args.out
              << "/divisions.csv, coverage_vs_divisions.png, time_vs_divisions.png, study.json\n";
  } else {
    std::cout << "other shards' items are still missing: the last shard to finish, or a rerun "
                 "without --shard, writes divisions.csv and the plots\n";
  }
  return 0;
}

struct ImportArgs {
  std::string log;
  std::string out;
  std::string sensor;
  bool force = false;
};

int Import(const ImportArgs& args) {
  namespace sim = sonarbench::sim;
  sonarbench::mapping::SensorGeometry sensor;
  if (!args.sensor.empty()) sensor = sim::LoadSensorModel(args.sensor).geometry;
  const sonarbench::mapping::MatLog log = sonarbench::mapping::ReadMatLog(args.log);
  const sim::DatasetSummary summary =
      sim::ImportLogDataset(args.log, log, sensor, args.out, args.force);
  if (summary.already_complete) {
    std::cout << args.out << ": already holds this log's dataset; nothing to do\n";
    return 0;
  }
  std::cout << log.beams.size() << " beams (" << log.truncated_beams << " truncated) in "
            << summary.sweeps_total << " sweeps\nwrote " << args.out << "/manifest.json\n";
  return 0;
}

// An option's text as a T, whole and in T's range; nullopt otherwise.
template <typename T>
std::optional<T> ParsedWhole(const std::string& text) {
  T value{};
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (text.empty() || error != std::errc() || stop != end) return std::nullopt;
  return value;
}

// -s/--seed: a decimal integer from 0 to 2^64 - 1, checked as text (CLI11 would take "-1" as
// 2^64 - 1 and a seed past the top as the top).
void AddSeedOption(CLI::App* command, std::optional<std::uint64_t>& seed,
                   const std::string& description) {
  command->add_option("-s,--seed", seed, description)
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            if (ParsedWhole<std::uint64_t>(text)) return "";
            return "expected an integer from 0 to 18446744073709551615, got '" + text + "'";
          },
          "UINT64"));
}

// --max-triangles and --max-cells: what a run may build (Budgets), checked before building.
void AddBudgetOptions(CLI::App* command, sonarbench::sim::Budgets& budgets) {
  command
      ->add_option("--max-triangles", budgets.max_triangles,
                   "Refuse a scene whose meshes would make more triangles (estimated from the "
                   "scene before anything is built)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command
      ->add_option("--max-cells", budgets.max_cells,
                   "Refuse a scene whose ground truth or map would hold more cells (estimated "
                   "from the scene, or the log's poses, before anything is built)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
}

// The --threads option every subcommand has.
void AddThreadsOption(CLI::App* command, int& threads) {
  command
      ->add_option("-j,--threads", threads,
                   "Threads; 0 = all cores. Outputs are identical for any value.")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
}

// A run that broke still leaves a junit.xml saying so (and nothing of an earlier run), for the CI
// system that collects it.
void CommitErrorJunit(sonarbench::sim::OutputDirectory& out, const RunArgs& args,
                      std::string_view type, const std::string& message) {
  try {
    const std::string xml = sonarbench::sim::ErrorJunitXml(
        std::filesystem::path(args.scene).stem().string(), type, message);
    sonarbench::WriteFileAtomically((out.write_root() / "junit.xml").string(),
                                    [&](std::ostream& file) { file << xml; });
    out.Commit();
  } catch (const std::exception& e) {
    std::cerr << "sonarbench: could not write junit.xml: " << e.what() << "\n";
  }
}

int Run(const RunArgs& args) {
  namespace sim = sonarbench::sim;
  std::vector<std::string> files = sim::kScenarioOutputFiles;
  std::erase(files, "report.json");
  files.insert(files.begin(), "report.json");
  // Taken before any work: a run writes its junit.xml there even when the scene is refused.
  sim::OutputDirectory out(args.out, OneShotClaim("run", files, {args.scene}));
  try {
    const sim::Scene scene = LoadScene(args.scene, args.budgets);
    sim::RunOptions options;
    options.seed = args.seed;
    options.threads = args.threads;
    ProgressLine progress(ProgressLine::WantedFor(args.no_progress));
    options.progress = [&](std::string_view stage, std::size_t done, std::size_t total) {
      progress.Update(stage, done, total);
    };
    const auto result = sim::RunScenario(scene, options);
    progress.Clear();
    sim::WriteScenarioOutputs(out.write_root().string(), scene, result);
    out.Commit();
    PrintSummary(scene, result, args.out);
    return result.verdict.passed ? 0 : kExitCriteriaFailed;
  } catch (const sonarbench::InputError& e) {
    CommitErrorJunit(out, args, "input_error", e.what());
    throw;
  } catch (const std::exception& e) {
    CommitErrorJunit(out, args, "internal_error", e.what());
    throw;
  }
}

// `sonarbench run`: its options, filled into `args` when parsed.
CLI::App* AddRunCommand(CLI::App& app, RunArgs& args) {
  CLI::App* command = app.add_subcommand(
      "run",
      "Run a scenario end to end: simulate every sweep of SCENE, map them, score the map against "
      "the scene's ground truth and its criteria, and write report.json, junit.xml, report.html, "
      "map.bt (open it in octovis), polar.png (the first sweep, beams x bins), fan.png, "
      "map_top.png and map_side.png into --out. Exit status 0 when the criteria pass, 1 when "
      "they fail, 2 on bad input, 3 on an internal error.");
  command->add_option("scene", args.scene, "Scene YAML file (see scenes/)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("-o,--out", args.out, "Output directory (created if needed)")
      ->capture_default_str();
  AddSeedOption(command, args.seed, "Seed of every random draw; overrides the scene's 'seed'");
  AddThreadsOption(command, args.threads);
  AddBudgetOptions(command, args.budgets);
  command->add_flag("--no-progress", args.no_progress,
                    "Never show the progress line (it shows only on a terminal, and never when "
                    "the CI environment variable is set)");
  return command;
}

// `sonarbench map`: its options, filled into `args` when parsed.
CLI::App* AddMapCommand(CLI::App& app, MapArgs& args) {
  CLI::App* command = app.add_subcommand(
      "map",
      "Map a recorded log with the production mapper: INPUT is a sonarbench dataset directory "
      "(from `simulate` or `import`; its manifest's sensor is used) or a real MSIS log in MATLAB "
      ".mat form (the CRAS lab's parsedData layout; the vehicle static at the origin), or a folder "
      "holding one such log. Writes map.bt and map.ot (octovis), map_top.png (occupied cells "
      "from above), polar.png and fan.png (the first sweep) and report.json into --out. The "
      "sensor is the SHAD Micron and the mapper uses its defaults unless --scene, --sensor or "
      "--mapping say otherwise.");
  command
      ->add_option("input", args.input,
                   "A dataset directory, a .mat log, or a folder holding one .mat log")
      ->required()
      ->check(CLI::ExistingPath);
  command->add_option("-o,--out", args.out, "Output directory (created if needed)")
      ->capture_default_str();
  auto* scene_opt =
      command
          ->add_option("--scene", args.scene,
                       "Take the sensor model and the mapping section from this scene")
          ->check(CLI::ExistingFile);
  command->add_option("--sensor", args.sensor, "Sensor model YAML (its geometry is used)")
      ->check(CLI::ExistingFile)
      ->excludes(scene_opt);
  command
      ->add_option("--mapping", args.mapping,
                   "YAML file of mapping parameters (the keys of a scene's 'mapping' section)")
      ->check(CLI::ExistingFile)
      ->excludes(scene_opt);
  command
      ->add_flag("--score", args.score,
                 "Score the map against the --scene's surfaces as `run` scores a simulated one "
                 "(precision, recall, coverage; report.json's metrics). A .mat log, static at its "
                 "origin, is mapped from the scene's sonar pose, which must not move; a dataset's "
                 "beams keep their poses")
      ->needs(scene_opt);
  AddThreadsOption(command, args.threads);
  AddBudgetOptions(command, args.budgets);
  command->add_flag("--no-progress", args.no_progress, "Never show the progress line");
  return command;
}

// `sonarbench fidelity`: its options, filled into `args` when parsed.
CLI::App* AddFidelityCommand(CLI::App& app, FidelityArgs& args) {
  CLI::App* command = app.add_subcommand(
      "fidelity",
      "Compare a simulated scene with a real log of the same place: mean intensity against range "
      "(correlation), the strongest echo's range per head angle (median difference in bins) and "
      "its intensity (percentiles), the profile around it (the tail behind the walls; and its "
      "front, over the beams whose strongest echo is the simulated wall) and around twice its "
      "range (the second trip), intensity histograms (intersection), the texture along range "
      "and across beams (correlations), and the first sweeps side by side (sim left, real "
      "right). Writes fidelity.json, profile.csv/.png, wall_range.csv, wall_profile.csv, "
      "direct_wall_profile.csv, second_trip_profile.csv, histogram.csv, by_head_angle.csv (the "
      "self-reflection's and the near range's mean per head angle), polar.png and fan.png into "
      "--out.");
  command->add_option("scene", args.scene, "Scene YAML file")->required()->check(CLI::ExistingFile);
  command->add_option("log", args.log, "Real log (.mat)")->required()->check(CLI::ExistingFile);
  command->add_option("-o,--out", args.out, "Output directory")->capture_default_str();
  AddSeedOption(command, args.seed, "Overrides the scene's seed");
  AddThreadsOption(command, args.threads);
  AddBudgetOptions(command, args.budgets);
  command->add_flag("--no-progress", args.no_progress, "Never show the progress line");
  command
      ->add_option("--wall-min-range", args.wall_min_range_m,
                   "Strongest echoes are sought beyond this range [m] (past the floor's)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            const std::optional<double> range = ParsedWhole<double>(text);
            if (range && std::isfinite(*range) && *range > 0.0) return "";
            return "expected a range in metres, finite and above 0, got '" + text + "'";
          },
          "METRES"))
      ->capture_default_str();
  return command;
}

// `sonarbench simulate`: its options, filled into `args` when parsed.
CLI::App* AddSimulateCommand(CLI::App& app, SimulateArgs& args) {
  CLI::App* command = app.add_subcommand(
      "simulate",
      "Simulate SCENE into a dataset directory (format: docs/dataset-format.md): beams of every "
      "sweep in binary, a polar PNG per sweep, per-beam ground truth, sonar and vehicle poses "
      "(TUM), the truth occupancy (.bt) and manifest.json with the sha256 of every file. Writes "
      "are atomic; a rerun resumes where a killed one stopped; an existing dataset is replaced "
      "only with --force. `sonarbench map DIR` maps it.");
  command->add_option("scene", args.scene, "Scene YAML file")->required()->check(CLI::ExistingFile);
  command->add_option("-o,--out", args.out, "Dataset directory")->required();
  AddSeedOption(command, args.seed, "Overrides the scene's seed");
  AddThreadsOption(command, args.threads);
  AddBudgetOptions(command, args.budgets);
  command->add_flag("--force", args.force,
                    "Replace an existing dataset (never deletes a directory that is not one)");
  command->add_option(
      "--shard", args.shard,
      "K/N: write only sweeps s with s mod N = K-1 (cluster array jobs; default from "
      "SLURM_ARRAY_TASK_ID/_MIN/_COUNT). Beams are seeded by hashing their index, so shards "
      "give the same bytes as one run");
  command->add_flag("--no-progress", args.no_progress, "Never show the progress line");
  return command;
}

// `sonarbench sweep`: its options, filled into `args` when parsed.
CLI::App* AddSweepCommand(CLI::App& app, SweepArgs& args) {
  CLI::App* command = app.add_subcommand(
      "sweep",
      "The coverage-vs-divisions study (the seed paper's figures 9 and 10): simulate SCENE once, "
      "then for each setting of horizontal x vertical ray divisions (H 1..64 at V 64, V 1..128 at "
      "H 32, and a grid) map it and measure the coverage of the exact beam volume, the map's "
      "precision, recall and coverage, and the mapping time. Writes items/item_NNN.json per "
      "setting, then divisions.csv, coverage_vs_divisions.png, time_vs_divisions.png and "
      "study.json into --out. Resumable; --shard splits the settings across array jobs.");
  command->add_option("scene", args.scene, "Scene YAML file")->required()->check(CLI::ExistingFile);
  command->add_option("-o,--out", args.out, "Study directory")->required();
  AddSeedOption(command, args.seed, "Overrides the scene's seed");
  command->add_option("--sweeps", args.sweeps, "Overrides the scene's sweeps (fewer: quicker)")
      ->check(CLI::Range(1, 100000));
  command
      ->add_option("--coverage-beams", args.coverage_beams,
                   "Beams of the first sweep whose exact volume is measured")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  AddThreadsOption(command, args.threads);
  AddBudgetOptions(command, args.budgets);
  command->add_flag("--force", args.force, "Discard the items of an earlier study in --out");
  command->add_option("--shard", args.shard,
                      "K/N: run only settings i with i mod N = K-1 (default from SLURM_ARRAY_*)");
  command->add_flag("--no-progress", args.no_progress, "Never show the progress line");
  return command;
}

// `sonarbench import`: its options, filled into `args` when parsed.
CLI::App* AddImportCommand(CLI::App& app, ImportArgs& args) {
  CLI::App* command = app.add_subcommand(
      "import",
      "Write a real .mat log as a dataset directory (the format `simulate` writes, without "
      "truth), so `sonarbench map DIR` and other tools read both the same way.");
  command->add_option("log", args.log, "Real log (.mat)")->required()->check(CLI::ExistingFile);
  command->add_option("-o,--out", args.out, "Dataset directory")->required();
  command->add_option("--sensor", args.sensor, "Sensor model YAML (default: the SHAD Micron)")
      ->check(CLI::ExistingFile);
  command->add_flag("--force", args.force, "Replace an existing dataset");
  return command;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "sonarbench: simulate a mechanical scanning imaging sonar, map its beams into an OctoMap, "
      "and score the map against ground truth."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("sonarbench ") + sonarbench::sim::kVersion);

  RunArgs run;
  CLI::App* run_cmd = AddRunCommand(app, run);
  MapArgs map;
  CLI::App* map_cmd = AddMapCommand(app, map);
  FidelityArgs fidelity;
  CLI::App* fidelity_cmd = AddFidelityCommand(app, fidelity);
  SimulateArgs simulate;
  CLI::App* simulate_cmd = AddSimulateCommand(app, simulate);
  SweepArgs sweep;
  CLI::App* sweep_cmd = AddSweepCommand(app, sweep);
  ImportArgs import;
  CLI::App* import_cmd = AddImportCommand(app, import);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // A missing or unknown command is named, with the commands there are.
    if (app.get_subcommands().empty() && (argc == 1 || argv[1][0] != '-')) {
      std::string commands;
      for (const CLI::App* command : app.get_subcommands({})) {
        commands += (commands.empty() ? "" : ", ") + command->get_name();
      }
      std::cerr << "sonarbench: error: "
                << (argc == 1 ? std::string("a command is required")
                              : "unknown command '" + std::string(argv[1]) + "'")
                << "; the commands are " << commands << " (sonarbench --help)\n";
      return kExitBadInput;
    }
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }

  try {
    if (*run_cmd) return Run(run);
    if (*map_cmd) return Map(map);
    if (*fidelity_cmd) return Fidelity(fidelity);
    if (*simulate_cmd) return Simulate(simulate);
    if (*import_cmd) return Import(import);
    if (*sweep_cmd) return Sweep(sweep);
  } catch (const sonarbench::InputError& e) {
    std::cerr << "sonarbench: error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::filesystem::filesystem_error& e) {
    // The machine's refusal (a read-only or full disk, no permission), with the OS's reason.
    std::cerr << "sonarbench: error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "sonarbench: internal error: " << e.what() << "\n";
    return kExitInternalError;
  }
  return kExitInternalError;
}
