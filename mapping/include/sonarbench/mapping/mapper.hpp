#pragma once

#include <octomap/OcTree.h>

#include <functional>
#include <memory>
#include <ostream>
#include <span>
#include <string>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/integrate.hpp"
#include "sonarbench/mapping/key_set.hpp"
#include "sonarbench/mapping/map_tree.hpp"
#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::mapping {

/// Writes `tree` in OctoMap's binary `.bt` format: the bytes OcTree::writeBinaryConst writes,
/// without the " done." that Debian's liboctomap prints on stderr for each file.
void WriteOctomapBinary(const octomap::OcTree& tree, std::ostream& out);

/// The production mapper: detection, beam-volume ray casting and OctoMap log-odds updates.
/// Threading: Integrate() casts the rays of a batch on `config.threads` threads, each into its
/// own key sets, merged afterwards, and updates the root's octants in parallel; the resulting
/// map is identical for any thread count. A Mapper
/// is not safe to call from several threads at once.
class Mapper {
 public:
  Mapper(const MapperConfig& config, const SensorGeometry& sensor);

  /// Integrates a batch of beams (one sweep: Canny detection works on the sweep's image) as one
  /// update: each cell is updated at most once per batch, occupied winning over free.
  BatchStats Integrate(std::span<const Beam> beams);
  /// Integrates a run of beams sweep by sweep: batches of BeamsPerSweep() consecutive beams (the
  /// last may be partial), each as one Integrate(). Returns the summed counts. `on_sweep`, when
  /// set, is called after each sweep with the sweeps done and the total.
  BatchStats IntegrateSweeps(
      std::span<const Beam> beams,
      const std::function<void(std::size_t done, std::size_t total)>& on_sweep = {});
  /// The same, with obstacle ranges already detected (one list per beam).
  BatchStats Integrate(std::span<const Beam> beams, std::span<const std::vector<double>> obstacles);

  /// The map, brought up to date (FinishUpdates) if a batch was integrated since the last call.
  [[nodiscard]] const octomap::OcTree& tree() const {
    if (stale_) {
      FinishUpdates(*tree_);
      stale_ = false;
    }
    return *tree_;
  }
  [[nodiscard]] const MapperConfig& config() const { return config_; }

  /// Writes the map as an OctoMap binary `.bt` file (maximum-likelihood occupancy), atomically.
  void WriteBinary(const std::string& path) const;
  /// Writes the map as an OctoMap `.ot` file (full probabilities), atomically.
  void WriteFull(const std::string& path) const;

 private:
  MapperConfig config_;
  SensorGeometry sensor_;
  double free_range_m_ = 0.0;
  int threads_ = 1;
  std::vector<Eigen::Vector3d> directions_;
  std::unique_ptr<MapTree> tree_;
  /// The key sets and buffers of the batches, kept between them (the one of config.key_set).
  BatchWorkspace<KeySet> std_workspace_;
  BatchWorkspace<KeyOpenSet> open_workspace_;
  /// Whether the tree's node count and inner nodes lag its leaves (see FinishUpdates).
  mutable bool stale_ = false;
};

}  // namespace sonarbench::mapping
