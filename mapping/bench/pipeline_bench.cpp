// The seed paper's Table 1, measured here: a real MSIS log through the whole mapper (detection,
// 32 × 64 ray casts per beam, key sets, OctoMap updates) with each key set, and in exact mode
// (each beam's wedge) with two, side by side in one run, against a naive OctoMap pipeline. Prints a
// table with each variant's median time over
// --repeats runs and its speed-up against the naive pipeline and against std::unordered_set.
//
//   pipeline_bench [LOG.mat] [--repeats N] [--resolution M] [--sets-only] [--exact-only]
//
// Every mapper variant must produce the same map, leaf for leaf (checked; a mismatch is an
// error). The naive pipeline is: one thread, per beam OctoMap's computeRayKeys into its KeySet,
// then updateNode per key: a cell seen by k beams of a sweep is updated k times, so its map
// differs.
//
// A second table isolates the key sets' share: every insert and iteration the mapper's threads
// made into their sets, recorded from a mapper run and replayed alone into each set type (the
// sets' work within the mapper, without the ray casting around it).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "bench_sets.hpp"
#include "block_set.hpp"
#include "integrate.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/mapping/detection.hpp"
#include "sonarbench/mapping/mapper.hpp"

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

// The map's leaves, each as its key, depth and log-odds bytes, in tree order: equal exactly
// when the maps are (OctoMap's own writeBinary would do, but prints to stderr on Debian's build).
std::string Bytes(const octomap::OcTree& tree) {
  std::string bytes;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    const octomap::OcTreeKey key = it.getKey();
    const unsigned depth = it.getDepth();
    const float log_odds = it->getLogOdds();
    bytes.append(reinterpret_cast<const char*>(&key[0]), 3 * sizeof(key[0]));
    bytes.append(reinterpret_cast<const char*>(&depth), sizeof(depth));
    bytes.append(reinterpret_cast<const char*>(&log_odds), sizeof(log_odds));
  }
  return bytes;
}

MapTree MakeTree(const MapperConfig& config) {
  MapTree tree(config.resolution_m);
  tree.setProbHit(config.prob_hit);
  tree.setProbMiss(config.prob_miss);
  tree.setClampingThresMin(config.clamp_min);
  tree.setClampingThresMax(config.clamp_max);
  return tree;
}

// The production pipeline with key set `Set` on `threads` threads, sweep by sweep, its sets
// kept in `workspace`; the beams' cells from their ray casts or, with `integration: exact`,
// their wedges.
template <typename Set>
std::string RunMapper(const std::vector<Beam>& beams, const SensorGeometry& sensor,
                      const MapperConfig& config, int threads, BatchStats* totals,
                      BatchWorkspace<Set>& workspace) {
  if (totals != nullptr) *totals = BatchStats{};
  MapTree tree = MakeTree(config);
  const auto directions = BeamRayDirections(sensor, config.rays_horizontal, config.rays_vertical);
  const auto per_sweep = static_cast<std::size_t>(sensor.BeamsPerSweep());
  const std::span<const Beam> all(beams);
  for (std::size_t first = 0; first < all.size(); first += per_sweep) {
    const auto sweep = all.subspan(first, std::min(per_sweep, all.size() - first));
    const auto obstacles = DetectObstacles(sweep, sensor, config.detection);
    const BatchStats stats = config.integration == Integration::kExact
                                 ? IntegrateExactBatch(tree, sweep, obstacles, sensor,
                                                       sensor.MaxRangeM(), threads, workspace)
                                 : IntegrateBatch(tree, sweep, obstacles, directions,
                                                  sensor.MaxRangeM(), threads, workspace);
    if (totals != nullptr) *totals += stats;
  }
  FinishUpdates(tree, threads);
  return Bytes(tree);
}

// The production pipeline in exact mode (every cell of each beam's wedge once).
template <typename Set>
std::string RunExact(const std::vector<Beam>& beams, const SensorGeometry& sensor,
                     const MapperConfig& config, int threads, BatchStats* totals) {
  MapperConfig exact = config;
  exact.integration = Integration::kExact;
  BatchWorkspace<Set> workspace;
  return RunMapper(beams, sensor, exact, threads, totals, workspace);
}

