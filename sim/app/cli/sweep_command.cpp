#include <iostream>
#include <memory>

#include "cli.hpp"
#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/sim/app/divisions_study.hpp"

namespace sonarbench::app {
namespace {

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
  const sim::Scene scene = sonarbench::sim::LoadScene(args.scene, args.budgets);
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

// `sonarbench sweep`: its options, filled into `args` when parsed.
CLI::App* AddOptions(CLI::App& app, SweepArgs& args) {
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

}  // namespace

Command AddSweepCommand(CLI::App& app) {
  auto args = std::make_shared<SweepArgs>();
  return {AddOptions(app, *args), [args] { return Sweep(*args); }};
}

}  // namespace sonarbench::app
