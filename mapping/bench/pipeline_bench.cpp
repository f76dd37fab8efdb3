// The seed paper's Table 1, measured here: a real MSIS log through the whole mapper (detection,
// 32 × 64 ray casts per beam, key sets, OctoMap updates) with each key set, side by side in one
// run, against a naive OctoMap pipeline. Prints a table with each variant's median time over
// --repeats runs and its speed-up against the naive pipeline and against std::unordered_set.
//
//   pipeline_bench [LOG.mat] [--repeats N] [--resolution M]
//
// Every mapper variant must produce the same map, byte for byte (checked; a mismatch is an
// error). The naive pipeline is: one thread, per beam OctoMap's computeRayKeys into its KeySet,
// then updateNode per key: a cell seen by k beams of a sweep is updated k times, so its map
// differs.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "bench_sets.hpp"
#include "sonarbench/mapping/detection.hpp"
#include "sonarbench/mapping/integrate.hpp"
#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/mapping/mat_log.hpp"

namespace sonarbench::mapping::bench {
namespace {

struct Variant {
  std::string name;
  int threads;
  std::function<std::string()> run;  // returns the map's bytes
};

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

std::string Bytes(const octomap::OcTree& tree) {
  std::ostringstream out;
  tree.writeBinaryConst(out);
  return out.str();
}

MapTree MakeTree(const MapperConfig& config) {
  MapTree tree(config.resolution_m);
  tree.setProbHit(config.prob_hit);
  tree.setProbMiss(config.prob_miss);
  tree.setClampingThresMin(config.clamp_min);
  tree.setClampingThresMax(config.clamp_max);
  return tree;
}

// The production pipeline with key set `Set` on `threads` threads, sweep by sweep.
template <typename Set>
std::string RunMapper(const std::vector<Beam>& beams, const SensorGeometry& sensor,
                      const MapperConfig& config, int threads, BatchStats* totals) {
  MapTree tree = MakeTree(config);
  const auto directions = BeamRayDirections(sensor, config.rays_horizontal, config.rays_vertical);
  const auto per_sweep = static_cast<std::size_t>(sensor.BeamsPerSweep());
  const std::span<const Beam> all(beams);
  BatchWorkspace<Set> workspace;
  for (std::size_t first = 0; first < all.size(); first += per_sweep) {
    const auto sweep = all.subspan(first, std::min(per_sweep, all.size() - first));
    const auto obstacles = DetectObstacles(sweep, sensor, config.detection);
    const BatchStats stats =
        IntegrateBatch(tree, sweep, obstacles, directions, sensor.MaxRangeM(), threads, workspace);
    if (totals != nullptr) *totals += stats;
  }
  FinishUpdates(tree);
  return Bytes(tree);
}

std::string RunNaive(const std::vector<Beam>& beams, const SensorGeometry& sensor,
                     const MapperConfig& config) {
  MapTree tree = MakeTree(config);
  const auto directions = BeamRayDirections(sensor, config.rays_horizontal, config.rays_vertical);
  octomap::KeyRay ray;
  for (const Beam& beam : beams) {
    const std::vector<double> obstacles = DetectThreshold(beam, sensor, config.detection);
    const double free_end = obstacles.empty() ? sensor.MaxRangeM() : obstacles.front();
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(beam.head_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    KeySet free_cells;
    KeySet occupied_cells;
    for (const Eigen::Vector3d& d : directions) {
      const Eigen::Vector3d end = free_end * (R * d);
      if (tree.computeRayKeys(
              octomap::point3d(0, 0, 0),
              octomap::point3d(static_cast<float>(end.x()), static_cast<float>(end.y()),
                               static_cast<float>(end.z())),
              ray)) {
        free_cells.insert(ray.begin(), ray.end());
      }
      for (const double r : obstacles) {
        const Eigen::Vector3d p = r * (R * d);
        octomap::OcTreeKey key;
        if (tree.coordToKeyChecked(p.x(), p.y(), p.z(), key)) occupied_cells.insert(key);
      }
    }
    for (const auto& key : occupied_cells) free_cells.erase(key);
    for (const auto& key : free_cells) tree.updateNode(key, false);
    for (const auto& key : occupied_cells) tree.updateNode(key, true);
  }
  return Bytes(tree);
}

int Main(int argc, char** argv) {
  std::string path = SONARBENCH_REAL_LOG;
  int repeats = 3;
  MapperConfig config;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--repeats") == 0 && i + 1 < argc) {
      repeats = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--resolution") == 0 && i + 1 < argc) {
      config.resolution_m = std::atof(argv[++i]);
    } else if (argv[i][0] != '-') {
      path = argv[i];
    } else {
      std::fprintf(stderr, "usage: pipeline_bench [LOG.mat] [--repeats N] [--resolution M]\n");
      return 2;
    }
  }
  const MatLog log = ReadMatLog(path);
  const SensorGeometry sensor;
  const int cores = omp_get_max_threads();
  std::printf("log %s: %zu beams; resolution %.3f m; %d x %d rays per beam; %d cores\n",
              path.c_str(), log.beams.size(), config.resolution_m, config.rays_horizontal,
              config.rays_vertical, cores);

