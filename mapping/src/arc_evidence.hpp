#pragma once

#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace sonarbench::mapping {

/// How a detection's shell cells are updated (MapperConfig::occupancy). Default: arc marking.
struct ArcEvidence {
  /// The two-way vertical pattern exp(-pattern_k · elevation²) [1/rad²]; 0: arc marking (every
  /// shell cell gets the full hit, the seed paper's).
  double pattern_k = 0.0;
  [[nodiscard]] bool on() const { return pattern_k > 0.0; }
};

/// Bits of an occupied cell's share level in a batch's updates (docs/mapper.md, "Arc evidence"):
/// level 0 is free, 1..kShareLevelMax an occupied share of kShareLevelMax.
inline constexpr unsigned kShareBits = 8;
inline constexpr std::uint64_t kShareLevelMax = (std::uint64_t{1} << kShareBits) - 1;

/// AppendArcShares' scratch, reused from beam to beam: each shell cell's w·P and its shell's
/// index, and each shell's largest w·P.
struct ArcShareScratch {
  struct Cell {
    double weight = 0.0;
    std::size_t shell = 0;
  };
  std::vector<Cell> cells;
  std::vector<double> shell_max;
};

/// Appends, for each of one beam's occupied `keys` (packed, PackKey), `packed << kShareBits |
/// level`: the cell's share of its shell's echo, w·P / max over the shell of w·P, where w is the
/// vertical pattern at the elevation of the cell's centre seen from `origin` (world frame, `up`
/// the beam's elevation axis, unit), P the cell's occupancy in `tree` before this batch (0.5
/// unknown), and its shell the detection range (`ranges_m`, nearest first) nearest the centre's
/// range. `scratch` is reused.
void AppendArcShares(const octomap::OcTree& tree, const ArcEvidence& evidence,
                     const Eigen::Vector3d& origin, const Eigen::Vector3d& up,
                     std::span<const double> ranges_m, std::span<const std::uint64_t> keys,
                     ArcShareScratch& scratch, std::vector<std::uint64_t>& out);

/// The log-odds update of share level `level` (1..kShareLevelMax): logit(0.5 + (p_hit - 0.5) ·
/// level / kShareLevelMax); the full level is `hit_log_odds` itself.
[[nodiscard]] float ShareLogOdds(double prob_hit, float hit_log_odds, std::uint64_t level);

}  // namespace sonarbench::mapping
