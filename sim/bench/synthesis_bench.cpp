// Google Benchmark of beam synthesis against raw Embree (issue 3's speed goals), one sweep of the
// default tank scenario:
//   BM_RawEmbree        the same number of rays, in the same stratified pattern, intersected only
//   BM_Synthesis/1, /2  the whole synthesis (hits, backscatter, the scene's multipath: mirrored and
//                       occlusion rays, range spreading, noise, quantisation) on 1 and 2 threads
// Counters: primary rays per second (compare BM_Synthesis/1 with BM_RawEmbree) and, for the
// synthesis, the real-time factor: the real sonar's time for the sweep over ours.
#include <benchmark/benchmark.h>

#include <numbers>

#include "sonarbench/sim/beam_synthesizer.hpp"
#include "sonarbench/sim/mesh.hpp"
#include "sonarbench/sim/random.hpp"
#include "sonarbench/sim/simulation.hpp"

namespace sonarbench::sim {
namespace {

struct Tank {
  Scene scene = [] {
    Scene s = LoadScene(SONARBENCH_SOURCE_DIR "/scenes/cras-tank.yaml");
    s.sweeps = 1;
    return s;
  }();
  std::vector<TriangleMesh> meshes = BuildSceneMeshes(scene);
  RayTracer tracer{meshes};
};

Tank& TheTank() {
  static Tank tank;
  return tank;
}

double PrimaryRaysPerSweep(const Scene& scene) {
  const Acoustics& a = scene.sensor.acoustics;
  return static_cast<double>(a.rays_horizontal) * a.rays_vertical *
         scene.sensor.geometry.BeamsPerSweep();
}

void BM_RawEmbree(benchmark::State& state) {
  Tank& tank = TheTank();
  const auto& g = tank.scene.sensor.geometry;
  const Acoustics& a = tank.scene.sensor.acoustics;
  const auto max_range = static_cast<float>(g.MaxRangeM());
  for (auto _ : state) {
    std::size_t hits = 0;
    for (int b = 0; b < g.BeamsPerSweep(); ++b) {
      const ScheduledBeam s = ScheduleBeam(tank.scene, static_cast<std::size_t>(b));
      const Eigen::Matrix3d R =
          s.pose.T_world_sonar.linear() *
          Eigen::AngleAxisd(s.pose.head_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      const Eigen::Vector3f origin = s.pose.T_world_sonar.translation().cast<float>();
      Rng rng(DeriveSeed(1, static_cast<std::uint64_t>(b)));
      for (int i = 0; i < a.rays_horizontal; ++i) {
        for (int j = 0; j < a.rays_vertical; ++j) {
          const double theta =
              ((i + rng.Uniform()) / a.rays_horizontal - 0.5) * g.beam_width_horizontal_rad;
          const double epsilon =
              ((j + rng.Uniform()) / a.rays_vertical - 0.5) * g.beam_width_vertical_rad;
          const Eigen::Vector3f d = (R * mapping::SonarRayDirection(theta, epsilon)).cast<float>();
          hits += tank.tracer.Intersect(origin, d, max_range).has_value() ? 1 : 0;
        }
      }
    }
    benchmark::DoNotOptimize(hits);
  }
  state.counters["rays/s"] = benchmark::Counter(
      PrimaryRaysPerSweep(tank.scene) * state.iterations(), benchmark::Counter::kIsRate);
}

void BM_Synthesis(benchmark::State& state) {
  Tank& tank = TheTank();
  const auto threads = static_cast<int>(state.range(0));
  double traced = 0.0;
  for (auto _ : state) {
    auto beams = SimulateScene(tank.scene, tank.tracer, 1, threads);
    for (const SynthesizedBeam& beam : beams) traced += static_cast<double>(beam.traced_rays);
    benchmark::DoNotOptimize(beams);
  }
  const auto& g = tank.scene.sensor.geometry;
  state.counters["rays/s"] = benchmark::Counter(
      PrimaryRaysPerSweep(tank.scene) * state.iterations(), benchmark::Counter::kIsRate);
  // Every ray traced (mirrored and occlusion rays too), per second and per primary ray.
  state.counters["traced_rays/s"] = benchmark::Counter(traced, benchmark::Counter::kIsRate);
  state.counters["traced_per_primary"] =
      traced / (PrimaryRaysPerSweep(tank.scene) * static_cast<double>(state.iterations()));
  // Real time of a sweep over the (wall-clock) time per sweep: the counter is a rate of sweeps,
  // scaled by the sonar's seconds per sweep.
  state.counters["real_time_factor"] = benchmark::Counter(
      g.BeamsPerSweep() / g.beams_per_second * state.iterations(), benchmark::Counter::kIsRate);
}

// The same without multipath: one ray per primary, the raw benchmark's rays exactly.
void BM_SynthesisNoMultipath(benchmark::State& state) {
  Tank& tank = TheTank();
  Scene scene = tank.scene;
  for (Material& m : scene.materials) m.specular = 0.0;
  for (auto _ : state) {
    auto beams = SimulateScene(scene, tank.tracer, 1, 1);
    benchmark::DoNotOptimize(beams);
  }
  state.counters["rays/s"] = benchmark::Counter(PrimaryRaysPerSweep(scene) * state.iterations(),
                                                benchmark::Counter::kIsRate);
}

BENCHMARK(BM_RawEmbree)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SynthesisNoMultipath)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Synthesis)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace sonarbench::sim

BENCHMARK_MAIN();
