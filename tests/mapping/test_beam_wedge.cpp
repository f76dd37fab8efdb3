#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "beam_volume.hpp"
#include "beam_wedge.hpp"
#include "mapping_grid.hpp"
#include "sonarbench/mapping/mapper.hpp"

namespace sonarbench::mapping {
namespace {

using test::kResolution;

Beam BeamAt(const Eigen::Vector3d& origin, double head_angle_rad, const Eigen::Vector3d& rpy) {
  Beam beam;
  beam.T_world_sonar = PoseFromXyzRpy(origin, rpy);
  beam.head_angle_rad = head_angle_rad;
  beam.bin_size_m = 0.01;
  return beam;
}

struct Cells {
  std::set<std::uint64_t> free;
  std::set<std::uint64_t> occupied;
  std::size_t examined = 0;
};

Cells Exact(const octomap::OcTree& tree, const SensorGeometry& sensor, const Beam& beam,
            std::vector<double> obstacles, double free_range_m = 0.0) {
  std::vector<std::uint64_t> free, occupied;
  const auto counts =
      ExactBeamCells(tree, BeamWedge(sensor, beam), obstacles, free_range_m, free, occupied);
  Cells out{{free.begin(), free.end()}, {occupied.begin(), occupied.end()}, counts.examined};
  EXPECT_EQ(out.free.size(), free.size()) << "a free cell listed twice";
  EXPECT_EQ(out.occupied.size(), occupied.size()) << "an occupied cell listed twice";
  for (const auto key : out.occupied) EXPECT_FALSE(out.free.contains(key));
  return out;
}

std::uint64_t Key(const octomap::OcTree& tree, double x, double y, double z) {
  return PackKey(tree.coordToKey(x, y, z));
}

// A needle beam (0.1° wide) along +x from a cell's centre: its cells are that row's, cell k
// spanning ranges [0.05 k - 0.025, 0.05 k + 0.025] (k >= 1). Counted by hand:
//   detection at 0.5 m: cells 0-9 free (the last ends at 0.475), cell 10 holds 0.5: occupied;
//   at 0.475, the face between cells 9 and 10: both meet that shell, both occupied, 0-8 free;
//   at 0.2 and 0.4: cells 0-3 free, 4 and 8 occupied, 5-7 and beyond untouched;
//   none, clearing out to 0.3: cells 0-6 free (cell 6, from 0.275, is partly before it).
TEST(ExactBeamCells, ANeedleBeamMarksTheCellsCountedByHand) {
  const octomap::OcTree tree(kResolution);
  SensorGeometry needle;
  needle.beam_width_horizontal_rad = 0.1 * kDegToRad;
  needle.beam_width_vertical_rad = 0.1 * kDegToRad;
  const Beam beam = BeamAt({0.025, 0.025, 0.025}, 0.0, Eigen::Vector3d::Zero());
  auto row = [&](std::initializer_list<int> cells) {
    std::set<std::uint64_t> keys;
    for (const int k : cells) keys.insert(Key(tree, 0.025 + 0.05 * k, 0.025, 0.025));
    return keys;
  };
  const Cells at_half = Exact(tree, needle, beam, {0.5});
  EXPECT_EQ(at_half.free, row({0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(at_half.occupied, row({10}));
  const Cells on_face = Exact(tree, needle, beam, {0.475});
  EXPECT_EQ(on_face.free, row({0, 1, 2, 3, 4, 5, 6, 7, 8}));
  EXPECT_EQ(on_face.occupied, row({9, 10}));
  const Cells two = Exact(tree, needle, beam, {0.2, 0.4});
  EXPECT_EQ(two.free, row({0, 1, 2, 3}));
  EXPECT_EQ(two.occupied, row({4, 8}));
  const Cells cleared = Exact(tree, needle, beam, {}, 0.3);
  EXPECT_EQ(cleared.free, row({0, 1, 2, 3, 4, 5, 6}));
  EXPECT_TRUE(cleared.occupied.empty());
  const Cells nothing = Exact(tree, needle, beam, {}, 0.0);
  EXPECT_TRUE(nothing.free.empty() && nothing.occupied.empty());
}

// The wedge of a Micron beam on a wall at 2 m: occupied cells are exactly the cells that meet
// the 2 m sphere inside the wedge, free ones lie wholly inside it. Checked per cell against the
// box's own ranges: an occupied cell's box reaches from at most 2 m to at least 2 m, a free
// cell's nearest point is within 2 m - and each occupied cell's centre within half a cell
// diagonal of the sphere.
TEST(ExactBeamCells, AWallAtAKnownRangeIsOccupiedAndTheWaterBeforeItFree) {
  const octomap::OcTree tree(kResolution);
  const SensorGeometry micron;
  const Beam beam = BeamAt({0.01, 0.02, -0.03}, 0.4, Eigen::Vector3d::Zero());
  const double wall = 2.0;
  const Cells cells = Exact(tree, micron, beam, {wall});
  const double half = 0.5 * kResolution;
  const double half_diagonal = std::sqrt(3.0) * half;
  ASSERT_GT(cells.occupied.size(), 50u);
  for (const auto packed : cells.occupied) {
    const auto key = UnpackKey(packed);
    const Eigen::Vector3d c =
        Eigen::Vector3d(tree.keyToCoord(key[0]), tree.keyToCoord(key[1]), tree.keyToCoord(key[2])) -
        beam.T_world_sonar.translation();
    EXPECT_LE(std::abs(c.norm() - wall), half_diagonal);
    const Eigen::Vector3d a = c.cwiseAbs();
    EXPECT_LE((a - Eigen::Vector3d::Constant(half)).cwiseMax(0.0).norm(), wall);
    EXPECT_GE((a + Eigen::Vector3d::Constant(half)).norm(), wall);
  }
  for (const auto packed : cells.free) {
    const auto key = UnpackKey(packed);
    const Eigen::Vector3d c =
        Eigen::Vector3d(tree.keyToCoord(key[0]), tree.keyToCoord(key[1]), tree.keyToCoord(key[2])) -
        beam.T_world_sonar.translation();
    EXPECT_LT(c.norm(), wall);
  }
  // The wall's cells make a shell about one cell thick: its area over the wedge, in cells, times
  // between one and three (a sphere crossing a grid meets 1-√3 cells per cell of area on average
  // over directions, the wedge's rim adds a ring).
  const double area = wall * wall * micron.beam_width_horizontal_rad * 2.0 *
                      std::sin(0.5 * micron.beam_width_vertical_rad);
  const double cells_of_area = area / (kResolution * kResolution);
  EXPECT_GT(static_cast<double>(cells.occupied.size()), cells_of_area);
  EXPECT_LT(static_cast<double>(cells.occupied.size()), 3.0 * cells_of_area);
}

// For random poses, head angles and ranges: every cell that 256 × 512 ray casts (CastBeam, the
// ray mode) visit lies in the exact set, and every exact cell the dense casts miss lies within
// one cell of the set's boundary (a neighbour of it is not in the set). Each cell is examined
// about once: the candidates are at most twice the cells marked.
TEST(ExactBeamCells, HoldsEveryCellOfDenseRayCastsAndMissesNone) {
  const octomap::OcTree tree(kResolution);
  const SensorGeometry micron;
  const auto dense = BeamRayDirections(micron, 256, 512);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 12; ++trial) {
    const Beam beam =
        BeamAt({unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5}, 6.283 * unit(rng),
               trial % 3 == 0 ? Eigen::Vector3d::Zero()
                              : Eigen::Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, 3 * unit(rng)));
    const double range = 0.4 + 2.6 * unit(rng);
    SCOPED_TRACE("trial " + std::to_string(trial) + ", range " + std::to_string(range));
    const Cells exact = Exact(tree, micron, beam, {range});
    std::set<std::uint64_t> all(exact.free);
    all.insert(exact.occupied.begin(), exact.occupied.end());
    BeamCells rays;
    CastBeam(tree, beam, dense, std::vector<double>{range}, 0.0, rays);
    std::set<std::uint64_t> visited;
    for (const auto& key : rays.free) visited.insert(PackKey(key));
    for (const auto& key : rays.occupied) {
      visited.insert(PackKey(key));
      EXPECT_TRUE(exact.occupied.contains(PackKey(key))) << "a ray's end not occupied";
    }
    std::size_t outside = 0;
    for (const auto key : visited) outside += all.contains(key) ? 0 : 1;
    EXPECT_EQ(outside, 0u);
    std::size_t missed = 0, missed_inside = 0;
    for (const auto packed : all) {
      if (visited.contains(packed)) continue;
      ++missed;
      const auto k = UnpackKey(packed);
      bool on_boundary = false;
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dz = -1; dz <= 1; ++dz) {
            const octomap::OcTreeKey n(static_cast<octomap::key_type>(k[0] + dx),
                                       static_cast<octomap::key_type>(k[1] + dy),
                                       static_cast<octomap::key_type>(k[2] + dz));
            on_boundary |= !all.contains(PackKey(n));
          }
        }
      }
      missed_inside += on_boundary ? 0 : 1;
    }
    EXPECT_EQ(missed_inside, 0u) << missed << " cells missed by the rays";
    EXPECT_LE(exact.examined, 2 * all.size());
    // Without a detection, clearing out to the range: every cell the rays clear is cleared.
    const Cells cleared = Exact(tree, micron, beam, {}, range);
    EXPECT_TRUE(cleared.occupied.empty());
    BeamCells clearing;
    CastBeam(tree, beam, dense, std::vector<double>{}, range, clearing);
    std::size_t not_cleared = 0;
    for (const auto& key : clearing.free)
      not_cleared += cleared.free.contains(PackKey(key)) ? 0 : 1;
    EXPECT_EQ(not_cleared, 0u);
    EXPECT_GE(cleared.free.size(), exact.free.size());
  }
}

