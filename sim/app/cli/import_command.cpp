#include <iostream>
#include <memory>

#include "cli.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/mapping/atomic_file.hpp"
#include "sonarbench/mapping/error.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

namespace sonarbench::app {
namespace {

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

// `sonarbench import`: its options, filled into `args` when parsed.
CLI::App* AddOptions(CLI::App& app, ImportArgs& args) {
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

Command AddImportCommand(CLI::App& app) {
  auto args = std::make_shared<ImportArgs>();
  return {AddOptions(app, *args), [args] { return Import(*args); }};
}

}  // namespace sonarbench::app
