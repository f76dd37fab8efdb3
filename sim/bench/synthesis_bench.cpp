// Google Benchmark of beam synthesis against raw Embree, one sweep of the
// default tank scenario (/tank: 14 triangles, 8 rough reflections per ray) and of the seabed
// survey (/seabed: an 11.5 k-triangle height field, no multipath), each row for both but
// BM_SynthesisNoMultipath (the tank's only: the seabed has none):
//   BM_RawEmbree        the synthesis's primary rays, generated beforehand, intersected only:
//                       one rtcIntersect1 per ray
//   BM_RawEmbreeBundle  the same, each beam's rays as one coherent stream (rtcIntersect1M), the
//                       query the synthesis makes
//   BM_SynthesisNoMultipath  the tank's synthesis with no material specular and no vehicle
//                       parts: one ray traced per primary, the raw rows' rays exactly (the
//                       goal's comparison)
//   BM_Synthesis/1, /2  the whole synthesis (hits, backscatter, the vehicle's parts, the scene's
//                       multipath: mirrored and occlusion rays, range spreading, noise,
//                       quantisation) on 1 and 2 threads
//   BM_RawEmbreeReplay  every ray BM_Synthesis/1 traces (its primaries, the vehicle's bundles,
//                       mirrored and occlusion rays), recorded from one sweep and replayed
//                       through Embree alone: /*_queries as the queries it made, /*_per_ray one
//                       query per ray (the whole synthesis's comparison: traced_rays/s)
//   BM_SynthesisLabels  one sweep on one thread without labels, with the bins' labels, and with
//                       the sweep's label file formed too
//   BM_SimulateDataset  `simulate` whole on one thread, every sweep of the scene (its own count):
//                       meshes, BVH, synthesis, the beam, truth, image and (/*_labels) label
//                       files, the truth occupancy, into a temporary directory replaced each time
// Per-run set-up is outside every timing but BM_SimulateDataset's, as a run does it once: the BVH
// (the raw rows' too) and the synthesizer's tables (SceneSynthesizer); everything done per beam is
// inside. Counters: primary rays per second (compare BM_SynthesisNoMultipath with the faster raw
// one), all rays traced per second (compare BM_Synthesis/1 with the replays) and, for the
// synthesis, the real-time factor: the real sonar's time for the sweep over ours.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sonarbench/io/labels.hpp"
#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/sonar/beam_synthesizer.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/random.hpp"