// Every shortcut the scan takes (box ranges, corners, one-plane spans, the separating axes, the
// columns' extents and runs) agrees with the semantics applied to each cell's clipped span
// (BeamWedge::CellSpan) over the whole bounding box: random poses, none to three detections,
// with and without clearing, out to 3 m (the wedge is narrower than a cell within 1 m).
TEST(ExactBeamCells, EveryCellIsMarkedAsItsClippedSpanDecides) {
  const octomap::OcTree tree(kResolution);
  const SensorGeometry micron;
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    const Beam beam = BeamAt({unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5}, 6.283 * unit(rng),
                             {unit(rng) - 0.5, unit(rng) - 0.5, 6.283 * unit(rng)});
    std::vector<double> obstacles;
    for (int k = 0; k < trial % 4; ++k) obstacles.push_back(0.1 + 2.9 * unit(rng));
    std::sort(obstacles.begin(), obstacles.end());
    const double free_range = trial % 8 < 4 ? 0.0 : 0.2 + 2.8 * unit(rng);
    SCOPED_TRACE("trial " + std::to_string(trial));
    const Cells cells = Exact(tree, micron, beam, obstacles, free_range);
    const BeamWedge wedge(micron, beam);
    const double first = obstacles.empty() ? free_range : obstacles.front();
    std::set<std::uint64_t> free, occupied;
    const Eigen::Vector3d o = beam.T_world_sonar.translation();
    const double reach = std::max(first, obstacles.empty() ? 0.0 : obstacles.back()) + kResolution;
    const auto lo = tree.coordToKey(o.x() - reach, o.y() - reach, o.z() - reach);
    const auto hi = tree.coordToKey(o.x() + reach, o.y() + reach, o.z() + reach);
    for (int x = lo[0]; x <= hi[0]; ++x) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int z = lo[2]; z <= hi[2]; ++z) {
          const octomap::OcTreeKey key(static_cast<octomap::key_type>(x),
                                       static_cast<octomap::key_type>(y),
                                       static_cast<octomap::key_type>(z));
          const Eigen::Vector3d c(tree.keyToCoord(key[0]), tree.keyToCoord(key[1]),
                                  tree.keyToCoord(key[2]));
          const BeamWedge::Span span = wedge.CellSpan(c - o, 0.5 * kResolution);
          if (!span.meets) continue;
          bool on_shell = false;
          for (const double r : obstacles) on_shell |= span.near <= r && r <= span.far;
          if (on_shell) {
            occupied.insert(PackKey(key));
          } else if (first > 0.0 && (obstacles.empty() ? span.near : span.far) < first) {
            free.insert(PackKey(key));
          }
        }
      }
    }
    EXPECT_EQ(cells.occupied, occupied);
    EXPECT_EQ(cells.free, free);
  }
}

