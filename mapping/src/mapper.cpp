#include "sonarbench/mapping/mapper.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <variant>

#include "beam_volume.hpp"
#include "block_set.hpp"
#include "integrate.hpp"
#include "key_set.hpp"
#include "map_tree.hpp"
#include "sonarbench/mapping/detection.hpp"

namespace sonarbench::mapping {

struct Mapper::State {
  double free_range_m = 0.0;
  int threads = 1;
  ArcEvidence evidence;
  WaterKeys water;
  std::vector<Eigen::Vector3d> directions;
  MapTree tree;
  /// The key sets and buffers of the batches, kept between them: those of config.key_set.
  std::variant<BatchWorkspace<BlockKeySet>, BatchWorkspace<KeyOpenSet>, BatchWorkspace<KeySet>>
      workspace;
  /// Whether the tree's inner nodes lag its leaves (see FinishUpdates).
  bool stale = false;

  explicit State(double resolution_m) : tree(resolution_m) {}
};

namespace {

// `c`, once checked: throws std::invalid_argument naming the first field the mapper cannot take.
const MapperConfig& Checked(const MapperConfig& c) {
  const auto need = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("MapperConfig: expected ") + what);
  };
  need(std::isfinite(c.resolution_m) && c.resolution_m > 0.0, "resolution_m > 0");
  need(c.rays_horizontal >= 1 && c.rays_vertical >= 1, "rays_horizontal and rays_vertical >= 1");
  need(c.threads >= 0, "threads >= 0 (0: all cores)");
  need(std::isfinite(c.free_range_m) && c.free_range_m >= 0.0, "free_range_m >= 0");
  need(!std::isnan(c.water.floor_z_m) && !std::isnan(c.water.surface_z_m) &&
           c.water.floor_z_m < c.water.surface_z_m,
       "water.floor_z_m below water.surface_z_m");
  need(c.prob_hit >= 0.5 && c.prob_hit <= 1.0, "prob_hit in [0.5, 1]");
  need(c.prob_miss >= 0.0 && c.prob_miss <= 0.5, "prob_miss in [0, 0.5]");
  need(c.clamp_min >= 0.0 && c.clamp_min <= 0.5 && c.clamp_max >= 0.5 && c.clamp_max <= 1.0,
       "clamp_min in [0, 0.5] and clamp_max in [0.5, 1]");
  const DetectionConfig& d = c.detection;
  need(d.threshold >= 1 && d.threshold <= 255, "detection.threshold in 1..255");
  need(d.smoothing_bins >= 1 && d.smoothing_bins % 2 == 1, "detection.smoothing_bins odd, >= 1");
  need(d.min_run_bins >= 1, "detection.min_run_bins >= 1");
  need(d.max_obstacles >= 1, "detection.max_obstacles >= 1");
  need(d.cfar.guard_bins >= 0 && d.cfar.training_bins >= 1,
       "detection.cfar guard_bins >= 0 and training_bins >= 1");
  need(d.cfar.false_alarm > 0.0 && d.cfar.false_alarm < 1.0,
       "detection.cfar.false_alarm in (0, 1)");
  need(d.cfar.order > 0.0 && d.cfar.order <= 1.0, "detection.cfar.order in (0, 1]");
  need(d.cfar.db_per_count > 0.0 && d.cfar.db_per_count <= 1.0,
       "detection.cfar.db_per_count in (0, 1]");
  return c;
}

}  // namespace

Mapper::Mapper(const MapperConfig& config, const SensorGeometry& sensor)
    : config_(Checked(config)),
      sensor_(sensor),
      state_(std::make_unique<State>(config.resolution_m)) {
  state_->free_range_m = !config.clear_without_obstacle ? 0.0
                         : config.free_range_m > 0.0    ? config.free_range_m
                                                        : sensor.MaxRangeM();
  state_->threads = config.threads > 0 ? config.threads : omp_get_max_threads();
  state_->water = WaterKeysOf(config.water, config.resolution_m);
  if (config.occupancy == Occupancy::kArcEvidence) {
    // The two-way pattern's -3 dB points at the wedge's elevation limits (docs/physics.md).
    const double w = sensor.beam_width_vertical_rad;
    state_->evidence.pattern_k = 4.0 * std::log(2.0) / (w * w);
  }
  switch (config.key_set) {
    case KeySetKind::kBlocks:
      break;  // the variant's first
    case KeySetKind::kOpenAddressing:
      state_->workspace.emplace<BatchWorkspace<KeyOpenSet>>();
      break;
    case KeySetKind::kStd:
      state_->workspace.emplace<BatchWorkspace<KeySet>>();
      break;
  }
  state_->directions = BeamRayDirections(sensor, config.rays_horizontal, config.rays_vertical);
  MapTree& tree = state_->tree;
  tree.setProbHit(config.prob_hit);
  tree.setProbMiss(config.prob_miss);
  tree.setClampingThresMin(config.clamp_min);
  tree.setClampingThresMax(config.clamp_max);
}

