#include "sonarbench/sim/eval/score.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/world/ray_tracer.hpp"

namespace sonarbench::sim {
namespace {

double Ratio(std::size_t numerator, std::size_t denominator) {
  return denominator == 0 ? 0.0 : static_cast<double>(numerator) / static_cast<double>(denominator);
}

DistanceStats Summarise(std::vector<double> d) {
  DistanceStats s;
  s.count = d.size();
  if (d.empty()) return s;
  std::sort(d.begin(), d.end());
  double sum = 0.0;
  for (const double v : d) sum += v;
  s.mean_m = sum / static_cast<double>(d.size());
  s.p95_m = d[std::min(d.size() - 1, static_cast<std::size_t>(std::ceil(0.95 * d.size())) - 1)];
  s.max_m = d.back();
  return s;
}

using Key = octomap::OcTreeKey;

// Visits the cells at Chebyshev distance exactly `ring` from `centre`.
template <typename F>
void ForEachInRing(const Key& centre, int ring, F&& f) {
  for (int dx = -ring; dx <= ring; ++dx) {
    for (int dy = -ring; dy <= ring; ++dy) {
      for (int dz = -ring; dz <= ring; ++dz) {
        if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != ring) continue;
        const int x = centre[0] + dx, y = centre[1] + dy, z = centre[2] + dz;
        if (x < 0 || y < 0 || z < 0 || x > 65535 || y > 65535 || z > 65535) continue;
        f(Key(static_cast<octomap::key_type>(x), static_cast<octomap::key_type>(y),
              static_cast<octomap::key_type>(z)));
      }
    }
  }
}

// Searches rings outwards from `from`'s cell; `visit(cell)` returns the distance to what that
// cell holds, or a negative number. A cell `ring` rings out is at least (ring - 1) cells away,
// so the search stops once that exceeds the best distance found, or at `max_ring`.
template <typename Visit>
double NearestByRings(const Key& from, double resolution, int max_ring, Visit&& visit) {
  double best = -1.0;
  for (int ring = 0; ring <= max_ring; ++ring) {
    if (best >= 0.0 && (ring - 1) * resolution > best) break;
    ForEachInRing(from, ring, [&](const Key& cell) {
      const double d = visit(cell);
      if (d >= 0.0 && (best < 0.0 || d < best)) best = d;
    });
  }
  return best;
}

Eigen::Vector3d Centre(const octomap::OcTree& map, const Key& key) {
  const octomap::point3d c = map.keyToCoord(key);
  return {c.x(), c.y(), c.z()};
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

MapCells CollectMapCells(const mapping::Mapper& mapper) {
  MapCells cells;
  mapper.ForEachLeaf([&cells](const octomap::OcTreeKey& key, bool occupied) {
    (occupied ? cells.occupied : cells.free).insert(key);
  });
  return cells;
}

bool AnyWithin(const mapping::KeySet& cells, const Key& key, int k) {
  for (int dx = -k; dx <= k; ++dx) {
    for (int dy = -k; dy <= k; ++dy) {
      for (int dz = -k; dz <= k; ++dz) {
        const Key near(static_cast<octomap::key_type>(key[0] + dx),
                       static_cast<octomap::key_type>(key[1] + dy),
                       static_cast<octomap::key_type>(key[2] + dz));
        if (cells.contains(near)) return true;
      }
    }
  }
  return false;
}

namespace {

double F1(double precision, double recall) {
  const double sum = precision + recall;
  return sum > 0.0 ? 2.0 * precision * recall / sum : 0.0;
}

// Precision, recall and F1 within 1 and 2 cells (index 0: CountCells' exact figures, which it
// needs first), and the ghosts' share; returns the ghosts.
std::vector<Key> CountWithinTolerance(const MapCells& cells, const mapping::KeySet& truth,
                                      const mapping::KeySet& observable, MapMetrics& m) {
  m.precision_within[0] = m.occupied_precision;
  m.recall_within[0] = m.occupied_recall;
  m.f1_within[0] = m.occupied_f1;
  std::vector<Key> ghosts;
  for (int k = 1; k < 3; ++k) {
    std::size_t near_truth = 0;
    for (const auto& key : cells.occupied) {
      if (AnyWithin(truth, key, k)) {
        ++near_truth;
      } else if (k == 2) {
        ghosts.push_back(key);
      }
    }
    std::size_t seen = 0;
    for (const auto& key : observable) {
      if (truth.contains(key)) seen += AnyWithin(cells.occupied, key, k) ? 1 : 0;
    }
    const auto index = static_cast<std::size_t>(k);
    m.precision_within[index] = Ratio(near_truth, m.occupied_cells);
    m.recall_within[index] = Ratio(seen, m.observable_cells);
    m.f1_within[index] = F1(m.precision_within[index], m.recall_within[index]);
  }
  m.ghost_share = cells.occupied.empty() ? 0.0 : 1.0 - m.precision_within[2];
  return ghosts;
}

// The ghosts (occupied, more than 2 cells from every truth cell) on a direct echo's arc, and
// the others, the detector's: their shares, and their cells into `detector_ghosts` if given.
void SplitGhosts(const octomap::OcTree& map, const std::vector<Key>& ghosts,
                 const DirectEchoes& direct, MapMetrics& m, mapping::KeySet* detector_ghosts) {
  const double half_diagonal = 0.5 * std::sqrt(3.0) * map.getResolution();
  std::vector<char> on_arc(ghosts.size());
  const auto count = static_cast<std::int64_t>(ghosts.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (std::int64_t i = 0; i < count; ++i) {
    const auto g = static_cast<std::size_t>(i);
    on_arc[g] = direct.Explains(Centre(map, ghosts[g]), half_diagonal) ? 1 : 0;
  }
  std::size_t arc = 0;
  for (std::size_t g = 0; g < ghosts.size(); ++g) {
    arc += static_cast<std::size_t>(on_arc[g]);
    if (detector_ghosts && on_arc[g] == 0) detector_ghosts->insert(ghosts[g]);
  }
  m.ghost_arc_share = Ratio(arc, m.occupied_cells);
  m.ghost_echo_share = Ratio(ghosts.size() - arc, m.occupied_cells);
}

}  // namespace

std::pair<double, double> SplitGhostsBy(const octomap::OcTree& map, const mapping::KeySet& truth,
                                        const DirectEchoes& direct) {
  const MapCells cells = CollectMapCells(map);
  std::vector<Key> ghosts;
  for (const Key& key : cells.occupied) {
    if (!AnyWithin(truth, key, 2)) ghosts.push_back(key);
  }
  MapMetrics m;
  m.occupied_cells = cells.occupied.size();
  SplitGhosts(map, ghosts, direct, m, nullptr);
  return {*m.ghost_arc_share, *m.ghost_echo_share};
}

namespace {

// Column precision and recall: the cells' (x, y) columns, top down.
void CountColumns(const MapCells& cells, const mapping::KeySet& truth,
                  const mapping::KeySet& observable, MapMetrics& m) {
  const auto column = [](const Key& key) {
    return (static_cast<std::uint32_t>(key[0]) << 16) | key[1];
  };
  std::unordered_set<std::uint32_t> occupied;
  std::unordered_set<std::uint32_t> truth_columns;
  std::unordered_set<std::uint32_t> observable_columns;
  for (const auto& key : cells.occupied) occupied.insert(column(key));
  for (const auto& key : truth) truth_columns.insert(column(key));
  for (const auto& key : observable) {
    if (truth.contains(key)) observable_columns.insert(column(key));
  }
  std::size_t true_columns = 0;
  for (const std::uint32_t c : occupied) true_columns += truth_columns.contains(c) ? 1 : 0;
  std::size_t seen_columns = 0;
  for (const std::uint32_t c : observable_columns) seen_columns += occupied.contains(c) ? 1 : 0;
  m.column_precision = Ratio(true_columns, occupied.size());
  m.column_recall = Ratio(seen_columns, observable_columns.size());
}

// The cell counts and the ratios made of them.
void CountCells(const MapCells& cells, const mapping::KeySet& truth,
                const mapping::KeySet& observable, MapMetrics& m) {
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
  m.occupied_f1 = F1(m.occupied_precision, m.occupied_recall);
  m.coverage = Ratio(m.known_observable_cells, m.observable_cells);
  std::size_t known_truth = 0;
  for (const auto& key : truth) {
    known_truth += (cells.occupied.contains(key) || cells.free.contains(key)) ? 1 : 0;
  }
  m.coverage_absolute = Ratio(known_truth, truth.size());
  for (const auto& key : cells.free) m.free_on_surface_cells += truth.contains(key) ? 1 : 0;
  // Not applicable (NaN, null in report.json) to a map of occupied cells only.
  m.free_accuracy = cells.free.empty() ? NAN : 1.0 - Ratio(m.free_on_surface_cells, m.free_cells);
}

// Recall of one mesh's own observable cells.
MapMetrics::MeshRecall MeshRecallOf(const TriangleMesh& mesh, const octomap::OcTree& map,
                                    const MapCells& cells, const mapping::KeySet& observable) {
  MapMetrics::MeshRecall r;
  r.name = mesh.name;
  for (const auto& key : VoxelizeMeshes(std::span(&mesh, 1), map)) {
    if (!observable.contains(key)) continue;
    ++r.observable_cells;
    r.observed_occupied_cells += cells.occupied.contains(key) ? 1 : 0;
  }
  r.recall = Ratio(r.observed_occupied_cells, r.observable_cells);
  return r;
}

// Distances from occupied cell centres to the nearest truth surface.
DistanceStats MapToMesh(const std::vector<TriangleMesh>& truth_meshes, const octomap::OcTree& map,
                        const MapCells& cells) {
  const RayTracer tracer(truth_meshes);
  std::vector<double> d;
  d.reserve(cells.occupied.size());
  for (const auto& key : cells.occupied) {
    if (const auto best = tracer.NearestSurfaceDistance(Centre(map, key), 1e3)) d.push_back(*best);
  }
  return Summarise(std::move(d));
}

// Distances from observable surface cells to the nearest occupied cell.
DistanceStats MeshToMap(const octomap::OcTree& map, const MapCells& cells,
                        const mapping::KeySet& truth, const mapping::KeySet& observable) {
  const double res = map.getResolution();
  // Occupied cells bucketed in blocks of 8³ cells: rings of blocks around a query skip empty
  // space 8 cells at a time. A block `ring` blocks out is at least (ring - 1) blocks away.
  constexpr int kBlock = 8;
  std::unordered_map<Key, std::vector<Key>, Key::KeyHash> blocks;
  for (const auto& key : cells.occupied) {
    blocks[Key(static_cast<octomap::key_type>(key[0] / kBlock),
               static_cast<octomap::key_type>(key[1] / kBlock),
               static_cast<octomap::key_type>(key[2] / kBlock))]
        .push_back(key);
  }
  std::vector<double> d;
  for (const auto& key : observable) {
    if (!truth.contains(key)) continue;
    const Eigen::Vector3d p = Centre(map, key);
    const Key block(static_cast<octomap::key_type>(key[0] / kBlock),
                    static_cast<octomap::key_type>(key[1] / kBlock),
                    static_cast<octomap::key_type>(key[2] / kBlock));
    const double best = NearestByRings(block, kBlock * res, 65536 / kBlock, [&](const Key& b) {
      const auto it = blocks.find(b);
      if (it == blocks.end()) return -1.0;
      double nearest = -1.0;
      for (const auto& cell : it->second) {
        const double dist = (Centre(map, cell) - p).norm();
        if (nearest < 0.0 || dist < nearest) nearest = dist;
      }
      return nearest;
    });
    if (best >= 0.0) d.push_back(best);
  }
  return Summarise(std::move(d));
}

}  // namespace

MapMetrics ScoreMap(const octomap::OcTree& map, const mapping::KeySet& truth,
                    const mapping::KeySet& observable, std::span<const TriangleMesh> meshes,
                    const StageProgress& progress, const DirectEchoes* direct,
                    mapping::KeySet* detector_ghosts) {
  const MapCells cells = CollectMapCells(map);
  MapMetrics m;
  CountCells(cells, truth, observable, m);
  const std::vector<Key> ghosts = CountWithinTolerance(cells, truth, observable, m);
  if (direct) SplitGhosts(map, ghosts, *direct, m, detector_ghosts);
  CountColumns(cells, truth, observable, m);
  std::vector<TriangleMesh> truth_meshes;
  for (const TriangleMesh& mesh : meshes) {
    if (mesh.truth) truth_meshes.push_back(mesh);
  }
  std::size_t passes = 0;
  const std::size_t total = truth_meshes.size() + 3;
  const auto pass_done = [&] {
    if (progress) progress(++passes, total);
  };
  pass_done();
  for (const TriangleMesh& mesh : truth_meshes) {
    m.per_mesh.push_back(MeshRecallOf(mesh, map, cells, observable));
    pass_done();
  }
  if (!truth_meshes.empty()) m.map_to_mesh = MapToMesh(truth_meshes, map, cells);
  pass_done();
  if (!cells.occupied.empty()) m.mesh_to_map = MeshToMap(map, cells, truth, observable);
  pass_done();
  return m;
}

}  // namespace sonarbench::sim
