// A sensor-model YAML file (geometry, acoustics, self-reflection, mounting), read as
// LoadSensorModel reads it.
#include "fuzz_support.hpp"
#include "sonarbench/io/yaml_reader.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonarbench;
  return fuzz::KeepsTheContract([&] {
    YamlReader root = YamlReader::FromString(std::string(fuzz::AsText(data, size)), "model.yaml");
    (void)sim::ReadSensorModel(root);
    root.ThrowIfErrors();
  });
}
