// A scene's `criteria` mapping (expect, metrics and their bounds), read over the tank's meshes.
#include "fuzz_support.hpp"
#include "sonarbench/io/yaml_reader.hpp"
#include "sonarbench/sim/world/criteria.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonarbench;
  static const std::vector<std::string> kMeshes = {"floor", "wall_north", "wall_south", "wall_east",
                                                   "wall_west"};
  return fuzz::KeepsTheContract([&] {
    YamlReader root =
        YamlReader::FromString(std::string(fuzz::AsText(data, size)), "criteria.yaml");
    const sim::Criteria base = sim::ReadCriteria(root, kMeshes);
    root.ThrowIfErrors();
    // The same text over a base, as a scene that extends another reads it.
    YamlReader again =
        YamlReader::FromString(std::string(fuzz::AsText(data, size)), "criteria.yaml");
    (void)sim::ReadCriteria(again, kMeshes, &base);
    again.ThrowIfErrors();
  });
}
