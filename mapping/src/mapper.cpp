#include "sonarbench/mapping/mapper.hpp"

#include <omp.h>

#include <algorithm>

#include "sonarbench/mapping/atomic_file.hpp"
#include "sonarbench/mapping/beam_volume.hpp"
#include "sonarbench/mapping/detection.hpp"
#include "sonarbench/mapping/error.hpp"

namespace sonarbench::mapping {

Mapper::Mapper(const MapperConfig& config, const SensorGeometry& sensor)
    : config_(config),
      sensor_(sensor),
      directions_(BeamRayDirections(sensor, config.rays_horizontal, config.rays_vertical)),
      tree_(std::make_unique<octomap::OcTree>(config.resolution_m)) {
  tree_->setProbHit(config.prob_hit);
  tree_->setProbMiss(config.prob_miss);
  tree_->setClampingThresMin(config.clamp_min);
  tree_->setClampingThresMax(config.clamp_max);
}

BatchStats Mapper::Integrate(std::span<const Beam> beams) {
  const int threads = config_.threads > 0 ? config_.threads : omp_get_max_threads();
  const double free_range_m =
      !config_.clear_without_obstacle
          ? 0.0
          : (config_.free_range_m > 0.0 ? config_.free_range_m : sensor_.MaxRangeM());
  std::vector<BeamCells> per_thread(static_cast<std::size_t>(threads));
  std::size_t with_obstacle = 0;
  const auto count = static_cast<std::int64_t>(beams.size());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 4) reduction(+ : with_obstacle)
  for (std::int64_t b = 0; b < count; ++b) {
    const Beam& beam = beams[static_cast<std::size_t>(b)];
    const std::vector<double> obstacles = DetectThreshold(beam, sensor_, config_.detection);
    with_obstacle += obstacles.empty() ? 0 : 1;
    CastBeam(*tree_, beam, directions_, obstacles, free_range_m,
             per_thread[static_cast<std::size_t>(omp_get_thread_num())]);
  }
  // Sets merge in thread order, but a set's content does not depend on order, and each key is
  // updated once below, so the map is the same for any thread count.
  BeamCells merged = std::move(per_thread.front());
  for (std::size_t t = 1; t < per_thread.size(); ++t) {
    merged.free.insert(per_thread[t].free.begin(), per_thread[t].free.end());
    merged.occupied.insert(per_thread[t].occupied.begin(), per_thread[t].occupied.end());
  }
  ResolveConflicts(merged);
  for (const auto& key : merged.free) tree_->updateNode(key, false, /*lazy_eval=*/true);
  for (const auto& key : merged.occupied) tree_->updateNode(key, true, /*lazy_eval=*/true);
  tree_->updateInnerOccupancy();

  BatchStats stats;
  stats.beams = beams.size();
  stats.beams_with_obstacle = with_obstacle;
  stats.ray_casts = beams.size() * directions_.size();
  stats.free_cells = merged.free.size();
  stats.occupied_cells = merged.occupied.size();
  return stats;
}

void Mapper::WriteBinary(const std::string& path) const {
  try {
    WriteFileAtomically(path, [&](std::ostream& out) {
      if (!tree_->writeBinaryConst(out)) throw std::runtime_error("OctoMap could not serialise");
    });
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": cannot write map: " + e.what());
  }
}

}  // namespace sonarbench::mapping
