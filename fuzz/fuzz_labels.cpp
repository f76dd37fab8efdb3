// A dataset's label file (truth/labels_NNNN.bin) as `export` reads it: ReadLabelFile's frame,
// size and layout checks, then every bin's shares, mesh and point.
#include "fuzz_support.hpp"
#include "sonarbench/io/labels.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonarbench;
  const auto path = fuzz::ScratchDir() / "labels.bin";
  fuzz::WriteBytes(path, fuzz::AsText(data, size));
  return fuzz::KeepsTheContract([&] {
    for (const io::BeamLabels& beam : io::ReadLabelFile(path.string())) {
      if (beam.mesh.size() != beam.shares.size() || beam.point_sonar_m.size() != beam.shares.size())
        __builtin_trap();
      for (const auto& shares : beam.shares) {
        unsigned sum = 0;
        for (const std::uint8_t s : shares) sum += s;
        if (sum != 255) __builtin_trap();
      }
    }
  });
}
