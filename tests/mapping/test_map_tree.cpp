#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <random>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include "beam_raster.hpp"
#include "beam_volume.hpp"
#include "integrate.hpp"
#include "map_tree.hpp"
#include "ray_keys.hpp"
#include "sonarbench/mapping/mapper.hpp"

namespace sonarbench::mapping {
namespace {

using Reference = std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash>;

// A batch of up to 3000 distinct keys, each with whether it is occupied (Morton code << 1 |
// occupied), updated in OctoMap's `tree` by updateNode in the batch's order. Few keys in all
// (25^3, across the root's octants), so most are updated again and many reach a clamp.
std::vector<std::pair<std::uint64_t, octomap::OcTreeKey>> RandomBatch(std::mt19937_64& rng,
                                                                      octomap::OcTree& tree) {
  std::uniform_int_distribution<int> near(32768 - 12, 32768 + 12);
  std::bernoulli_distribution hit(0.3);
  std::vector<std::pair<std::uint64_t, octomap::OcTreeKey>> updates;
  std::vector<std::uint64_t> seen;
  for (int i = 0; i < 3000; ++i) {
    const octomap::OcTreeKey key(static_cast<octomap::key_type>(near(rng)),
                                 static_cast<octomap::key_type>(near(rng)),
                                 static_cast<octomap::key_type>(near(rng)));
    if (std::find(seen.begin(), seen.end(), PackKey(key)) != seen.end()) continue;
    seen.push_back(PackKey(key));
    updates.emplace_back((MortonCode(key) << 1) | (hit(rng) ? 1 : 0), key);
  }
  for (const auto& [code, key] : updates) tree.updateNode(key, (code & 1) != 0, true);
  return updates;
}

// Updating leaves in octree order along shared paths builds the tree OctoMap's updateNode builds,
// byte for byte, including clamping at the thresholds (keys updated many times over batches).
TEST(MapTree, UpdateLeavesInOrderBuildsUpdateNodesTree) {
  MapTree ours(0.05);
  octomap::OcTree octomaps(0.05);
  std::mt19937_64 rng(8);
  for (int batch = 0; batch < 30; ++batch) {
    auto updates = RandomBatch(rng, octomaps);
    std::sort(updates.begin(), updates.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    const float log_odds[2] = {ours.getProbMissLog(), ours.getProbHitLog()};
    ours.UpdateLeavesInOrder(
        updates.size(), [&](std::size_t i) { return updates[i].second; },
        [&](std::size_t i) { return log_odds[updates[i].first & 1]; });
  }
  FinishUpdates(ours);
  octomaps.updateInnerOccupancy();
  std::ostringstream a;
  std::ostringstream b;
  WriteOctomapBinary(ours, a);
  WriteOctomapBinary(octomaps, b);
  EXPECT_EQ(ours.size(), octomaps.size());
  EXPECT_TRUE(a.str() == b.str());
}

// Updates kept beside the tree (ApplyUpdates, octant by octant) and set into its leaves when it
// is read (SyncLeaves, here after some batches and not others, on 1 or 2 threads) build the tree
// updateNode builds, byte for byte: clamping, nodes created and their count included, .ot too.
// The .bt and .ot written from the leaves alone are those bytes too.
TEST(MapTree, UpdatesAppliedBesideTheTreeSyncToUpdateNodesTree) {
  for (const int threads : {1, 2}) {
    MapTree ours(0.05);
    octomap::OcTree octomaps(0.05);
    std::mt19937_64 rng(9);
    for (int batch = 0; batch < 30; ++batch) {
      std::vector<std::uint64_t> updates;
      for (const auto& update : RandomBatch(rng, octomaps)) updates.push_back(update.first);
      std::sort(updates.begin(), updates.end());
      const float log_odds[2] = {ours.getProbMissLog(), ours.getProbHitLog()};
      for (int o = 0; o < 8; ++o) {
        std::vector<std::uint64_t> octant;
        for (const std::uint64_t u : updates) {
          if (static_cast<int>(u >> 46) == o) octant.push_back(u);
        }
        ours.ApplyUpdates(o, octant, 1, log_odds);
      }
      if (batch % 7 == 3) ours.SyncLeaves(threads);
    }
    std::ostringstream from_leaves, full_from_leaves;
    ours.WriteBinaryFromLeaves(from_leaves);  // before the last sync: the leaves alone
    ours.WriteFullFromLeaves(full_from_leaves);
    FinishUpdates(ours, threads);
    FinishUpdates(ours, threads);  // nothing left to set: the same tree
    octomaps.updateInnerOccupancy();
    std::ostringstream a, b, full_a, full_b;
    WriteOctomapBinary(ours, a);
    WriteOctomapBinary(octomaps, b);
    (void)ours.write(full_a);
    (void)octomaps.write(full_b);
    EXPECT_EQ(ours.size(), octomaps.size()) << threads << " threads";
    EXPECT_TRUE(a.str() == b.str()) << threads << " threads";
    EXPECT_TRUE(full_a.str() == full_b.str()) << threads << " threads";
    EXPECT_TRUE(from_leaves.str() == b.str()) << threads << " threads";
    EXPECT_TRUE(full_from_leaves.str() == full_b.str()) << threads << " threads";
  }
  // No update, no root: a header alone, as OctoMap writes an empty tree.
  const MapTree empty(0.05);
  std::ostringstream a, b, full_a, full_b;
  empty.WriteBinaryFromLeaves(a);
  WriteOctomapBinary(empty, b);
  empty.WriteFullFromLeaves(full_a);
  (void)empty.write(full_b);
  EXPECT_EQ(a.str(), b.str());
  EXPECT_EQ(full_a.str(), full_b.str());
}

}  // namespace
}  // namespace sonarbench::mapping
