#pragma once

#include <octomap/OcTree.h>

#include <memory>
#include <span>
#include <string>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::mapping {

/// Per-batch counts, for reports and benchmarks.
struct BatchStats {
  std::size_t beams = 0;
  std::size_t beams_with_obstacle = 0;
  std::size_t ray_casts = 0;
  std::size_t free_cells = 0;
  std::size_t occupied_cells = 0;
};

/// The production mapper: detection, beam-volume ray casting and OctoMap log-odds updates.
/// Threading: Integrate() casts the rays of a batch on `config.threads` threads, each into its
/// own key sets, merged afterwards; the resulting map is identical for any thread count. A Mapper
/// is not safe to call from several threads at once.
class Mapper {
 public:
  Mapper(const MapperConfig& config, const SensorGeometry& sensor);

  /// Integrates a batch of beams (usually one sweep) as one update: each cell is updated at most
  /// once per batch, occupied winning over free.
  BatchStats Integrate(std::span<const Beam> beams);

  [[nodiscard]] const octomap::OcTree& tree() const { return *tree_; }
  [[nodiscard]] const MapperConfig& config() const { return config_; }

  /// Writes the map as an OctoMap binary `.bt` file (maximum-likelihood occupancy), atomically.
  void WriteBinary(const std::string& path) const;

 private:
  MapperConfig config_;
  SensorGeometry sensor_;
  std::vector<Eigen::Vector3d> directions_;
  std::unique_ptr<octomap::OcTree> tree_;
};

}  // namespace sonarbench::mapping
