#include "sonarbench/io/rosbag_export.hpp"

#include <filesystem>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/labels.hpp"
#include "sonarbench/io/mcap.hpp"
#include "sonarbench/io/version.hpp"

namespace sonarbench::io {
namespace {

namespace fs = std::filesystem;

// A rigid mounting moves the sonar with the vehicle to within this [m, rad]; TUM files keep
// nine significant digits.
constexpr double kMountTolerance = 1e-6;

std::string LibraryName() { return std::string("sonarbench ") + kVersion; }

}  // namespace

RosbagContent RosbagFromDataset(const std::string& dir) {
  Dataset dataset = ReadDataset(dir);
  RosbagContent bag;
  bag.sensor = dataset.sensor;
  bag.labels = ReadDatasetLabels(dir, dataset);  // before the beams move out
  bag.beams = std::move(dataset.beams);
  const fs::path vehicle_file = fs::path(dir) / "poses/vehicle.tum";
  const fs::path sonar_file = fs::path(dir) / "poses/sonar_true.tum";
  if (!fs::exists(vehicle_file) || !fs::exists(sonar_file)) return bag;
  const auto vehicle = ReadTum(vehicle_file.string());
  const auto sonar = ReadTum(sonar_file.string());
  if (vehicle.size() != bag.beams.size() || sonar.size() != bag.beams.size()) {
    throw InputError(vehicle_file.string() + ", " + sonar_file.string() +
                     ": expected a pose for each of the dataset's " +
                     std::to_string(bag.beams.size()) + " beams");
  }
  for (std::size_t b = 0; b < vehicle.size(); ++b) {
    const Eigen::Isometry3d mount = vehicle[b].pose.inverse() * sonar[b].pose;
    if (b == 0) bag.T_vehicle_sonar = mount;
    const Eigen::Isometry3d change = bag.T_vehicle_sonar.inverse() * mount;
    if (change.translation().norm() > kMountTolerance ||
        Eigen::AngleAxisd(change.linear()).angle() > kMountTolerance) {
      throw InputError(dir + ": the sonar moves on the vehicle (beam " + std::to_string(b) +
                       " of poses/vehicle.tum and poses/sonar_true.tum); expected a rigid mount");
    }
    bag.true_vehicle.push_back(vehicle[b].pose);
  }
  return bag;
}

void WriteRosbagFile(const RosbagContent& bag, const std::string& path, bool force) {
  ClaimExportFile(path, force, McapLibrary(path).value_or("").rfind("sonarbench", 0) == 0,
                  "an MCAP file");
  // A killed export's bag starts with the magic and a header naming sonarbench as its library.
  RemoveDeadTemporaries(path, [](const std::string& head) {
    return head.starts_with(kMcapMagic) && head.find("sonarbench") != std::string::npos;
  });
  WriteFileAtomically(path, [&](std::ostream& out) { WriteRosbag(out, bag, LibraryName()); });
}

}  // namespace sonarbench::io
