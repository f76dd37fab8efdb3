// The production mapper fed beams of hostile geometry, as a reader hands them over: each beam's
// head angle, bin size, bin count and pose drawn from the input, its bins from the rest. The
// beams pass the dataset's beam-file reader (what `map` reads them through) and the map-cell
// budget every command checks (sim::CheckBeamsMapCells), scaled to this process's 512 MB; then the
// mapper integrates them, sweep by sweep, with a detection method and resolution drawn too. A
// refusal is an InputError with a message; anything else (a crash, a sanitizer report, an input
// slower than -timeout, memory past -rss_limit_mb) is a finding: the budget let through a map the
// machine cannot hold.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <sstream>
#include <vector>

#include "fuzz_support.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/world/budget.hpp"

namespace {

using sonarbench::mapping::Beam;

// A pose from six drawn numbers, any finite value (a TUM file holds any).
Eigen::Isometry3d DrawPose(FuzzedDataProvider& in) {
  Eigen::Vector3d t;
  for (int i = 0; i < 3; ++i) t[i] = in.ConsumeFloatingPoint<double>();
  const double roll = in.ConsumeFloatingPoint<double>();
  const double pitch = in.ConsumeFloatingPoint<double>();
  const double yaw = in.ConsumeFloatingPoint<double>();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  if (!t.allFinite() || !std::isfinite(roll + pitch + yaw)) return pose;
  pose.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  pose.translation() = t;
  return pose;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonarbench;
  FuzzedDataProvider in(data, size);
  mapping::MapperConfig config;
  config.threads = 1;
  config.resolution_m = in.PickValueInArray({0.02, 0.05, 0.1, 0.25});
  using Detection = mapping::DetectionConfig;
  config.detection.method =
      in.PickValueInArray({Detection::Method::kThreshold, Detection::Method::kCanny,
                           Detection::Method::kCaCfar, Detection::Method::kOsCfar});
  config.detection.threshold = in.ConsumeIntegralInRange<int>(1, 255);
  config.detection.behind_walls =
      in.PickValueInArray({Detection::BehindWalls::kKeep, Detection::BehindWalls::kRefuse});
  if (in.ConsumeBool()) {  // a water column somewhere within the poses' reach
    config.water.floor_z_m = in.ConsumeFloatingPointInRange<double>(-20.0, 20.0);
    config.water.surface_z_m =
        config.water.floor_z_m + in.ConsumeFloatingPointInRange<double>(0.01, 20.0);
  }
  const mapping::SensorGeometry sensor;
  std::vector<Beam> beams(in.ConsumeIntegralInRange<std::size_t>(1, 12));
  for (Beam& beam : beams) {
    beam.time_s = in.ConsumeFloatingPoint<double>();
    beam.head_angle_rad = in.ConsumeFloatingPoint<double>();
    beam.bin_size_m = in.ConsumeFloatingPoint<double>();
    beam.T_world_sonar = DrawPose(in);
    beam.intensities.resize(in.ConsumeIntegralInRange<std::size_t>(0, 2 * kMaxBinsPerBeam));
  }
  const std::vector<std::uint8_t> bins = in.ConsumeRemainingBytes<std::uint8_t>();
  for (Beam& beam : beams) {
    for (std::size_t k = 0; k < beam.intensities.size(); ++k) {
      beam.intensities[k] = bins.empty() ? 0 : bins[k % bins.size()];
    }
  }
  return fuzz::KeepsTheContract([&] {
    // Through the reader: a beam file of these beams, read back (it refuses what `map` would).
    std::stringstream file;
    io::WriteBeamFile(file, beams);
    std::vector<Beam> read = io::ReadBeamFile(file, "fuzzed beams");
    for (std::size_t b = 0; b < read.size(); ++b) read[b].T_world_sonar = beams[b].T_world_sonar;
    // OctoMap takes up to ~100 bytes a cell: 2e6 cells within the fuzzer's 512 MB.
    sim::Budgets budgets;
    budgets.max_cells = 2e6;
    sim::CheckBeamsMapCells(read, sensor, config.resolution_m, budgets, "fuzzed beams");
    mapping::Mapper mapper(config, sensor);
    (void)mapper.IntegrateSweeps(read);
  });
}