namespace sonarbench::sim {
namespace {

// A scene as the bench runs it: one sweep, its meshes' BVH, and the same scene without multipath
// (no material reflects specularly) and without its vehicle's parts: the primaries alone, traced
// against the scene's BVH, as the raw rows trace them.
struct BenchScene {
  explicit BenchScene(const std::string& file)
      : scene([&] {
          Scene s = LoadScene(std::string(SONARBENCH_SOURCE_DIR "/scenes/") + file);
          s.sweeps = 1;
          return s;
        }()),
        meshes(BuildSceneMeshes(scene)),
        tracer(meshes),
        no_multipath([this] {
          Scene s = scene;
          for (Material& m : s.materials) m.specular = 0.0;
          s.vehicle.clear();
          return s;
        }()) {}
  Scene scene;
  std::vector<TriangleMesh> meshes;
  RayTracer tracer;
  Scene no_multipath;
};

constexpr std::uint64_t kSeed = 1;

// One sweep of `scene`, as SimulateScene makes it, with a synthesizer built beforehand.
std::vector<SynthesizedBeam> SimulateSweep(const Scene& scene, const BeamSynthesizer& synthesizer,
                                           int threads) {
  return SimulateBeams(scene, synthesizer, kSeed, threads, 0, ScenarioBeamCount(scene));
}

// One sweep's primary rays, drawn as the synthesis draws them (BeamPattern::DrawRays: the
// same strata and jitter slots, from the benchmark's own seeds), generated once, outside any
// timing.
struct SweepRays {
  std::vector<Eigen::Vector3f> origins;                  // per beam
  std::vector<std::vector<Eigen::Vector3f>> directions;  // per beam, per ray
};

SweepRays DrawSweepRays(const BenchScene& bench) {
  const BeamSynthesizer synthesizer(bench.scene.sensor, bench.tracer,
                                    std::vector<Material>(bench.meshes.size()));
  SweepRays out;
  std::vector<double> patterns;
  for (int b = 0; b < bench.scene.sensor.geometry.BeamsPerSweep(); ++b) {
    const ScheduledBeam s = ScheduleBeam(bench.scene, static_cast<std::size_t>(b));
    const Eigen::Matrix3d R =
        s.pose.T_world_sonar.linear() *
        Eigen::AngleAxisd(s.pose.head_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    out.origins.push_back(s.pose.T_world_sonar.translation().cast<float>());
    Rng rng(DeriveSeed(kSeed, static_cast<std::uint64_t>(b)));
    synthesizer.pattern().DrawRays(R, rng, out.directions.emplace_back(), patterns);
  }
  return out;
}

// Every query the whole synthesis makes of Embree in one sweep (1 thread), recorded, with each
// bundle's directions apart, as IntersectBundle takes them: the scene's queries and the vehicle
// parts' (against their own BVH, kept here by the synthesizer that made them).
struct SweepQueries {
  struct Traced {
    RayQueryLog log;
    std::vector<std::vector<Eigen::Vector3f>> bundle_directions;  // per entry; empty if not one
  };
  BeamSynthesizer synthesizer;
  Traced scene;
  Traced vehicle;
  std::size_t rays = 0;
};

void SplitBundles(SweepQueries::Traced& traced) {
  for (const RayQueryLog::Entry& entry : traced.log.entries) {
    std::vector<Eigen::Vector3f>& directions = traced.bundle_directions.emplace_back();
    if (entry.query != RayQueryLog::Query::kBundle) continue;
    for (const Ray& ray : entry.rays) directions.push_back(ray.direction);
  }
}

std::unique_ptr<SweepQueries> RecordSweepQueries(const BenchScene& bench) {
  auto out = std::make_unique<SweepQueries>(
      SweepQueries{SceneSynthesizer(bench.scene, bench.tracer, kSeed), {}, {}, 0});
  const RayTracer* vehicle = out->synthesizer.VehicleTracer();
  bench.tracer.Record(&out->scene.log);
  if (vehicle != nullptr) vehicle->Record(&out->vehicle.log);
  (void)SimulateSweep(bench.scene, out->synthesizer, 1);
  bench.tracer.Record(nullptr);
  if (vehicle != nullptr) vehicle->Record(nullptr);
  SplitBundles(out->scene);
  SplitBundles(out->vehicle);
  out->rays = out->scene.log.RayCount() + out->vehicle.log.RayCount();
  return out;
}

// The scene, its sweep's primary rays and every query of its whole synthesis, built on first
// use and kept for every row.
struct Setup {
  BenchScene bench;
  SweepRays rays;
  std::unique_ptr<SweepQueries> queries;
};

const Setup& TheSetup(const std::string& file) {
  static std::map<std::string, std::unique_ptr<Setup>> setups;
  std::unique_ptr<Setup>& setup = setups[file];
  if (!setup) {
    setup = std::make_unique<Setup>(Setup{BenchScene(file), {}, {}});
    setup->rays = DrawSweepRays(setup->bench);
    setup->queries = RecordSweepQueries(setup->bench);
  }
  return *setup;
}

double PrimaryRaysPerSweep(const Scene& scene) {
  return static_cast<double>(PrimaryRays(scene.sensor.acoustics)) *
         scene.sensor.geometry.BeamsPerSweep();
}

// Raw Embree, one rtcIntersect1 per ray (RayTracer::Intersect), of the precomputed rays.
void BM_RawEmbree(benchmark::State& state, const std::string& file) {
  const Setup& setup = TheSetup(file);
  const SweepRays& rays = setup.rays;
  const auto max_range = static_cast<float>(setup.bench.scene.sensor.geometry.MaxRangeM());
  for (auto _ : state) {
    std::size_t hits = 0;
    for (std::size_t b = 0; b < rays.origins.size(); ++b) {
      for (const Eigen::Vector3f& d : rays.directions[b]) {
        hits += setup.bench.tracer.Intersect(rays.origins[b], d, max_range).has_value() ? 1 : 0;
      }
    }
    benchmark::DoNotOptimize(hits);
  }
  state.counters["rays/s"] = benchmark::Counter(
      PrimaryRaysPerSweep(setup.bench.scene) * state.iterations(), benchmark::Counter::kIsRate);
}

// Raw Embree, each beam's rays as one coherent stream (RayTracer::IntersectBundle, the query
// the synthesis makes), of the precomputed rays.
void BM_RawEmbreeBundle(benchmark::State& state, const std::string& file) {
  const Setup& setup = TheSetup(file);
  const SweepRays& rays = setup.rays;
  const auto max_range = static_cast<float>(setup.bench.scene.sensor.geometry.MaxRangeM());
  std::vector<std::optional<Hit>> hits;
  for (auto _ : state) {
    std::size_t hit_count = 0;
    for (std::size_t b = 0; b < rays.origins.size(); ++b) {
      hits.resize(rays.directions[b].size());
      setup.bench.tracer.IntersectBundle(rays.origins[b], rays.directions[b], max_range, hits);
      for (const auto& hit : hits) hit_count += hit.has_value() ? 1 : 0;
    }
    benchmark::DoNotOptimize(hit_count);
  }
  state.counters["rays/s"] = benchmark::Counter(
      PrimaryRaysPerSweep(setup.bench.scene) * state.iterations(), benchmark::Counter::kIsRate);
}

// Replays `traced` through `tracer`: each entry as the query it was (a coherent bundle, an
// incoherent stream, an occlusion stream or one ray), or with `per_ray` each of its rays as a
// query of its own (rtcIntersect1 or rtcOccluded1). Returns the hits and occluded rays found.
std::size_t Replay(const RayTracer& tracer, const SweepQueries::Traced& traced, bool per_ray) {
  using Query = RayQueryLog::Query;
  thread_local std::vector<std::optional<Hit>> hits;
  thread_local std::vector<bool> occluded;
  std::size_t found = 0;
  for (std::size_t e = 0; e < traced.log.entries.size(); ++e) {
    const RayQueryLog::Entry& entry = traced.log.entries[e];
    const bool occlusion =
        entry.query == Query::kOccludedStream || entry.query == Query::kSingleOccluded;
    if (per_ray || entry.query == Query::kSingle || entry.query == Query::kSingleOccluded) {
      for (const Ray& ray : entry.rays) {
        found += occlusion
                     ? (tracer.Occluded(ray.origin, ray.direction, ray.max_distance) ? 1 : 0)
                     : (tracer.Intersect(ray.origin, ray.direction, ray.max_distance) ? 1 : 0);
      }
      continue;
    }
    if (occlusion) {
      tracer.OccludedStream(entry.rays, occluded);
      for (const bool o : occluded) found += o ? 1 : 0;
      continue;
    }
    hits.resize(entry.rays.size());
    if (entry.query == Query::kBundle) {
      tracer.IntersectBundle(entry.rays.front().origin, traced.bundle_directions[e],
                             entry.rays.front().max_distance, hits);
    } else {
      tracer.IntersectStream(entry.rays, hits);
    }
    for (const auto& hit : hits) found += hit.has_value() ? 1 : 0;
  }
  return found;
}

// Raw Embree on every ray the whole synthesis traces in a sweep (BM_Synthesis/1's: primaries,
// the vehicle's bundles, mirrored rays, occlusion rays, the beam's axis), recorded from it and
// replayed: as the queries it made (`per_ray` false) or one query per ray.
void BM_RawEmbreeReplay(benchmark::State& state, const std::string& file, bool per_ray) {
  const Setup& setup = TheSetup(file);
  const SweepQueries& queries = *setup.queries;
  const RayTracer* vehicle = queries.synthesizer.VehicleTracer();
  for (auto _ : state) {
    std::size_t found = Replay(setup.bench.tracer, queries.scene, per_ray);
    if (vehicle != nullptr) found += Replay(*vehicle, queries.vehicle, per_ray);
    benchmark::DoNotOptimize(found);
  }
  state.counters["traced_rays/s"] = benchmark::Counter(
      static_cast<double>(queries.rays) * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
}

void BM_Synthesis(benchmark::State& state, const std::string& file) {
  const BenchScene& bench = TheSetup(file).bench;
  const auto threads = static_cast<int>(state.range(0));
  const BeamSynthesizer synthesizer = SceneSynthesizer(bench.scene, bench.tracer, kSeed);
  double traced = 0.0;
  for (auto _ : state) {
    auto beams = SimulateSweep(bench.scene, synthesizer, threads);
    for (const SynthesizedBeam& beam : beams) traced += static_cast<double>(beam.traced_rays);
    benchmark::DoNotOptimize(beams);
  }
  const auto& g = bench.scene.sensor.geometry;
  state.counters["rays/s"] = benchmark::Counter(
      PrimaryRaysPerSweep(bench.scene) * state.iterations(), benchmark::Counter::kIsRate);
  // Every ray traced (mirrored and occlusion rays too), per second and per primary ray.
  state.counters["traced_rays/s"] = benchmark::Counter(traced, benchmark::Counter::kIsRate);
  state.counters["traced_per_primary"] =
      traced / (PrimaryRaysPerSweep(bench.scene) * static_cast<double>(state.iterations()));
  // Real time of a sweep over the (wall-clock) time per sweep: the counter is a rate of sweeps,
  // scaled by the sonar's seconds per sweep.
  state.counters["real_time_factor"] = benchmark::Counter(
      g.BeamsPerSweep() / g.beams_per_second * state.iterations(), benchmark::Counter::kIsRate);
}

// What the labels of a dataset cost: none, the bins' labels, or those and the sweep's label file
// formed as `simulate` writes it (each bin's shares, the zstd frame; not the disk).
enum class Labelled { kNone, kBins, kFile };

// The same on one thread, labelled as asked: the labels' cost is the ratio to kNone. Each sweep
// into the last one's memory, as `simulate` writes a dataset.
void BM_SynthesisLabels(benchmark::State& state, const std::string& file, Labelled labelled) {
  const BenchScene& bench = TheSetup(file).bench;
  const BeamSynthesizer synthesizer = SceneSynthesizer(bench.scene, bench.tracer, kSeed);
  std::vector<SynthesizedBeam> beams;
  std::vector<io::BeamLabels> labels;
  for (auto _ : state) {
    SimulateBeamsInto(bench.scene, synthesizer, kSeed, 1, 0, ScenarioBeamCount(bench.scene),
                      labelled == Labelled::kNone ? Labels::kDrop : Labels::kKeep, beams);
    benchmark::DoNotOptimize(beams.data());
    if (labelled == Labelled::kFile) {
      LabelFileBeams(beams, 1, labels);
      const std::string frame = io::EncodeLabelFile(labels);
      benchmark::DoNotOptimize(frame.data());
    }
  }
  state.counters["rays/s"] = benchmark::Counter(
      PrimaryRaysPerSweep(bench.scene) * state.iterations(), benchmark::Counter::kIsRate);
}

// `simulate` as a user runs it, with and without the label files: their whole cost is the ratio.
void BM_SimulateDataset(benchmark::State& state, const std::string& file, bool labels) {
  const Scene scene = LoadScene(std::string(SONARBENCH_SOURCE_DIR "/scenes/") + file);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("sonarbench-bench-" + std::to_string(::getpid()));
  DatasetOptions options;
  options.threads = 1;
  options.force = true;
  options.labels = labels;
  for (auto _ : state) {
    const DatasetSummary summary = SimulateDataset(scene, dir.string(), options);
    benchmark::DoNotOptimize(summary.sweeps_written);
  }
  std::filesystem::remove_all(dir);
  state.counters["sweeps"] = static_cast<double>(scene.sweeps);
}

// The same without multipath: one ray per primary, the raw benchmark's rays exactly.
void BM_SynthesisNoMultipath(benchmark::State& state, const std::string& file) {
  const BenchScene& bench = TheSetup(file).bench;
  const BeamSynthesizer synthesizer = SceneSynthesizer(bench.no_multipath, bench.tracer, kSeed);
  for (auto _ : state) {
    auto beams = SimulateSweep(bench.no_multipath, synthesizer, 1);
    benchmark::DoNotOptimize(beams);
  }
  state.counters["rays/s"] = benchmark::Counter(
      PrimaryRaysPerSweep(bench.no_multipath) * state.iterations(), benchmark::Counter::kIsRate);
}

// The tank: 14 triangles, 8 rough reflections per ray, the horizontal pattern's sidelobes (40 more
// primary rays per beam, to ±22°), the default scenario.
const std::string kTank = "cras-tank.yaml";
// The seabed survey: a 30 m × 12 m height field at 25 cm (11.5 k triangles), no multipath.
const std::string kSeabed = "seabed.yaml";

BENCHMARK_CAPTURE(BM_RawEmbree, tank, kTank)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RawEmbreeBundle, tank, kTank)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_SynthesisNoMultipath, tank, kTank)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_RawEmbreeReplay, tank_queries, kTank, false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_RawEmbreeReplay, tank_per_ray, kTank, true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Synthesis, tank, kTank)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SynthesisLabels, tank_unlabelled, kTank, Labelled::kNone)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SynthesisLabels, tank_labelled, kTank, Labelled::kBins)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SynthesisLabels, tank_labelled_file, kTank, Labelled::kFile)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SimulateDataset, tank_labels, kTank, true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SimulateDataset, tank_no_labels, kTank, false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_RawEmbree, seabed, kSeabed)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RawEmbreeBundle, seabed, kSeabed)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_RawEmbreeReplay, seabed_queries, kSeabed, false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Synthesis, seabed, kSeabed)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SynthesisLabels, seabed_unlabelled, kSeabed, Labelled::kNone)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SynthesisLabels, seabed_labelled, kSeabed, Labelled::kBins)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SynthesisLabels, seabed_labelled_file, kSeabed, Labelled::kFile)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SimulateDataset, seabed_labels, kSeabed, true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SimulateDataset, seabed_no_labels, kSeabed, false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace sonarbench::sim

BENCHMARK_MAIN();