  BatchStats totals;
  const std::vector<Variant> variants = {
      {"naive OctoMap (computeRayKeys + KeySet + updateNode per beam)", 1,
       [&] { return RunNaive(log.beams, sensor, config); }},
      {"mapper, std::unordered_set (OctoMap KeySet)", cores,
       [&] { return RunMapper<KeySet>(log.beams, sensor, config, cores, nullptr); }},
      {"mapper, abseil flat_hash_set", cores,
       [&] { return RunMapper<AbslKeySet>(log.beams, sensor, config, cores, nullptr); }},
      {"mapper, OpenKeySet quadratic, all-at-once resize", cores,
       [&] { return RunMapper<QuadraticAllAtOnce>(log.beams, sensor, config, cores, nullptr); }},
      {"mapper, OpenKeySet quadratic, in-place resize", cores,
       [&] { return RunMapper<Quadratic>(log.beams, sensor, config, cores, &totals); }},
      {"mapper, OpenKeySet quadratic, in-place, 1 thread", 1,
       [&] { return RunMapper<Quadratic>(log.beams, sensor, config, 1, nullptr); }},
  };
  std::vector<double> times;
  std::string reference;
  for (std::size_t v = 0; v < variants.size(); ++v) {
    std::vector<double> runs;
    std::string bytes;
    for (int r = 0; r < repeats; ++r) {
      if (v == 4 && r > 0) totals = BatchStats{};
      const auto start = std::chrono::steady_clock::now();
      bytes = variants[v].run();
      runs.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    if (v == 1) reference = bytes;
    if (v > 1 && bytes != reference) {
      std::fprintf(stderr, "error: '%s' built a different map than std::unordered_set\n",
                   variants[v].name.c_str());
      return 1;
    }
    times.push_back(Median(runs));
  }
  std::printf("\n%-62s %7s %9s %9s %9s\n", "variant", "threads", "median s", "vs naive", "vs std");
  for (std::size_t v = 0; v < variants.size(); ++v) {
    std::printf("%-62s %7d %9.2f %8.2fx %8.2fx\n", variants[v].name.c_str(), variants[v].threads,
                times[v], times[0] / times[v], times[1] / times[v]);
  }
  const double updated = static_cast<double>(totals.free_cells + totals.occupied_cells);
  std::printf(
      "\nall mapper variants built the identical map\n"
      "cell visits %zu, cells updated (per sweep, summed) %.0f: %.1f visits per updated cell\n",
      totals.cell_visits, updated, static_cast<double>(totals.cell_visits) / updated);
  std::printf(
      "distinct free cells per beam, summed: %zu (%.1f visits each)\n", totals.beam_free_cells,
      static_cast<double>(totals.cell_visits) / static_cast<double>(totals.beam_free_cells));
  std::printf("stages of '%s' (last run): cast %.2f s, split %.2f s, update %.2f s\n",
              variants[4].name.c_str(), totals.cast_s, totals.split_s, totals.update_s);
  return 0;
}

}  // namespace
}  // namespace sonarbench::mapping::bench

int main(int argc, char** argv) { return sonarbench::mapping::bench::Main(argc, argv); }
