// The C++ side of python/bench/overhead.py: the calls the Python module makes to load a scene,
// simulate its run sweep by sweep (labels dropped) and map it, timed with a steady clock.
// Usage: python_overhead_baseline SCENE SEED THREADS [MAP.bt]; prints {"seconds": S} on stdout.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "sonarbench/io/octomap_file.hpp"
#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/sonar/scene_world.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace {

using namespace sonarbench;

double SimulateAndMap(const char* scene_path, std::uint64_t seed, int threads,
                      const char* map_path) {
  const auto start = std::chrono::steady_clock::now();
  const sim::Scene scene = sim::LoadScene(scene_path);
  const sim::SceneWorld world(scene);
  const sim::BeamSynthesizer synthesizer = sim::SceneSynthesizer(scene, world.tracer, seed);
  mapping::MapperConfig config = scene.mapping;
  config.threads = threads;
  mapping::Mapper mapper(config, scene.sensor.geometry);
  const std::size_t total = sim::ScenarioBeamCount(scene);
  const auto per_sweep = static_cast<std::size_t>(scene.sensor.geometry.BeamsPerSweep());
  std::vector<sim::SynthesizedBeam> synthesized;
  for (std::size_t first = 0; first < total; first += per_sweep) {
    sim::SimulateBeamsInto(scene, synthesizer, seed, threads, first,
                           std::min(total, first + per_sweep), sim::Labels::kDrop, synthesized);
    (void)mapper.Integrate(sim::BeamsOf(synthesized));
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (map_path != nullptr) io::WriteMapFile(mapper, map_path, io::MapFormat::kBinary);
  return seconds;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4 && argc != 5) {
    std::fprintf(stderr, "usage: python_overhead_baseline SCENE SEED THREADS [MAP.bt]\n");
    return 2;
  }
  try {
    const double seconds = SimulateAndMap(argv[1], std::stoull(argv[2]), std::stoi(argv[3]),
                                          argc == 5 ? argv[4] : nullptr);
    std::printf("{\"seconds\": %.6f}\n", seconds);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "python_overhead_baseline: %s\n", e.what());
    return 2;
  }
  return 0;
}
