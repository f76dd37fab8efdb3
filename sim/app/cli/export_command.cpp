#include <iostream>
#include <memory>

#include "cli.hpp"
#include "sonarbench/io/numpy_export.hpp"
#include "sonarbench/io/rosbag_export.hpp"

namespace sonarbench::app {
namespace {

struct ExportArgs {
  std::string dataset;
  std::string out;
  float sound_speed = 1500.0F;
  bool force = false;
};

int Export(const ExportArgs& args) {
  if (args.out.ends_with(".npz")) {
    io::WriteNpzFromDataset(args.dataset, args.out, args.force);
    std::cout << "wrote " << args.out << " (numpy.load reads it: docs/dataset-format.md)\n";
    return 0;
  }
  io::RosbagContent bag = io::RosbagFromDataset(args.dataset);
  bag.sound_speed_m_s = args.sound_speed;
  io::WriteRosbagFile(bag, args.out, args.force);
  std::cout << bag.beams.size() << " beams on " << io::kSonarTopic << ", /tf, /tf_static"
            << (bag.true_vehicle.empty() ? "" : std::string(", ") + io::kGroundTruthTopic)
            << (bag.labels.empty()
                    ? ""
                    : std::string(", ") + io::kLabelPathTopic + ", " + io::kLabelPointsTopic)
            << "\nwrote " << args.out << "\n";
  return 0;
}

// `sonarbench export`: its options, filled into `args` when parsed.
CLI::App* AddOptions(CLI::App& app, ExportArgs& args) {
  CLI::App* command = app.add_subcommand(
      "export",
      "Write a dataset as a ROS 2 bag (MCAP, as rosbag2 stores it): a "
      "marine_acoustic_msgs/ProjectedSonarImage a beam, /tf, /tf_static and, for simulated "
      "data, the true pose (docs/ros2.md); or, when --out ends in .npz, as NumPy arrays, sweeps "
      "× beams × bins, with a simulated dataset's per-bin labels (docs/dataset-format.md).");
  command->add_option("dataset", args.dataset, "Dataset directory")
      ->required()
      ->check(CLI::ExistingDirectory);
  command->add_option("-o,--out", args.out, "The bag to write (FILE.mcap), or FILE.npz")
      ->required();
  command
      ->add_option("--sound-speed", args.sound_speed,
                   "Speed of sound the ranges were computed at [m/s], for ping_info (default: "
                   "1500, the Micron's default)")
      ->check(CLI::Range(1.0, 10000.0));
  command->add_flag("--force", args.force, "Replace a bag or .npz sonarbench wrote before");
  return command;
}

}  // namespace

Command AddExportCommand(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  return {AddOptions(app, *args), [args] { return Export(*args); }};
}

}  // namespace sonarbench::app
