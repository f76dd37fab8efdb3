#include <array>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include "cli.hpp"
#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/sim/app/detector_study.hpp"
#include "sonarbench/sim/app/map_fidelity.hpp"
#include "sonarbench/sim/app/map_log.hpp"
#include "sonarbench/sim/report/fidelity_report.hpp"
#include "sonarbench/sim/sonar/scene_world.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"

namespace sonarbench::app {
namespace {

struct FidelityArgs {
  bool no_progress = false;
  sonarbench::sim::Budgets budgets;
  std::string scene;
  std::string log;
  std::string out = "out/fidelity";
  std::optional<std::uint64_t> seed;
  int threads = 0;
  double wall_min_range_m = 1.6;
  std::string maps = "all";
  std::size_t seeds = 0;
};

// The log's beams: a .mat log, a folder holding one, or a dataset directory (as `map` takes).
std::vector<sonarbench::mapping::Beam> ReadLogBeams(const std::string& input) {
  if (const std::string mat = sonarbench::sim::MatLogInDirectory(input); !mat.empty()) {
    return sonarbench::io::ReadMatLog(mat).beams;
  }
  if (std::filesystem::is_directory(input)) return sonarbench::io::ReadDataset(input).beams;
  return sonarbench::io::ReadMatLog(input).beams;
}

// The detector study's settings --maps names: all of them, none, or their indices (detectors.csv's
// `item` column) separated by commas. Throws InputError naming the option and what it expects.
std::optional<std::vector<sonarbench::sim::DetectorItem>> MapSettings(
    const std::string& text, const sonarbench::mapping::DetectionConfig& detection) {
  const auto all = sonarbench::sim::DetectorStudyItems(detection);
  if (text == "none") return std::nullopt;
  if (text == "all") return all;
  std::vector<sonarbench::sim::DetectorItem> chosen;
  std::stringstream list(text);
  for (std::string item; std::getline(list, item, ',');) {
    const std::optional<std::size_t> index = ParsedWhole<std::size_t>(item);
    if (!index || *index >= all.size()) {
      throw sonarbench::InputError("--maps '" + text + "': expected all, none, or indices 0-" +
                                   std::to_string(all.size() - 1) +
                                   " of the detector study's settings separated by commas");
    }
    chosen.push_back(all[*index]);
  }
  if (chosen.size() < 2) {
    throw sonarbench::InputError("--maps '" + text + "': expected at least two settings to rank");
  }
  return chosen;
}

int Fidelity(const FidelityArgs& args) {
  namespace sim = sonarbench::sim;
  sonarbench::CheckOutputDirectory(args.out);
  const sim::Scene scene = sonarbench::sim::LoadScene(args.scene, args.budgets);
  if (const double range = scene.sensor.geometry.MaxRangeM(); args.wall_min_range_m >= range) {
    std::ostringstream message;
    message << "--wall-min-range " << args.wall_min_range_m << ": expected less than the sonar's "
            << range << " m range (no echo lies past it)";
    throw sonarbench::InputError(message.str());
  }
  const auto map_settings = MapSettings(args.maps, scene.mapping.detection);
  const std::vector<sonarbench::mapping::Beam> log_beams = ReadLogBeams(args.log);
  sim::CheckBeamsMapCells(log_beams, scene.sensor.geometry, scene.mapping.resolution_m,
                          args.budgets, args.log);
  const sim::SceneWorld world(scene);
  std::vector<std::string> inputs = sim::SceneInputFiles(scene);
  const std::vector<std::string> log_files = sim::LogInputFiles(args.log);
  inputs.insert(inputs.end(), log_files.begin(), log_files.end());
  io::OutputDirectory out(args.out, OneShotClaim("fidelity", sim::kFidelityOutputFiles, inputs));
  ProgressLine progress(ProgressLine::WantedFor(args.no_progress));
  const auto synthesized = sim::SimulateScene(
      scene, world.tracer, args.seed.value_or(scene.seed), args.threads,
      [&](std::size_t done, std::size_t total) { progress.Update("simulate", done, total); });
  progress.Clear();
  const std::vector<sonarbench::mapping::Beam> beams = sim::BeamsOf(synthesized);
  const auto& g = scene.sensor.geometry;
  const auto report = sim::CompareWithLog(beams, log_beams, g, args.wall_min_range_m);
  nlohmann::json maps;
  nlohmann::json spread;
  if (map_settings || args.seeds > 0) {
    sim::DetectorStudyOptions options;
    if (map_settings) options.items = *map_settings;
    options.seed = args.seed;
    options.log = args.log;
    options.threads = args.threads;
    options.world = &world;
    options.progress = [&](std::size_t done, std::size_t total) {
      progress.Update("maps", done, total);
    };
    if (args.seeds > 0) {
      sim::MapSpreadOptions runs;
      for (std::size_t s = 0; s < args.seeds; ++s)
        runs.seeds.push_back(args.seed.value_or(scene.seed) + s);
      sim::MapSpread judged = sim::JudgeMapsAgainstSeeds(scene, options, runs);
      maps = std::move(judged.maps);
      spread = std::move(judged.spread);
    } else {
      maps = sim::MapFidelity(scene, options);
    }
    progress.Clear();
  }
  const auto per_sweep = static_cast<std::size_t>(g.BeamsPerSweep());
  const std::span<const sonarbench::mapping::Beam> sim_all(beams);
  const std::span<const sonarbench::mapping::Beam> real_all(log_beams);
  sim::WriteFidelityOutputs(
      out.write_root().string(), report, sim_all.first(std::min(per_sweep, sim_all.size())),
      real_all.first(std::min(per_sweep, real_all.size())), g, args.scene, args.log, maps, spread);
  out.Commit();
  nlohmann::json brief = sim::FidelityJson(report, args.scene, args.log);
  if (!maps.is_null()) brief["maps"] = maps;
  if (!spread.is_null()) brief["spread"] = spread;
  std::cout << sim::FidelityBrief(brief) << "wrote " << args.out
            << "/report.html, fidelity.json (every statistic)"
            << (maps.is_null() ? "" : ", maps.csv") << (spread.is_null() ? "" : ", spread.csv")
            << ", profile.png, polar.png, fan.png\n";
  return 0;
}

// `sonarbench fidelity`: its options, filled into `args` when parsed.
CLI::App* AddOptions(CLI::App& app, FidelityArgs& args) {
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
      "--out; and, with --maps, the maps of both against the scene, setting by setting, in "
      "maps.csv, with report.html to read first.");
  command->add_option("scene", args.scene, "Scene YAML file")->required()->check(CLI::ExistingFile);
  command->add_option("log", args.log, "Real log: a .mat log, its folder, or a dataset directory")
      ->required()
      ->check(CLI::ExistingPath);
  command
      ->add_option("--maps", args.maps,
                   "Also map the scene and the log with the detector study's settings (all, none, "
                   "or indices as in detectors.csv, e.g. 6,7,8) over the whole sweep and each half "
                   "of it, and compare the maps (fidelity.json's maps, maps.csv, report.html)")
      ->capture_default_str();
  command
      ->add_option(
          "--seeds", args.seeds,
          "Also judge the log against N simulated runs (seeds SEED to SEED+N-1, SEED the "
          "scene's or --seed): per figure and part, whether the log lies within the runs' "
          "own spread at the scene's mapping and over the --maps settings (fidelity.json's "
          "spread, spread.csv, report.html)")
      ->check(CLI::Range(std::size_t{4}, std::size_t{64}));
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

}  // namespace

Command AddFidelityCommand(CLI::App& app) {
  auto args = std::make_shared<FidelityArgs>();
  return {AddOptions(app, *args), [args] { return Fidelity(*args); }};
}

}  // namespace sonarbench::app
