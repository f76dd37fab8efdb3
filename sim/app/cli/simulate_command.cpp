#include <iostream>
#include <memory>

#include "cli.hpp"
#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"

namespace sonarbench::app {
namespace {

struct SimulateArgs {
  sonarbench::sim::Budgets budgets;
  std::string scene;
  std::string out;
  std::optional<std::uint64_t> seed;
  int threads = 0;
  bool force = false;
  std::string shard;
  bool no_progress = false;
  bool no_labels = false;
};

int Simulate(const SimulateArgs& args) {
  namespace sim = sonarbench::sim;
  const sim::Scene scene = sonarbench::sim::LoadScene(args.scene, args.budgets);
  sim::DatasetOptions options;
  options.seed = args.seed;
  options.threads = args.threads;
  options.force = args.force;
  options.labels = !args.no_labels;
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
            << Count(summary.sweeps_written, "sweep") << ", skipped " << summary.sweeps_skipped
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

// `sonarbench simulate`: its options, filled into `args` when parsed.
CLI::App* AddOptions(CLI::App& app, SimulateArgs& args) {
  CLI::App* command = app.add_subcommand(
      "simulate",
      "Simulate SCENE into a dataset directory (format: docs/dataset-format.md): beams of every "
      "sweep in binary, a polar PNG per sweep, per-beam ground truth, per-bin labels of where "
      "each echo came from, sonar and vehicle poses (TUM), the truth occupancy (.bt) and "
      "manifest.json with the sha256 of every file. Writes "
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
  command->add_flag("--no-labels", args.no_labels,
                    "Write no per-bin label files (truth/labels_NNNN.bin, 3-4 times the size of "
                    "the beam files); the beams are the same bytes either way");
  command->add_flag("--no-progress", args.no_progress, "Never show the progress line");
  return command;
}

}  // namespace

Command AddSimulateCommand(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  return {AddOptions(app, *args), [args] { return Simulate(*args); }};
}

}  // namespace sonarbench::app
