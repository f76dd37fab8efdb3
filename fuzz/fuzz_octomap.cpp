// An OctoMap file (.bt or .ot) as `sonarbench score` reads it: ReadOcTreeFile's header and node
// checks, then OctoMap's readers, then a walk over the leaves, under a budget of 10⁶ cells.
#include "fuzz_support.hpp"
#include "sonarbench/io/octomap_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonarbench;
  const auto path = fuzz::ScratchDir() / "map.bt";
  fuzz::WriteBytes(path, fuzz::AsText(data, size));
  return fuzz::KeepsTheContract([&] {
    const auto tree = io::ReadOcTreeFile(path.string(), 1e6);
    std::size_t occupied = 0;
    for (auto it = tree->begin_leafs(); it != tree->end_leafs(); ++it) {
      occupied += tree->isNodeOccupied(*it);
    }
    if (occupied > tree->size()) __builtin_trap();
  });
}
