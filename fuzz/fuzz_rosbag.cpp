// A ROS 2 bag (MCAP) as `sonarbench import FILE.mcap` reads it: the MCAP records and chunks, the
// CDR messages, the transform tree, first with the sonar static (--static), then posed by /tf,
// under a limit of 16 MB of records.
#include "fuzz_support.hpp"
#include "sonarbench/io/rosbag.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonarbench;
  const auto path = fuzz::ScratchDir() / "bag.mcap";
  fuzz::WriteBytes(path, fuzz::AsText(data, size));
  io::RosbagReadOptions options;
  options.max_bytes = std::uint64_t{16} << 20;
  const auto check = [](const io::RosbagBeams& read) {
    for (const mapping::Beam& beam : read.beams) {
      if (!(beam.bin_size_m > 0.0) || !(beam.head_angle_rad >= 0.0)) __builtin_trap();
    }
  };
  options.static_sonar = true;
  fuzz::KeepsTheContract([&] { check(io::ReadRosbag(path.string(), options)); });
  options.static_sonar = false;
  return fuzz::KeepsTheContract([&] { check(io::ReadRosbag(path.string(), options)); });
}
