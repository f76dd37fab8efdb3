// sonarbench: the command-line front end. Exit status: 0 success, 2 bad input, 3 internal error.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <iostream>
#include <optional>
#include <string>

#include "sonarbench/mapping/error.hpp"
#include "sonarbench/sim/scenario.hpp"
#include "sonarbench/sim/scene.hpp"

namespace {

constexpr int kExitBadInput = 2;
constexpr int kExitInternalError = 3;

struct RunArgs {
  std::string scene;
  std::string out = "out";
  std::optional<std::uint64_t> seed;
  int threads = 0;
};

void PrintSummary(const sonarbench::sim::ScenarioResult& r, const std::string& out) {
  const auto& m = r.metrics;
  const auto& t = r.timings;
  std::cout << "beams " << r.beams << ", seed " << r.seed << ", threads " << r.threads << "\n"
            << "occupied precision " << m.occupied_precision << " (" << m.true_positive_cells
            << "/" << m.occupied_cells << "), recall " << m.occupied_recall << " ("
            << m.observed_occupied_cells << "/" << m.observable_cells << "), coverage "
            << m.coverage << " (" << m.known_observable_cells << "/" << m.observable_cells
            << ")\n"
            << "timing [s]: scene " << t.build_scene_s << ", simulate " << t.simulate_s
            << ", map " << t.map_s << ", ground truth " << t.ground_truth_s << ", score "
            << t.score_s << "\n"
            << "wrote " << out << "/report.json\n";
}

int Run(const RunArgs& args) {
  const sonarbench::sim::Scene scene = sonarbench::sim::LoadScene(args.scene);
  sonarbench::sim::RunOptions options;
  options.seed = args.seed;
  options.threads = args.threads;
  const auto result = sonarbench::sim::RunScenario(scene, options);
  sonarbench::sim::WriteScenarioOutputs(args.out, scene, result);
  PrintSummary(result, args.out);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "sonarbench: simulate a mechanical scanning imaging sonar, map its beams into an OctoMap, "
      "and score the map against ground truth."};
  app.require_subcommand(1);

  RunArgs run;
  CLI::App* run_cmd = app.add_subcommand(
      "run",
      "Run a scenario end to end: simulate every sweep of SCENE, map them, score the map against "
      "the scene's ground truth, and write report.json, map.bt (open it in octovis), polar.png "
      "(the first sweep, beams x bins), fan.png and map_top.png into --out.");
  run_cmd->add_option("scene", run.scene, "Scene YAML file (see scenes/)")
      ->required()
      ->check(CLI::ExistingFile);
  run_cmd->add_option("-o,--out", run.out, "Output directory (created if needed)")
      ->capture_default_str();
  run_cmd->add_option("-s,--seed", run.seed,
                      "Seed of every random draw; overrides the scene's 'seed'");
  run_cmd->add_option("-j,--threads", run.threads,
                      "Threads for simulation and mapping; 0 = all cores. Outputs are identical "
                      "for any value.")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }

  try {
    if (*run_cmd) return Run(run);
  } catch (const sonarbench::InputError& e) {
    std::cerr << "sonarbench: error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "sonarbench: internal error: " << e.what() << "\n";
    return kExitInternalError;
  }
  return kExitInternalError;
}