// The exact mode's map is the same on one thread and on several, whatever set collects it.
TEST(ExactBeamCells, TheMapIsTheSameOnOneAndManyThreadsInEveryKeySet) {
  const SensorGeometry micron;
  std::vector<Beam> beams;
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> level(0, 255);
  for (int i = 0; i < micron.BeamsPerSweep(); ++i) {
    Beam beam = BeamAt({0.1, -0.2, 0.3}, i * micron.step_angle_rad, {0.0, 0.1, 0.0});
    beam.bin_size_m = micron.bin_size_m;
    beam.intensities.assign(static_cast<std::size_t>(micron.num_bins), 10);
    // A wall at 1.5-2.5 m, nearer on one side, and a weaker echo behind it.
    const auto wall_bin = static_cast<std::size_t>((1.5 + (i % 50) * 0.02) / micron.bin_size_m);
    for (std::size_t b = wall_bin; b < wall_bin + 4; ++b) beam.intensities[b] = 150;
    beam.intensities[wall_bin + 40 + static_cast<std::size_t>(i % 7)] =
        static_cast<std::uint8_t>(100 + level(rng) % 50);
    beams.push_back(beam);
  }
  std::vector<std::string> maps;
  for (const KeySetKind set :
       {KeySetKind::kBlocks, KeySetKind::kOpenAddressing, KeySetKind::kStd}) {
    for (const int threads : {1, 3}) {
      MapperConfig config;
      config.integration = Integration::kExact;
      config.threads = threads;
      config.key_set = set;
      Mapper mapper(config, micron);
      const BatchStats stats = mapper.Integrate(beams);
      EXPECT_GT(stats.occupied_cells, 0u);
      EXPECT_GT(stats.free_cells, stats.occupied_cells);
      std::ostringstream out;
      WriteOctomapBinary(mapper.tree(), out);
      maps.push_back(out.str());
      EXPECT_EQ(maps.back(), maps.front()) << static_cast<int>(set) << ", " << threads;
    }
  }
}

}  // namespace
}  // namespace sonarbench::mapping
