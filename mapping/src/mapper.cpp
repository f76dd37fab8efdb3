#include "sonarbench/mapping/mapper.hpp"

#include <omp.h>

#include <algorithm>

#include "sonarbench/mapping/atomic_file.hpp"
#include "sonarbench/mapping/beam_volume.hpp"
#include "sonarbench/mapping/detection.hpp"
#include "sonarbench/mapping/key_set.hpp"

namespace sonarbench::mapping {

Mapper::Mapper(const MapperConfig& config, const SensorGeometry& sensor)
    : config_(config),
      sensor_(sensor),
      free_range_m_(!config.clear_without_obstacle ? 0.0
                    : config.free_range_m > 0.0    ? config.free_range_m
                                                   : sensor.MaxRangeM()),
      threads_(config.threads > 0 ? config.threads : omp_get_max_threads()),
      directions_(BeamRayDirections(sensor, config.rays_horizontal, config.rays_vertical)),
      tree_(std::make_unique<MapTree>(config.resolution_m)) {
  tree_->setProbHit(config.prob_hit);
  tree_->setProbMiss(config.prob_miss);
  tree_->setClampingThresMin(config.clamp_min);
  tree_->setClampingThresMax(config.clamp_max);
}

BatchStats Mapper::Integrate(std::span<const Beam> beams) {
  const auto obstacles = DetectObstacles(beams, sensor_, config_.detection);
  return Integrate(beams, obstacles);
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
  stale_ = true;
  if (config_.key_set == KeySetKind::kStd) {
    return IntegrateBatch(*tree_, beams, obstacles, directions_, free_range_m_, threads_,
                          std_workspace_);
  }
  return IntegrateBatch(*tree_, beams, obstacles, directions_, free_range_m_, threads_,
                        open_workspace_);
}

void WriteOctomapBinary(const octomap::OcTree& tree, std::ostream& out) {
  // AbstractOccupancyOcTree::writeBinaryConst's header, then the node data.
  out << "# Octomap OcTree binary file\n# (feel free to add / change comments, but leave the first "
         "line as it is!)\n#\n"
      << "id " << tree.getTreeType() << "\n"
      << "size " << tree.size() << "\n"
      << "res " << tree.getResolution() << "\n"
      << "data\n";
  tree.writeBinaryData(out);
}

void Mapper::WriteBinary(const std::string& path) const {
  // A failed write leaves `out` bad: WriteFileAtomically reports it with the OS's reason.
  WriteFileAtomically(path, [&](std::ostream& out) { WriteOctomapBinary(tree(), out); });
}

void Mapper::WriteFull(const std::string& path) const {
  WriteFileAtomically(path, [&](std::ostream& out) { (void)tree().write(out); });
}

}  // namespace sonarbench::mapping
