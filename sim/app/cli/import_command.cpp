#include <filesystem>
#include <iostream>
#include <memory>

#include "cli.hpp"
#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/io/mcap.hpp"
#include "sonarbench/io/rosbag.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

namespace sonarbench::app {
namespace {

struct ImportArgs {
  std::string log;
  std::string out;
  std::string sensor;
  std::string topic;
  bool static_sonar = false;
  bool force = false;
  std::uint64_t max_input_mb = kMaxLogBytes >> 20;
};

// A ROS 2 bag's beams, posed by its transforms (or static at the origin with --static).
sim::ImportedLog ReadBag(const ImportArgs& args, const mapping::SensorGeometry& sensor) {
  io::RosbagReadOptions options;
  options.sensor = sensor;
  options.topic = args.topic;
  options.static_sonar = args.static_sonar;
  options.max_bytes = args.max_input_mb << 20;
  io::RosbagBeams bag = io::ReadRosbag(args.log, options);
  bool moves = false;
  for (const mapping::Beam& beam : bag.beams) {
    moves = moves || !beam.T_world_sonar.isApprox(bag.beams.front().T_world_sonar, 1e-12);
  }
  sim::ImportedLog log{std::move(bag.beams), bag.truncated_beams, {}, {}};
  log.info = {{"format", "mcap"},
              {"topic", bag.topic},
              {"sonar_frame", bag.sonar_frame},
              {"world_frame", bag.world_frame},
              {"poses", args.static_sonar ? "static" : (moves ? "tf, moving" : "tf, static")},
              {"beams_outside_tf", bag.beams_outside_tf}};
  log.options = {{"topic", args.topic}, {"static", args.static_sonar}};
  if (bag.beams_outside_tf > 0) {
    std::cout << bag.beams_outside_tf
              << " beams left out: the transforms do not cover their time\n";
  }
  return log;
}

int Import(const ImportArgs& args) {
  namespace sim = sonarbench::sim;
  mapping::SensorGeometry sensor;
  if (!args.sensor.empty()) sensor = sim::LoadSensorModel(args.sensor).geometry;
  // A bag by its magic bytes, whatever its name; anything else is read as a .mat log.
  const bool bag =
      io::StartsAsMcap(args.log) || std::filesystem::path(args.log).extension() == ".mcap";
  if (!bag && (!args.topic.empty() || args.static_sonar)) {
    throw InputError("--topic and --static apply to ROS 2 bags (.mcap), not to " + args.log);
  }
  sim::ImportedLog log;
  if (bag) {
    log = ReadBag(args, sensor);
  } else {
    log = sim::ImportedMatLog(io::ReadMatLog(args.log, args.max_input_mb << 20));
  }
  const sim::DatasetSummary summary =
      sim::ImportLogDataset(args.log, log, sensor, args.out, args.force, args.sensor);
  if (summary.already_complete) {
    std::cout << args.out << ": already holds this log's dataset; nothing to do\n";
    return 0;
  }
  std::cout << log.beams.size() << " beams (" << log.truncated_beams << " truncated) in "
            << Count(summary.sweeps_total, "sweep") << "\nwrote " << args.out << "/manifest.json\n";
  return 0;
}

// `sonarbench import`: its options, filled into `args` when parsed.
CLI::App* AddOptions(CLI::App& app, ImportArgs& args) {
  CLI::App* command = app.add_subcommand(
      "import",
      "Write a recorded log, a .mat log or a ROS 2 bag (.mcap), as a dataset directory (the "
      "format `simulate` writes, without truth), so `sonarbench map DIR` reads both the same way.");
  command->add_option("log", args.log, "Real log (.mat) or ROS 2 bag (.mcap)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("-o,--out", args.out, "Dataset directory")->required();
  command->add_option("--sensor", args.sensor, "Sensor model YAML (default: the SHAD Micron)")
      ->check(CLI::ExistingFile);
  command->add_option("--topic", args.topic,
                      "The bag's ProjectedSonarImage topic (default: its only one)");
  command->add_flag("--static", args.static_sonar,
                    "Bag without transforms: the sonar static at the origin, as a .mat log");
  command->add_flag("--force", args.force, "Replace an existing dataset");
  command
      ->add_option("--max-input-mb", args.max_input_mb,
                   "MiB the log may take, its file and what it decompresses to together")
      ->capture_default_str()
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 20));
  return command;
}

}  // namespace

Command AddImportCommand(CLI::App& app) {
  auto args = std::make_shared<ImportArgs>();
  return {AddOptions(app, *args), [args] { return Import(*args); }};
}

}  // namespace sonarbench::app
