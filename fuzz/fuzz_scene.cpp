// A scene YAML file, loaded as `sonarbench run` loads it: `extends` of the shipped scenes, its
// sensor model, mesh files and every section, then its meshes built under a budget the fuzzer's
// memory limit allows (the budgets are checked before anything is built).
#include "fuzz_support.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace {

// The scratch folder as the repository lays scenes out: scenes/*.yaml (the shipped ones, which a
// fuzzed scene may extend), scenes/meshes/ and sensor-models/.
std::filesystem::path SceneFolder() {
  namespace fs = std::filesystem;
  static const fs::path scenes = [] {
    const fs::path source(SONARBENCH_SOURCE_DIR);
    const fs::path root = sonarbench::fuzz::ScratchDir();
    fs::copy(source / "scenes", root / "scenes", fs::copy_options::recursive);
    fs::copy(source / "sensor-models", root / "sensor-models", fs::copy_options::recursive);
    return root / "scenes";
  }();
  return scenes;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonarbench;
  const auto path = SceneFolder() / "fuzzed.yaml";
  fuzz::WriteBytes(path, fuzz::AsText(data, size));
  return fuzz::KeepsTheContract([&] {
    sim::Budgets budgets;
    budgets.max_triangles = 5e3;
    budgets.max_cells = 1e6;
    budgets.max_beams = 1e4;
    sim::Scene scene = sim::LoadScene(path.string(), budgets);
    (void)sim::BuildSceneMeshes(scene);
    (void)sim::BuildVehicleMeshes(scene);
  });
}