Mapper::~Mapper() = default;
Mapper::Mapper(Mapper&&) noexcept = default;
Mapper& Mapper::operator=(Mapper&&) noexcept = default;

const octomap::OcTree& Mapper::tree() const {
  if (state_->stale) {
    FinishUpdates(state_->tree, state_->threads);
    state_->stale = false;
  }
  return state_->tree;
}

BatchStats Mapper::Integrate(std::span<const Beam> beams) {
  std::vector<bool> heard_through_walls;
  auto obstacles = DetectObstacles(beams, sensor_, config_.detection, &heard_through_walls);
  if (std::none_of(heard_through_walls.begin(), heard_through_walls.end(),
                   [](bool b) { return b; })) {
    return Integrate(beams, obstacles);
  }
  // A beam that heard only through a wall places nothing: neither its echoes nor, without one,
  // the water out to the free range (through the wall).
  std::vector<Beam> kept;
  std::vector<std::vector<double>> kept_obstacles;
  for (std::size_t b = 0; b < beams.size(); ++b) {
    if (heard_through_walls[b]) continue;
    kept.push_back(beams[b]);
    kept_obstacles.push_back(std::move(obstacles[b]));
  }
  return Integrate(kept, kept_obstacles);
}

BatchStats Mapper::IntegrateSweeps(
    std::span<const Beam> beams,
    const std::function<void(std::size_t done, std::size_t total)>& on_sweep) {
  const auto per_sweep = static_cast<std::size_t>(sensor_.BeamsPerSweep());
  const std::size_t sweeps = (beams.size() + per_sweep - 1) / per_sweep;
  BatchStats totals;
  for (std::size_t sweep = 0; sweep < sweeps; ++sweep) {
    const std::size_t first = sweep * per_sweep;
    totals += Integrate(beams.subspan(first, std::min(per_sweep, beams.size() - first)));
    if (on_sweep) on_sweep(sweep + 1, sweeps);
  }
  return totals;
}

BatchStats Mapper::Integrate(std::span<const Beam> beams,
                             std::span<const std::vector<double>> obstacles) {
  State& s = *state_;
  s.stale = true;
  auto integrate = [&](auto& workspace) {
    if (config_.integration == Integration::kExact) {
      return IntegrateExactBatch(s.tree, beams, obstacles, sensor_, s.free_range_m, s.threads,
                                 workspace, s.evidence, s.water);
    }
    return IntegrateBatch(s.tree, beams, obstacles, s.directions, s.free_range_m, s.threads,
                          workspace, s.evidence, s.water);
  };
  return std::visit(integrate, s.workspace);
}

void WriteOctomapBinary(const octomap::OcTree& tree, std::ostream& out) {
  WriteOctomapHeader(tree, tree.size(), false, out);
  tree.writeBinaryData(out);
}

// Both write what the tree would, from the leaves' log-odds: the tree need not be built.
void Mapper::WriteBinary(std::ostream& out) const { state_->tree.WriteBinaryFromLeaves(out); }

void Mapper::WriteFull(std::ostream& out) const { state_->tree.WriteFullFromLeaves(out); }

void Mapper::ForEachLeaf(
    const std::function<void(const octomap::OcTreeKey& key, bool occupied)>& f) const {
  const MapTree& tree = state_->tree;
  const float threshold = tree.getOccupancyThresLog();
  tree.ForEachLeaf(
      [&](const octomap::OcTreeKey& key, float log_odds) { f(key, log_odds >= threshold); });
}

}  // namespace sonarbench::mapping
