#pragma once

#include <octomap/OcTree.h>

#include <functional>
#include <memory>
#include <ostream>
#include <span>
#include <string>

#include "sonarbench/mapping/batch_stats.hpp"
#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::mapping {

/// The first line of each OctoMap file format: binary `.bt` and full `.ot`, as OctoMap writes them.
inline constexpr const char* kOctomapBinaryHeader = "# Octomap OcTree binary file";
inline constexpr const char* kOctomapFullHeader = "# Octomap OcTree file";

/// Writes `tree` in OctoMap's binary `.bt` format: the bytes OcTree::writeBinaryConst writes,
/// without the " done." that Debian's liboctomap prints on stderr for each file.
void WriteOctomapBinary(const octomap::OcTree& tree, std::ostream& out);

/// The production mapper: detection, beam volumes (each beam's exact wedge, or ray casts:
/// `config.integration`) and OctoMap log-odds updates. Threading: Integrate() finds the cells of
/// a batch's beams on `config.threads` threads, each into its own key sets, merged afterwards,
/// and updates the root's octants in parallel; the resulting map is identical for any thread
/// count. A Mapper is not safe to call from several threads at once, but for its const members
/// between Integrates; tree(), which builds the tree the batches leave to it, must have returned
/// once before several threads call it.
class Mapper {
 public:
  /// Throws std::invalid_argument naming the field when `config` is outside what the mapper
  /// takes (a resolution that is not positive, rays or echoes under 1, a threshold outside
  /// 1..255, an even smoothing window, hit/miss probabilities or clamps on the wrong side of 0.5).
  explicit Mapper(const MapperConfig& config, const SensorGeometry& sensor);
  ~Mapper();
  Mapper(Mapper&&) noexcept;
  Mapper& operator=(Mapper&&) noexcept;
  Mapper(const Mapper&) = delete;
  Mapper& operator=(const Mapper&) = delete;

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

  /// The map, its inner nodes brought up to date if a batch was integrated since the last call.
  [[nodiscard]] const octomap::OcTree& tree() const;
  [[nodiscard]] const MapperConfig& config() const { return config_; }

  /// Writes the map in OctoMap's binary `.bt` format (maximum-likelihood occupancy) to `out`;
  /// a failed write leaves `out` bad.
  void WriteBinary(std::ostream& out) const;
  /// Writes the map in OctoMap's `.ot` format (full probabilities) to `out`.
  void WriteFull(std::ostream& out) const;
  /// Calls `f` with each leaf of the map (a cell updated at least once) and whether it is
  /// occupied (isNodeOccupied), in no particular order. Like the writers, it does not need the
  /// tree built: for maps that tree() is never asked for, it never is.
  void ForEachLeaf(
      const std::function<void(const octomap::OcTreeKey& key, bool occupied)>& f) const;

 private:
  MapperConfig config_;
  SensorGeometry sensor_;
  /// The tree and the batches' workspaces (mapper.cpp): the public header needs no OpenMP.
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace sonarbench::mapping
