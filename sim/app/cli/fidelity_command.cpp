#include <array>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/mapping/atomic_file.hpp"
#include "sonarbench/mapping/error.hpp"
#include "sonarbench/sim/report/fidelity_report.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/ray_tracer.hpp"

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
};

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
  const sonarbench::io::MatLog log = sonarbench::io::ReadMatLog(args.log);
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
  std::cout << sim::FidelitySummary(sim::FidelityJson(report, args.scene, args.log)) << "wrote "
            << args.out << "/fidelity.json\n";
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

}  // namespace

Command AddFidelityCommand(CLI::App& app) {
  auto args = std::make_shared<FidelityArgs>();
  return {AddOptions(app, *args), [args] { return Fidelity(*args); }};
}

}  // namespace sonarbench::app