template <typename Set>
std::string RunMapper(const std::vector<Beam>& beams, const SensorGeometry& sensor,
                      const MapperConfig& config, int threads, BatchStats* totals) {
  BatchWorkspace<Set> workspace;
  return RunMapper(beams, sensor, config, threads, totals, workspace);
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

// A KeyOpenSet that logs every key it is given, batch by batch (a clear() starts a batch): the
// key sets' share of the mapper's work, recorded to be replayed into other sets.
class RecordingSet {
 public:
  void insert_packed(std::span<const std::uint64_t> keys) {
    log.back().insert(log.back().end(), keys.begin(), keys.end());
    set_.insert_packed(keys);
  }
  bool insert(const octomap::OcTreeKey& key) {
    log.back().push_back(PackKey(key));
    return set_.insert(key);
  }
  void clear() {
    set_.clear();
    log.emplace_back();
  }
  void reserve(std::size_t n) { set_.reserve(n); }
  [[nodiscard]] std::size_t size() const { return set_.size(); }
  [[nodiscard]] auto begin() const { return set_.begin(); }
  [[nodiscard]] auto end() const { return set_.end(); }
  template <typename F>
  void for_each_packed(F&& f) const {
    set_.for_each_packed(f);
  }

  std::vector<std::vector<std::uint64_t>> log{1};

 private:
  KeyOpenSet set_;
};

// Per thread of a mapper run, the keys its free and its occupied set were given, per sweep.
struct SetStreams {
  std::vector<std::vector<std::uint64_t>> free;
  std::vector<std::vector<std::uint64_t>> occupied;
};

std::vector<SetStreams> RecordSetStreams(const std::vector<Beam>& beams,
                                         const SensorGeometry& sensor, const MapperConfig& config,
                                         int threads) {
  BatchWorkspace<RecordingSet> workspace;
  (void)RunMapper(beams, sensor, config, threads, nullptr, workspace);
  std::vector<SetStreams> streams;
  for (auto& cells : workspace.per_thread) {
    streams.push_back({std::move(cells.free.log), std::move(cells.occupied.log)});
  }
  return streams;
}

// Replays the recorded streams into sets of type `Set` as the mapper uses them: per sweep,
// empty the set keeping its room (BasicBeamCells::Clear), insert the sweep's keys, iterate them
// (the split into octants). Returns the wall time [s]; `checksum` keeps the work observable.
template <typename Set>
double ReplaySetStreams(const std::vector<SetStreams>& streams, std::uint64_t& checksum) {
  const auto start = std::chrono::steady_clock::now();
  for (const SetStreams& stream : streams) {
    for (const auto* batches : {&stream.free, &stream.occupied}) {
      Set set;
      for (const auto& keys : *batches) {
        const std::size_t held = set.size();
        set.clear();
        set.reserve(held);
        BasicBeamCells<Set>::Insert(set, keys);
        BasicBeamCells<Set>::ForEach(set,
                                     [&checksum](std::uint64_t packed) { checksum += packed; });
      }
    }
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The counts and stages of the last run of the ray row whose totals were kept (unless null) and
// of the exact row.
void PrintCounts(const BatchStats* rays, const std::string& rays_name, const BatchStats& exact,
                 const std::string& exact_name) {
  if (rays != nullptr) {
    const BatchStats& totals = *rays;
    const double updated = static_cast<double>(totals.free_cells + totals.occupied_cells);
    std::printf(
        "rays: cell visits %zu, cells updated (per sweep, summed) %.0f: %.1f visits per "
        "updated cell\n",
        totals.cell_visits, updated, static_cast<double>(totals.cell_visits) / updated);
    std::printf(
        "rays: distinct free cells per beam, summed: %zu (%.1f visits each)\n",
        totals.beam_free_cells,
        static_cast<double>(totals.cell_visits) / static_cast<double>(totals.beam_free_cells));
    std::printf("stages of '%s' (last run): cast %.2f s, split %.2f s, update %.2f s\n",
                rays_name.c_str(), totals.cast_s, totals.split_s, totals.update_s);
  }
  const double exact_updated = static_cast<double>(exact.free_cells + exact.occupied_cells);
  std::printf(
      "exact: cells examined %zu (%zu decided by clipping), distinct free cells per beam, "
      "summed %zu, cells updated (per sweep, summed) %.0f\n",
      exact.cell_visits, exact.clipped_cells, exact.beam_free_cells, exact_updated);
  std::printf("stages of '%s' (last run): cast %.2f s, split %.2f s, update %.2f s\n",
              exact_name.c_str(), exact.cast_s, exact.split_s, exact.update_s);
}

// The variants' median times, as ratios to the naive pipeline (row 0) and, unless `exact_only`,
// to the std::unordered_set mapper (row 1).
void PrintTimes(const std::vector<Variant>& variants, const std::vector<double>& times,
                bool exact_only) {
  std::printf("\n%-62s %7s %9s %9s %9s\n", "variant", "threads", "median s", "vs naive",
              exact_only ? "" : "vs std");
  for (std::size_t v = 0; v < variants.size(); ++v) {
    std::printf("%-62s %7d %9.2f %8.2fx", variants[v].name.c_str(), variants[v].threads, times[v],
                times[0] / times[v]);
    if (exact_only) {
      std::printf("\n");
    } else {
      std::printf(" %8.2fx\n", times[1] / times[v]);
    }
  }
  std::printf("\nthe mapper variants of each mode built the identical map\n");
}

// The whole mapper with each key set, and in exact mode, against the naive pipeline (Table 1).
int PipelineTable(const io::MatLog& log, const SensorGeometry& sensor, const MapperConfig& config,
                  int cores, int repeats, bool exact_only) {
  BatchStats totals;
  BatchStats exact_totals;
  const std::vector<Variant> all_variants = {
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
      {"mapper, BlockKeySet (key_set: blocks)", cores,
       [&] { return RunMapper<BlockKeySet>(log.beams, sensor, config, cores, nullptr); }},
      {"mapper, exact wedge, BlockKeySet (the defaults)", cores,
       [&] { return RunExact<BlockKeySet>(log.beams, sensor, config, cores, &exact_totals); }},
      {"mapper, exact wedge, BlockKeySet, 1 thread", 1,
       [&] { return RunExact<BlockKeySet>(log.beams, sensor, config, 1, nullptr); }},
      {"mapper, exact wedge, OpenKeySet", cores,
       [&] { return RunExact<KeyOpenSet>(log.beams, sensor, config, cores, nullptr); }},
      {"mapper, exact wedge, OpenKeySet, 1 thread", 1,
       [&] { return RunExact<KeyOpenSet>(log.beams, sensor, config, 1, nullptr); }},
  };
  constexpr std::size_t kRays = 4;   // the ray row whose stages are printed
  constexpr std::size_t kExact = 7;  // the first exact row
  std::vector<Variant> variants = all_variants;
  if (exact_only) {
    variants = {all_variants[0]};
    variants.insert(variants.end(), all_variants.begin() + kExact, all_variants.end());
  }
  const std::size_t exact_row = exact_only ? 1 : kExact;
  std::vector<double> times;
  std::string ray_map, exact_map;
  for (std::size_t v = 0; v < variants.size(); ++v) {
    std::vector<double> runs;
    std::string bytes;
    for (int r = 0; r < repeats; ++r) {
      const auto start = std::chrono::steady_clock::now();
      bytes = variants[v].run();
      runs.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    times.push_back(Median(runs));
    if (v == 0) continue;
    std::string& reference = v >= exact_row ? exact_map : ray_map;
    if (reference.empty()) reference = bytes;
    if (bytes != reference) {
      std::fprintf(stderr, "error: '%s' built a different map than the first of its mode\n",
                   variants[v].name.c_str());
      return 1;
    }
  }
  PrintTimes(variants, times, exact_only);
  PrintCounts(exact_only ? nullptr : &totals, all_variants[kRays].name, exact_totals,
              all_variants[kExact].name);
  return 0;
}

// The key sets' work inside the mapper, replayed alone.
int SetTable(const io::MatLog& log, const SensorGeometry& sensor, const MapperConfig& config,
             int cores, int repeats) {
  const auto streams = RecordSetStreams(log.beams, sensor, config, cores);
  std::size_t inserts = 0;
  std::size_t batches = 0;
  for (const SetStreams& stream : streams) {
    for (const auto* part : {&stream.free, &stream.occupied}) {
      for (const auto& keys : *part) inserts += keys.size();
      batches += part->size();
    }
  }
  struct Replay {
    const char* name;
    double (*run)(const std::vector<SetStreams>&, std::uint64_t&);
  };
  const Replay replays[] = {
      {"std::unordered_set (OctoMap KeySet)", &ReplaySetStreams<KeySet>},
      {"abseil flat_hash_set", &ReplaySetStreams<AbslKeySet>},
      {"OpenKeySet quadratic, all-at-once resize", &ReplaySetStreams<QuadraticAllAtOnce>},
      {"OpenKeySet quadratic, in-place resize", &ReplaySetStreams<Quadratic>},
  };
  std::vector<double> replay_times;
  std::uint64_t reference_checksum = 0;
  for (std::size_t r = 0; r < std::size(replays); ++r) {
    std::vector<double> runs;
    for (int i = 0; i < repeats; ++i) {
      std::uint64_t checksum = 0;
      runs.push_back(replays[r].run(streams, checksum));
      if (r == 0 && i == 0) reference_checksum = checksum;
      if (checksum != reference_checksum) {
        std::fprintf(stderr, "error: '%s' replayed to different keys\n", replays[r].name);
        return 1;
      }
    }
    replay_times.push_back(Median(runs));
  }
  std::printf(
      "\nthe key sets' work inside the mapper, replayed alone: %zu inserts in %zu set-sweeps "
      "(every insert and iteration the mapper's %d threads made, 1 thread)\n%-62s %9s %9s %9s\n",
      inserts, batches, cores, "set", "median s", "vs std", "vs abseil");
  for (std::size_t r = 0; r < std::size(replays); ++r) {
    std::printf("%-62s %9.3f %8.2fx %8.2fx\n", replays[r].name, replay_times[r],
                replay_times[0] / replay_times[r], replay_times[1] / replay_times[r]);
  }
  return 0;
}

int Main(int argc, char** argv) {
  std::string path = SONARBENCH_REAL_LOG;
  int repeats = 3;
  bool sets_only = false;
  bool exact_only = false;
  MapperConfig config;
  config.integration = Integration::kRays;  // Table 1's rows; the exact ones set their own
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--repeats") == 0 && i + 1 < argc) {
      repeats = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--exact-only") == 0) {
      exact_only = true;
    } else if (std::strcmp(argv[i], "--sets-only") == 0) {
      sets_only = true;
    } else if (std::strcmp(argv[i], "--resolution") == 0 && i + 1 < argc) {
      config.resolution_m = std::atof(argv[++i]);
    } else if (argv[i][0] != '-') {
      path = argv[i];
    } else {
      std::fprintf(stderr,
                   "usage: pipeline_bench [LOG.mat] [--repeats N] [--resolution M] [--sets-only] "
                   "[--exact-only]\n");
      return 2;
    }
  }
  const io::MatLog log = io::ReadMatLog(path);
  const SensorGeometry sensor;
  const int cores = omp_get_max_threads();
  std::printf("log %s: %zu beams; resolution %.3f m; %d x %d rays per beam; %d cores\n",
              path.c_str(), log.beams.size(), config.resolution_m, config.rays_horizontal,
              config.rays_vertical, cores);

  if (!sets_only) {
    if (const int status = PipelineTable(log, sensor, config, cores, repeats, exact_only);
        status != 0) {
      return status;
    }
    if (exact_only) return 0;
  }
  return SetTable(log, sensor, config, cores, repeats);
}

}  // namespace
}  // namespace sonarbench::mapping::bench

int main(int argc, char** argv) { return sonarbench::mapping::bench::Main(argc, argv); }
