#pragma once

#include <octomap/OcTree.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "key_set.hpp"
#include "ray_keys.hpp"

namespace sonarbench::mapping {

/// Appends to `walks` the start of OctoMap's DDA (StartRayWalkFromKey, bit for bit) for each
/// segment from `origin` to one of `ends` whose points both lie in the tree's key range and in
/// different cells, in the order of `ends`. With `vector` true and a processor with AVX-512,
/// eight segments are set up at a time (the same IEEE operations, in the same order).
void StartRayWalks(const octomap::OcTree& tree, const octomap::point3d& origin,
                   std::span<const octomap::point3d> ends, bool vector,
                   std::vector<RayWalk>& walks);

/// Collects the distinct cells that many rays from one origin cross: the free cells of one beam.
///
/// The rays are OctoMap's DDA (ForEachRayKey's cells, exactly). Each visited cell sets a mark in
/// a bitmap over the box of the beam's cells; a cell is reported when its mark was clear.
/// The seed paper's section 3.2 notes that H×V rays visit the same cells many times (≈70 visits per
/// distinct cell of a beam in the real tank log): the marks absorb those repeats, and only a beam's
/// distinct cells go on to the key set. On processors with AVX-512 the walks run eight at a
/// time, one per vector lane, with masks instead of branches (the same arithmetic, so the same
/// cells); on those with AVX2 only, four at a time; elsewhere one after another. A beam whose
/// box would exceed kMaxBoxCells (long range at fine resolution) is walked into a hash set
/// instead; the cells are the same.
///
/// One BeamRaster per thread: it keeps its buffers between beams.
class BeamRaster {
 public:
  /// kFastest uses the AVX-512 kernel where the processor has it, else the AVX2 walk where it
  /// has that; kAvx2 the AVX2 walk where the processor has it (tests); kPortable neither (tests
  /// compare them).
  enum class Kernel { kFastest, kAvx2, kPortable };
  explicit BeamRaster(Kernel kernel = Kernel::kFastest) : kernel_(kernel) {}

  /// Whether this processor runs the AVX-512 kernel.
  [[nodiscard]] static bool HasVectorKernel();
  /// Whether this processor runs the AVX2 walk (the walk only: the walks' set-up is then one
  /// ray at a time).
  [[nodiscard]] static bool HasAvx2Kernel();

  /// The largest box [cells] the marks cover (one bit per cell: 8 MiB).
  static constexpr std::uint64_t kMaxBoxCells = std::uint64_t{1} << 26;

  /// Appends to `free_keys` (packed, see PackKey) each distinct cell that a segment from
  /// `origin` to one of `ends` crosses before its end point's cell, once, in a fixed order.
  /// Segments with a point outside the tree's key range are skipped, as ForEachRayKey does.
  /// Returns the number of cell visits, repeats included.
  std::size_t Trace(const octomap::OcTree& tree, const octomap::point3d& origin,
                    std::span<const octomap::point3d> ends, std::vector<std::uint64_t>& free_keys);

  /// Whether the last Trace() walked its rays one at a time (its box was too large).
  [[nodiscard]] bool used_fallback() const { return used_fallback_; }

 private:
  // The walks in walks_, one at a time, into a hash set.
  std::size_t TraceOneByOne(std::vector<std::uint64_t>& free_keys);

  std::vector<RayWalk> walks_;
  std::vector<std::uint64_t> marks_;    // one bit per cell of the box; all zero between calls
  std::vector<std::uint64_t> touched_;  // cell indices whose bit was set, in order
  OpenKeySet<> seen_;                   // the fallback's set
  Kernel kernel_;
  bool used_fallback_ = false;
};

}  // namespace sonarbench::mapping
