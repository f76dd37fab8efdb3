#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "cli.hpp"
#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/sim/app/scenario.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"

namespace sonarbench::app {
namespace {

struct RunArgs {
  sonarbench::sim::Budgets budgets;
  std::string scene;
  std::string out = "out";
  std::optional<std::uint64_t> seed;
  int threads = 0;
  bool no_progress = false;
};

void PrintSummary(const sonarbench::sim::Scene& scene, const sonarbench::sim::ScenarioResult& r,
                  const std::string& out) {
  const auto& t = r.timings;
  std::cout << "beams " << r.beams << ", seed " << r.seed << ", threads " << r.threads << "\n"
            << MetricsLine(r.score.metrics) << "\n"
            << "timing [s]: scene " << Seconds3(t.build_scene_s) << ", simulate "
            << Seconds3(t.simulate_s) << ", map " << Seconds3(t.map_s) << ", ground truth "
            << Seconds3(t.ground_truth_s) << ", score " << Seconds3(t.score_s) << "\n"
            << "wrote " << out << "/report.json, junit.xml, report.html, map.bt and images\n";
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
  PrintVerdict(scene.name, r.score.verdict);
}

// A run that broke leaves a junit.xml saying so (and no other output) for the CI system that
// collects it; but an earlier complete result in --out stays as it was, whole.
void CommitErrorJunit(io::OutputDirectory& out, const RunArgs& args, std::string_view type,
                      const std::string& message) {
  try {
    out.DiscardStaged();
    if (out.HoldsRecord()) {
      std::cerr << "sonarbench: " << args.out
                << ": the last complete run's outputs stay as they were (this run wrote none)\n";
      return;
    }
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
  // The scene is loaded first, so that every file it reads is known as an input; the directory
  // is taken before any work, so a run writes its junit.xml there even when the scene is refused.
  std::optional<sim::Scene> loaded;
  std::exception_ptr refused;
  try {
    loaded = sim::LoadScene(args.scene, args.budgets);
  } catch (const std::exception&) {
    refused = std::current_exception();  // reported in junit.xml below
  }
  io::OutputDirectory out(
      args.out,
      OneShotClaim("run", files, loaded ? sim::SceneInputFiles(*loaded) : std::vector{args.scene}));
  try {
    if (refused) std::rethrow_exception(refused);
    const sim::Scene& scene = *loaded;
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
    return result.score.verdict.passed ? 0 : kExitCriteriaFailed;
  } catch (const sonarbench::InputError& e) {
    CommitErrorJunit(out, args, "input_error", e.what());
    throw;
  } catch (const std::exception& e) {
    CommitErrorJunit(out, args, "internal_error", e.what());
    throw;
  }
}

// `sonarbench run`: its options, filled into `args` when parsed.
CLI::App* AddOptions(CLI::App& app, RunArgs& args) {
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

}  // namespace

Command AddRunCommand(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  return {AddOptions(app, *args), [args] { return Run(*args); }};
}

}  // namespace sonarbench::app
