#include "arc_evidence.hpp"

#include <algorithm>
#include <cmath>

#include "key_set.hpp"

namespace sonarbench::mapping {

void AppendArcShares(const octomap::OcTree& tree, const ArcEvidence& evidence,
                     const Eigen::Vector3d& origin, const Eigen::Vector3d& up,
                     std::span<const double> ranges_m, std::span<const std::uint64_t> keys,
                     ArcShareScratch& scratch, std::vector<std::uint64_t>& out) {
  if (keys.empty() || ranges_m.empty()) return;
  scratch.cells.resize(keys.size());
  std::vector<double>& shell_max = scratch.shell_max;
  shell_max.assign(ranges_m.size(), 0.0);
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const octomap::OcTreeKey key = UnpackKey(keys[i]);
    const octomap::point3d c = tree.keyToCoord(key);
    const Eigen::Vector3d p = Eigen::Vector3d(c.x(), c.y(), c.z()) - origin;
    const double r = p.norm();
    std::size_t shell = 0;
    for (std::size_t s = 1; s < ranges_m.size(); ++s) {
      if (std::abs(r - ranges_m[s]) < std::abs(r - ranges_m[shell])) shell = s;
    }
    const double sine = r > 0.0 ? std::clamp(up.dot(p) / r, -1.0, 1.0) : 0.0;
    const double elevation = std::asin(sine);
    const octomap::OcTreeNode* node = tree.search(key);
    const double occupancy = node != nullptr ? node->getOccupancy() : 0.5;
    const double weight = std::exp(-evidence.pattern_k * elevation * elevation) * occupancy;
    scratch.cells[i] = {weight, shell};
    shell_max[shell] = std::max(shell_max[shell], weight);
  }
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const double top = shell_max[scratch.cells[i].shell];
    const double share = top > 0.0 ? scratch.cells[i].weight / top : 1.0;
    const auto level = std::clamp<std::uint64_t>(
        static_cast<std::uint64_t>(std::lround(share * static_cast<double>(kShareLevelMax))), 1,
        kShareLevelMax);
    out.push_back((keys[i] << kShareBits) | level);
  }
}

float ShareLogOdds(double prob_hit, float hit_log_odds, std::uint64_t level) {
  if (level >= kShareLevelMax) return hit_log_odds;
  const double p =
      0.5 + (prob_hit - 0.5) * static_cast<double>(level) / static_cast<double>(kShareLevelMax);
  return static_cast<float>(std::log(p / (1.0 - p)));
}

}  // namespace sonarbench::mapping
