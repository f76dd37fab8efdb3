#include <algorithm>
#include <iostream>
#include <memory>

#include "cli.hpp"
#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/mapping_yaml.hpp"
#include "sonarbench/sim/app/map_log.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

namespace sonarbench::app {
namespace {

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
  // The sensor and the mapper's defaults: the scene's, else the --sensor model's, else the
  // shipped Micron's; --mapping's keys over them.
  std::string defaults =
      args.sensor.empty() ? sonarbench::sim::ShippedSensorModelPath() : args.sensor;
  sonarbench::mapping::SensorGeometry sensor;
  sonarbench::mapping::MapperConfig config;
  // Every file the command reads: none may be an output.
  std::vector<std::string> inputs = sonarbench::sim::LogInputFiles(args.input);
  inputs.insert(inputs.end(), {args.sensor, args.mapping});
  if (!args.scene.empty()) {
    const sonarbench::sim::Scene scene = sonarbench::sim::LoadScene(args.scene, args.budgets);
    sensor = scene.sensor.geometry;
    config = scene.mapping;
    defaults = args.scene;
    const std::vector<std::string> scene_files = sonarbench::sim::SceneInputFiles(scene);
    inputs.insert(inputs.end(), scene_files.begin(), scene_files.end());
  } else {
    inputs.push_back(defaults);
    const sonarbench::sim::SensorModel model = sonarbench::sim::LoadSensorModel(defaults);
    sensor = model.geometry;
    config = model.mapping;
  }
  if (!args.mapping.empty()) {
    sonarbench::YamlReader reader = sonarbench::YamlReader::FromFile(args.mapping);
    config = sonarbench::io::ReadMapperConfig(reader, config);
    reader.ThrowIfErrors();
  }
  config.threads = args.threads;
  // A .mat log scored against the scene is mapped from the scene's sonar pose.
  std::optional<sonarbench::sim::Scene> scene;
  if (args.score) {
    scene = sonarbench::sim::LoadScene(args.scene, args.budgets);
    sonarbench::sim::CheckBudgets(*scene, args.budgets);
  }
  std::vector<std::string> files = sonarbench::sim::kLogMapOutputFiles;
  std::rotate(files.begin(), files.end() - 1, files.end());  // the record, report.json, first
  io::OutputDirectory out(args.out, OneShotClaim("map", files, inputs));
  ProgressLine progress(ProgressLine::WantedFor(args.no_progress));
  auto result = sonarbench::sim::MapLog(
      args.input, sensor, config, scene ? &*scene : nullptr, args.budgets,
      [&](std::size_t done, std::size_t total) { progress.Update("map", done, total); });
  progress.Clear();
  if (scene) {
    result.score = sonarbench::sim::ScoreLogMap(result, *scene);
    result.certainty = sonarbench::sim::SweepCertainty(result.mapped, result.sensor, config,
                                                       result.mapper->tree(), result.score->truth);
  }
  sonarbench::sim::WriteLogMapOutputs(out.write_root().string(), result, scene ? &*scene : nullptr);
  out.Commit();
  const auto& t = result.totals;
  std::cout << result.beams << " beams (" << result.truncated_beams << " truncated) in "
            << Count(result.sweeps, "sweep") << "; " << t.beams_with_obstacle
            << " with an obstacle\n"
            << "detection: " << DetectionLine(config) << " (from " << defaults
            << (args.mapping.empty() ? "" : " and " + args.mapping) << ")\n";
  for (const std::string& warning : result.warnings) std::cout << "warning: " << warning << "\n";
  if (result.score)
    std::cout << "against " << args.scene << ": " << MetricsLine(result.score->metrics) << "\n";
  std::cout << "timing [s]: import " << Seconds3(result.import_s) << ", map "
            << Seconds3(result.map_s) << "\n"
            << "wrote " << args.out << "/report.json, report.html"
            << (result.score ? ", junit.xml, map_side.png, certainty.png, certainty.csv" : "")
            << ", map.bt, map.ot, map_top.png, polar.png, fan.png\n";
  if (!result.score) return 0;
  PrintVerdict(scene->name, result.score->verdict);
  return result.score->verdict.passed ? 0 : kExitCriteriaFailed;
}

// `sonarbench map`: its options, filled into `args` when parsed.
CLI::App* AddOptions(CLI::App& app, MapArgs& args) {
  CLI::App* command = app.add_subcommand(
      "map",
      "Map a recorded log with the production mapper: INPUT is a sonarbench dataset directory "
      "(from `simulate` or `import`; its manifest's sensor is used) or a real MSIS log in MATLAB "
      ".mat form (the CRAS lab's parsedData layout; the vehicle static at the origin), or a folder "
      "holding one such log. Writes map.bt and map.ot (octovis), map_top.png (occupied cells "
      "from above), polar.png and fan.png (the first sweep), report.html and report.json into "
      "--out; with --score also junit.xml, map_side.png, and certainty.png and .csv (the "
      "occupied cells' probability after each sweep), the map images then against the truth. "
      "The sensor and the mapper's settings are the shipped SHAD Micron model's "
      "(sensor-models/shad-micron.yaml, its mapping section) unless --scene, --sensor or "
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
                 "Score the map against the --scene's surfaces and criteria as `run` scores a "
                 "simulated one (report.json's metrics, verdict and criteria; exit 1 when a "
                 "criterion fails). A .mat log, static at its origin, is mapped from the scene's "
                 "sonar pose, which must not move; a dataset's beams keep their poses")
      ->needs(scene_opt);
  AddThreadsOption(command, args.threads);
  AddBudgetOptions(command, args.budgets);
  command->add_flag("--no-progress", args.no_progress, "Never show the progress line");
  return command;
}

}  // namespace

Command AddMapCommand(CLI::App& app) {
  auto args = std::make_shared<MapArgs>();
  return {AddOptions(app, *args), [args] { return Map(*args); }};
}

}  // namespace sonarbench::app
