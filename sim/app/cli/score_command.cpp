#include <iostream>
#include <memory>

#include "cli.hpp"
#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/sim/app/score_map.hpp"

namespace sonarbench::app {
namespace {

struct ScoreArgs {
  bool no_progress = false;
  sonarbench::sim::Budgets budgets;
  std::string map;
  std::string scene;
  std::string out = "out/score";
};

int Score(const ScoreArgs& args) {
  namespace sim = sonarbench::sim;
  sonarbench::CheckOutputDirectory(args.out);
  const sim::Scene scene = sonarbench::sim::LoadScene(args.scene, args.budgets);
  sim::CheckBudgets(scene, args.budgets);
  std::vector<std::string> inputs = sim::SceneInputFiles(scene);
  inputs.push_back(args.map);
  io::OutputDirectory out(args.out,
                          OneShotClaim("score", sim::kMapFileScoreOutputFiles, std::move(inputs)));
  ProgressLine progress(ProgressLine::WantedFor(args.no_progress));
  const sim::MapFileScore file_score = sim::ScoreMapFile(
      args.map, scene, args.budgets,
      [&](std::size_t done, std::size_t total) { progress.Update("observable", done, total); });
  progress.Clear();
  sim::WriteMapFileScoreOutputs(out.write_root().string(), scene, file_score);
  out.Commit();
  std::cout << args.map << " (" << file_score.file.resolution_m << " m) against " << args.scene
            << ": " << MetricsLine(file_score.score.metrics) << "\n"
            << "wrote " << args.out << "/report.json, junit.xml, report.html, map_top.png, "
            << "map_side.png\n";
  PrintVerdict(scene.name, file_score.score.verdict);
  return file_score.score.verdict.passed ? 0 : kExitCriteriaFailed;
}

// `sonarbench score`: its options, filled into `args` when parsed.
CLI::App* AddOptions(CLI::App& app, ScoreArgs& args) {
  CLI::App* command = app.add_subcommand(
      "score",
      "Score a map written by any mapper (an OctoMap OcTree in .bt or .ot form, in the scene's "
      "world frame) against a scene: the scene's surfaces voxelised at the map's own resolution, "
      "the cells a perfect sensor sees from the scene's trajectory, the scene's criteria, as "
      "`run` scores its own map. Writes report.json, junit.xml, report.html, map_top.png and "
      "map_side.png into --out; exit 1 when a criterion fails. A map with under half its "
      "occupied cells within the sonar's reach (its trajectory grown by its range) is refused as "
      "being in another frame.");
  command->add_option("map", args.map, "The map: an OctoMap OcTree file (.bt or .ot)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--scene", args.scene, "The scene the map is of")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("-o,--out", args.out, "Output directory (created if needed)")
      ->capture_default_str();
  AddBudgetOptions(command, args.budgets);
  command->add_flag("--no-progress", args.no_progress, "Never show the progress line");
  return command;
}

}  // namespace

Command AddScoreCommand(CLI::App& app) {
  auto args = std::make_shared<ScoreArgs>();
  return {AddOptions(app, *args), [args] { return Score(*args); }};
}

}  // namespace sonarbench::app
