#include "sonarbench/sim/app/certainty.hpp"

#include <cstdio>

#include "sonarbench/mapping/mapper.hpp"

namespace sonarbench::sim {

CertaintyCurve SweepCertainty(std::span<const mapping::Beam> beams,
                              const mapping::SensorGeometry& sensor,
                              const mapping::MapperConfig& config, const octomap::OcTree& final_map,
                              const mapping::KeySet& truth) {
  std::vector<octomap::OcTreeKey> on_surface;
  std::vector<octomap::OcTreeKey> off_surface;
  for (auto it = final_map.begin_leafs(); it != final_map.end_leafs(); ++it) {
    if (it.getDepth() != final_map.getTreeDepth() || !final_map.isNodeOccupied(*it)) continue;
    (truth.count(it.getKey()) ? on_surface : off_surface).push_back(it.getKey());
  }
  CertaintyCurve curve;
  curve.true_cells = on_surface.size();
  curve.false_cells = off_surface.size();
  mapping::Mapper mapper(config, sensor);
  const auto mean = [&](const std::vector<octomap::OcTreeKey>& keys) {
    const octomap::OcTree& tree = mapper.tree();
    double sum = 0.0;
    for (const octomap::OcTreeKey& key : keys) {
      const octomap::OcTreeNode* node = tree.search(key);
      sum += node ? node->getOccupancy() : 0.5;
    }
    return keys.empty() ? 0.0 : sum / static_cast<double>(keys.size());
  };
  (void)mapper.IntegrateSweeps(beams, [&](std::size_t, std::size_t) {
    curve.true_mean.push_back(mean(on_surface));
    curve.false_mean.push_back(mean(off_surface));
  });
  return curve;
}

std::string CertaintyCsv(const CertaintyCurve& curve) {
  std::string csv = "sweep,true_cells,true_mean_probability,false_cells,false_mean_probability\n";
  for (std::size_t s = 0; s < curve.true_mean.size(); ++s) {
    char line[160];
    std::snprintf(line, sizeof line, "%zu,%zu,%.6f,%zu,%.6f\n", s + 1, curve.true_cells,
                  curve.true_mean[s], curve.false_cells, curve.false_mean[s]);
    csv += line;
  }
  return csv;
}

}  // namespace sonarbench::sim
