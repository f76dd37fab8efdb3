#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/sim/app/detector_study.hpp"
#include "sonarbench/sim/app/map_log.hpp"

namespace sonarbench::app {
namespace {

struct DetectorsArgs {
  sonarbench::sim::Budgets budgets;
  std::string scene;
  std::string log;
  std::string out = "out/detectors";
  std::optional<std::uint64_t> seed;
  int threads = 0;
  std::vector<double> heads;
  bool no_progress = false;
};

int Detectors(const DetectorsArgs& args) {
  namespace sim = sonarbench::sim;
  sonarbench::CheckOutputDirectory(args.out);
  const sim::Scene scene = sonarbench::sim::LoadScene(args.scene, args.budgets);
  sim::CheckBudgets(scene, args.budgets);
  sim::DetectorStudyOptions options;
  options.seed = args.seed;
  options.log = args.log;
  options.threads = args.threads;
  if (!args.heads.empty()) {
    if (!(args.heads[0] >= 0.0 && args.heads[0] < args.heads[1] && args.heads[1] <= 360.0)) {
      std::ostringstream message;
      message << "--heads " << args.heads[0] << " " << args.heads[1]
              << ": expected FROM TO degrees with 0 <= FROM < TO <= 360";
      throw sonarbench::InputError(message.str());
    }
    options.heads_deg = std::pair{args.heads[0], args.heads[1]};
  }
  std::vector<std::string> inputs = sim::SceneInputFiles(scene);
  if (!args.log.empty()) {
    const std::vector<std::string> log_files = sim::LogInputFiles(args.log);
    inputs.insert(inputs.end(), log_files.begin(), log_files.end());
  }
  io::OutputDirectory out(args.out,
                          OneShotClaim("detectors", sim::kDetectorStudyFiles, std::move(inputs)));
  ProgressLine progress(ProgressLine::WantedFor(args.no_progress));
  options.progress = [&](std::size_t done, std::size_t total) {
    progress.Update("settings", done, total);
  };
  const std::vector<sim::DetectorRow> rows = sim::RunDetectorStudy(scene, options);
  progress.Clear();
  sim::WriteDetectorStudy(out.write_root().string(), scene, options, rows);
  out.Commit();
  std::cout << "precision / recall at 1 cell, ghost share: scene"
            << (args.log.empty() ? "" : "; log") << "\n";
  for (const sim::DetectorRow& row : rows) {
    char line[256];
    std::snprintf(line, sizeof line, "%-42s %.3f / %.3f, %.3f", row.item.name.c_str(),
                  row.scene.precision_within[1], row.scene.recall_within[1], row.scene.ghost_share);
    std::cout << line;
    if (row.log) {
      std::snprintf(line, sizeof line, "; %.3f / %.3f, %.3f", row.log->precision_within[1],
                    row.log->recall_within[1], row.log->ghost_share);
      std::cout << line;
    }
    std::cout << "\n";
  }
  if (const auto agreement = sim::StudyAgreement(rows); !agreement.empty()) {
    std::cout << "the scene against the log over the settings: Spearman, mean / max |difference|\n";
    for (const sim::Agreement& a : agreement) {
      char line[160];
      std::snprintf(line, sizeof line, "  %-17s %5.2f, %.3f / %.3f\n", a.figure.c_str(), a.spearman,
                    a.mean_abs_difference, a.max_abs_difference);
      std::cout << line;
    }
    std::cout << "best F1 at 1 cell: " << rows[sim::BestF1Row(rows, false)].item.name
              << " (scene); " << rows[sim::BestF1Row(rows, true)].item.name << " (log)\n";
  }
  std::cout << "wrote " << args.out << "/detectors.csv, precision_vs_recall_scene.png"
            << (args.log.empty() ? "" : ", precision_vs_recall_log.png") << ", study.json\n";
  return 0;
}

// `sonarbench detectors`: its options, filled into `args` when parsed.
CLI::App* AddOptions(CLI::App& app, DetectorsArgs& args) {
  CLI::App* command = app.add_subcommand(
      "detectors",
      "The detector study: simulate SCENE once and map it with each detector setting (threshold "
      "70-150, Canny, automatic Canny; the first echo only, two echoes by strength, two echoes "
      "where a neighbouring beam hears the later one first), and with --log map a recorded log of "
      "the place the same way, both scored against the scene's surfaces as `run` and `map "
      "--score` score them. Writes detectors.csv, precision_vs_recall_scene.png (and _log.png) "
      "and study.json into --out: how to choose the mapping section's detection for a place.");
  command->add_option("scene", args.scene, "Scene YAML file")->required()->check(CLI::ExistingFile);
  command
      ->add_option("--log", args.log,
                   "A recorded log of the scene's place: a .mat log, its folder, or a dataset")
      ->check(CLI::ExistingPath);
  command->add_option("-o,--out", args.out, "Output directory")->capture_default_str();
  command
      ->add_option("--heads", args.heads,
                   "Only the beams whose head angle lies in [FROM, TO) degrees, of the scene and "
                   "the log alike: one half of the sweep to fit on, the other to check")
      ->expected(2)
      ->type_name("FROM TO");
  AddSeedOption(command, args.seed, "Overrides the scene's seed");
  AddThreadsOption(command, args.threads);
  AddBudgetOptions(command, args.budgets);
  command->add_flag("--no-progress", args.no_progress, "Never show the progress line");
  return command;
}

}  // namespace

Command AddDetectorsCommand(CLI::App& app) {
  auto args = std::make_shared<DetectorsArgs>();
  return {AddOptions(app, *args), [args] { return Detectors(*args); }};
}

}  // namespace sonarbench::app
