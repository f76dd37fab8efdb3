#include "sonarbench/sim/score.hpp"

namespace sonarbench::sim {
namespace {

double Ratio(std::size_t numerator, std::size_t denominator) {
  return denominator == 0 ? 0.0 : static_cast<double>(numerator) / static_cast<double>(denominator);
}

}  // namespace

MapCells CollectMapCells(const octomap::OcTree& map) {
  MapCells cells;
  const unsigned max_depth = map.getTreeDepth();
  for (auto it = map.begin_leafs(), end = map.end_leafs(); it != end; ++it) {
    mapping::KeySet& target = map.isNodeOccupied(*it) ? cells.occupied : cells.free;
    const octomap::OcTreeKey key = it.getIndexKey();
    const int span = 1 << (max_depth - it.getDepth());
    for (int x = 0; x < span; ++x) {
      for (int y = 0; y < span; ++y) {
        for (int z = 0; z < span; ++z) {
          target.insert(octomap::OcTreeKey(static_cast<octomap::key_type>(key[0] + x),
                                           static_cast<octomap::key_type>(key[1] + y),
                                           static_cast<octomap::key_type>(key[2] + z)));
        }
      }
    }
  }
  return cells;
}

MapMetrics ScoreMap(const octomap::OcTree& map, const mapping::KeySet& truth,
                    const mapping::KeySet& observable) {
  const MapCells cells = CollectMapCells(map);
  MapMetrics m;
  m.truth_cells = truth.size();
  m.occupied_cells = cells.occupied.size();
  m.free_cells = cells.free.size();
  for (const auto& key : cells.occupied) m.true_positive_cells += truth.contains(key) ? 1 : 0;
  for (const auto& key : observable) {
    if (!truth.contains(key)) continue;
    ++m.observable_cells;
    if (cells.occupied.contains(key)) {
      ++m.observed_occupied_cells;
      ++m.known_observable_cells;
    } else if (cells.free.contains(key)) {
      ++m.known_observable_cells;
    }
  }
  m.occupied_precision = Ratio(m.true_positive_cells, m.occupied_cells);
  m.occupied_recall = Ratio(m.observed_occupied_cells, m.observable_cells);
  const double sum = m.occupied_precision + m.occupied_recall;
  m.occupied_f1 = sum > 0.0 ? 2.0 * m.occupied_precision * m.occupied_recall / sum : 0.0;
  m.coverage = Ratio(m.known_observable_cells, m.observable_cells);
  return m;
}

}  // namespace sonarbench::sim
