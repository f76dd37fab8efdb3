#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <unordered_set>
#include <vector>

#include "beam_volume.hpp"
#include "block_set.hpp"
#include "integrate.hpp"
#include "key_set.hpp"

namespace sonarbench::mapping {
namespace {

using Reference = std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash>;

// The set holds exactly the reference's keys: same size, every key found, iteration yields each
// key once and nothing else.
template <typename Set>
::testing::AssertionResult SameKeys(const Set& set, const Reference& reference) {
  if (set.size() != reference.size()) {
    return ::testing::AssertionFailure() << "size " << set.size() << " != " << reference.size();
  }
  Reference seen;
  for (const auto& key : set) {
    if (!reference.contains(key)) {
      return ::testing::AssertionFailure()
             << "iterates a key the reference lacks: " << key[0] << "," << key[1] << "," << key[2];
    }
    if (!seen.insert(key).second) {
      return ::testing::AssertionFailure()
             << "iterates a key twice: " << key[0] << "," << key[1] << "," << key[2];
    }
  }
  for (const auto& key : reference) {
    if (!set.contains(key)) return ::testing::AssertionFailure() << "lost a key";
  }
  if constexpr (requires { set.for_each_packed([](std::uint64_t) {}); }) {
    // The blockwise walk yields what the iterator yields, in the same order.
    std::vector<std::uint64_t> iterated;
    std::vector<std::uint64_t> walked;
    for (const auto& key : set) iterated.push_back(PackKey(key));
    set.for_each_packed([&walked](std::uint64_t packed) { walked.push_back(packed); });
    if (walked != iterated) {
      return ::testing::AssertionFailure() << "for_each_packed yields " << walked.size()
                                           << " keys, not the iterator's " << iterated.size();
    }
  }
  return ::testing::AssertionSuccess();
}

// Keys from a small cube (so operations hit existing keys often) or from the whole key range.
octomap::OcTreeKey RandomKey(std::mt19937_64& rng, bool clustered) {
  std::uniform_int_distribution<int> near(32768 - 12, 32768 + 12);
  std::uniform_int_distribution<int> any(0, 65535);
  auto pick = [&] { return static_cast<octomap::key_type>(clustered ? near(rng) : any(rng)); };
  return {pick(), pick(), pick()};
}

template <typename Set>
class KeySetProperty : public ::testing::Test {};

using Variants = ::testing::Types<OpenKeySet<Probing::kLinear, Resize::kAllAtOnce, false>,
                                  OpenKeySet<Probing::kLinear, Resize::kInPlace, false>,
                                  OpenKeySet<Probing::kQuadratic, Resize::kAllAtOnce, false>,
                                  OpenKeySet<Probing::kQuadratic, Resize::kInPlace, false>,
                                  OpenKeySet<Probing::kDouble, Resize::kAllAtOnce, false>,
                                  OpenKeySet<Probing::kDouble, Resize::kInPlace, false>,
                                  OpenKeySet<Probing::kLinear, Resize::kInPlace, true>,
                                  OpenKeySet<Probing::kQuadratic, Resize::kAllAtOnce, true>,
                                  OpenKeySet<Probing::kQuadratic, Resize::kInPlace, true>,
                                  OpenKeySet<Probing::kDouble, Resize::kInPlace, true>>;
TYPED_TEST_SUITE(KeySetProperty, Variants);

// A long random sequence of every operation, checked against std::unordered_set after each
// operation's result and, every 1000 operations, in full.
TYPED_TEST(KeySetProperty, MatchesUnorderedSetOnRandomOperations) {
  for (const bool clustered : {true, false}) {
    SCOPED_TRACE(clustered ? "clustered keys" : "keys from the whole range");
    std::mt19937_64 rng(clustered ? 1 : 2);
    TypeParam set;
    Reference reference;
    std::uniform_int_distribution<int> op(0, 99);
    for (int i = 0; i < 60000; ++i) {
      const octomap::OcTreeKey key = RandomKey(rng, clustered);
      const int o = op(rng);
      if (o < 50) {
        ASSERT_EQ(set.insert(key), reference.insert(key).second) << "insert, op " << i;
      } else if (o < 80) {
        ASSERT_EQ(set.erase(key), reference.erase(key) == 1) << "erase, op " << i;
      } else if (o < 95) {
        ASSERT_EQ(set.contains(key), reference.contains(key)) << "contains, op " << i;
      } else if (o < 97) {
        TypeParam other;
        Reference other_reference;
        for (int k = 0; k < 200; ++k) {
          const auto extra = RandomKey(rng, clustered);
          other.insert(extra);
          other_reference.insert(extra);
        }
        if (o == 95) {
          set.merge(other);
        } else {
          set.merge_without_reserve(other);
        }
        reference.insert(other_reference.begin(), other_reference.end());
      } else if (o < 99) {
        TypeParam other;
        for (int k = 0; k < 300; ++k) {
          const auto gone = RandomKey(rng, clustered);
          other.insert(gone);
          reference.erase(gone);
        }
        set.difference(other);
      } else if (rng() % 20 == 0) {
        set.clear();
        reference.clear();
      } else {
        set.reserve(set.size() + 500);
      }
      if (i % 1000 == 999) {
        ASSERT_TRUE(SameKeys(set, reference)) << "after op " << i;
      }
    }
    ASSERT_TRUE(SameKeys(set, reference));
    // Copies and moves keep the keys.
    const TypeParam copy = set;
    EXPECT_TRUE(SameKeys(copy, reference));
    TypeParam moved = std::move(set);
    EXPECT_TRUE(SameKeys(moved, reference));
  }
}

// Tombstones must not let a key in twice: erase a key that lies earlier on another key's probe
// path, then insert that other key again.
TYPED_TEST(KeySetProperty, NoDuplicateAfterErasures) {
  TypeParam set;
  std::vector<octomap::OcTreeKey> keys;
  for (int i = 0; i < 64; ++i) {
    keys.push_back({static_cast<octomap::key_type>(i), 7, 9});
    set.insert(keys.back());
  }
  for (int i = 0; i < 64; i += 2) set.erase(keys[static_cast<std::size_t>(i)]);
  for (int i = 1; i < 64; i += 2) EXPECT_FALSE(set.insert(keys[static_cast<std::size_t>(i)]));
  EXPECT_EQ(set.size(), 32u);
  std::size_t iterated = 0;
  for (const auto& key : set) iterated += key[1] == 7 ? 1 : 0;
  EXPECT_EQ(iterated, 32u);
}

TEST(OpenKeySet, PackingRoundTripsEveryCoordinate) {
  for (const int v : {0, 1, 255, 256, 32767, 32768, 65534, 65535}) {
    const auto k = static_cast<octomap::key_type>(v);
    for (const octomap::OcTreeKey& key :
         {octomap::OcTreeKey(k, 0, 0), octomap::OcTreeKey(0, k, 0), octomap::OcTreeKey(0, 0, k),
          octomap::OcTreeKey(k, k, k)}) {
      EXPECT_EQ(UnpackKey(PackKey(key)), key);
    }
  }
}

// In-place growth keeps only one table, grown: its peak is the final table; all-at-once holds
// the old and the new table together during the last resize, 1.5 times as much.
TEST(OpenKeySet, InPlaceResizeNeedsLessPeakMemory) {
  OpenKeySet<Probing::kQuadratic, Resize::kInPlace> in_place;
  OpenKeySet<Probing::kQuadratic, Resize::kAllAtOnce> all_at_once;
  std::mt19937_64 rng(3);
  for (int i = 0; i < 100000; ++i) {
    const auto key = RandomKey(rng, false);
    in_place.insert(key);
    all_at_once.insert(key);
  }
  ASSERT_EQ(in_place.capacity(), all_at_once.capacity());
  EXPECT_EQ(in_place.peak_bytes(), in_place.capacity() * sizeof(std::uint64_t));
  EXPECT_EQ(all_at_once.peak_bytes(), in_place.capacity() * sizeof(std::uint64_t) * 3 / 2);
}

// Inserting packed keys as a batch (with prefetching) leaves the set that inserting them one by
// one leaves, duplicates and growth included.
TEST(OpenKeySet, BatchInsertMatchesOneByOne) {
  std::mt19937_64 rng(9);
  OpenKeySet<Probing::kQuadratic, Resize::kInPlace> batched;
  Reference reference;
  for (int round = 0; round < 20; ++round) {
    std::vector<std::uint64_t> keys;
    for (int i = 0; i < 3000; ++i) {
      const auto key = RandomKey(rng, round % 2 == 0);
      keys.push_back(PackKey(key));
      reference.insert(key);
    }
    batched.insert_packed(std::span<const std::uint64_t>(keys));
    ASSERT_TRUE(SameKeys(batched, reference)) << "round " << round;
  }
}

// The recent-key filter never claims a key it was not given (a false "seen" would drop a cell
// from the map), and remembers the key it was given last.
TEST(RecentKeys, OnlyRemembersKeysItWasGiven) {
  std::mt19937_64 rng(10);
  RecentKeys recent;
  std::unordered_set<std::uint64_t> given;
  for (int i = 0; i < 200000; ++i) {
    const std::uint64_t packed = PackKey(RandomKey(rng, i % 3 != 0));
    if (recent.CheckAndRemember(packed)) {
      ASSERT_TRUE(given.contains(packed)) << i;
    }
    given.insert(packed);
    ASSERT_TRUE(recent.CheckAndRemember(packed));
  }
  recent.clear();
  for (const std::uint64_t packed : given) ASSERT_FALSE(recent.CheckAndRemember(packed));
}

// A block set holds exactly the keys given it, from one cube or the whole key range (its edges
// included), reports new keys as new, walks each key once, block by block in Morton order, and
// holds nothing of a batch after clear() (it is reused from batch to batch).
TEST(BlockKeySet, HoldsWhatAReferenceSetHoldsAndWalksBlocksInMortonOrder) {
  std::mt19937_64 rng(8);
  BlockKeySet set;
  for (const bool clustered : {true, false, true}) {
    set.clear();
    Reference reference;
    for (int i = 0; i < 40000; ++i) {
      octomap::OcTreeKey key = RandomKey(rng, clustered);
      if (i % 97 == 0) key = {0, 65535, static_cast<octomap::key_type>(i % 2 == 0 ? 0 : 65535)};
      ASSERT_EQ(set.insert(key), reference.insert(key).second) << i;
    }
    ASSERT_EQ(set.size(), reference.size());
    for (int i = 0; i < 20000; ++i) {
      const octomap::OcTreeKey key = RandomKey(rng, clustered);
      ASSERT_EQ(set.contains(key), reference.contains(key)) << i;
    }
    std::vector<std::uint64_t> walked;
    set.for_each_packed([&walked](std::uint64_t packed) { walked.push_back(packed); });
    ASSERT_EQ(walked.size(), reference.size());
    for (std::size_t i = 0; i < walked.size(); ++i) {
      ASSERT_TRUE(reference.contains(UnpackKey(walked[i])));
      const bool same_block =
          i > 0 && ((walked[i] ^ walked[i - 1]) & BlockKeySet::kOriginMask) == 0;
      if (same_block) {
        ASSERT_LT(MortonCode(UnpackKey(walked[i - 1])), MortonCode(UnpackKey(walked[i])));
      }
    }
  }
  set.clear();
  EXPECT_EQ(set.size(), 0u);
  EXPECT_TRUE(set.empty());
  EXPECT_FALSE(set.contains({32768, 32768, 32768}));
}

// A cell's index in its block is its Morton code's low nine bits, and back.
TEST(BlockKeySet, IndexInBlockIsTheLowBitsOfTheMortonCode) {
  const std::uint64_t origin = PackKey({800, 1608, 65528});
  for (unsigned index = 0; index < 512; ++index) {
    const std::uint64_t packed = BlockKeySet::KeyInBlock(origin, index);
    ASSERT_EQ(packed & BlockKeySet::kOriginMask, origin);
    ASSERT_EQ(BlockKeySet::IndexInBlock(packed), index);
    ASSERT_EQ(MortonCode(UnpackKey(packed)) & 511u, index);
  }
}

// The cells a beam marks do not depend on the set that collects them.
TEST(BeamCells, SameCellsInEverySet) {
  const SensorGeometry sensor;
  octomap::OcTree tree(0.05);
  Beam beam;
  beam.head_angle_rad = 1.1;
  beam.T_world_sonar.translation() = Eigen::Vector3d(0.31, -0.12, 0.45);
  const auto directions = BeamRayDirections(sensor, 32, 64);
  const std::vector<double> ranges{1.7, 2.4};
  BasicBeamCells<Reference> with_std;
  BasicBeamCells<KeyOpenSet> with_open;
  CastBeam(tree, beam, directions, ranges, 0.0, with_std);
  CastBeam(tree, beam, directions, ranges, 0.0, with_open);
  EXPECT_TRUE(SameKeys(with_open.free, with_std.free));
  EXPECT_TRUE(SameKeys(with_open.occupied, with_std.occupied));
  EXPECT_EQ(with_open.visits, with_std.visits);
}

// ForEachRayKey replays OctoMap's computeRayKeys exactly, on rays in every direction, and on rays
// ending on a cell's face or corner, where the walk can pass beside the end cell and stops at the
// segment's length.
TEST(ForEachRayKey, SameKeysAsOctomapComputeRayKeys) {
  octomap::OcTree tree(0.05);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<float> coordinate(-3.0f, 3.0f);
  octomap::KeyRay expected;
  for (int i = 0; i < 20000; ++i) {
    const octomap::point3d origin(coordinate(rng), coordinate(rng), coordinate(rng));
    // Every tenth ray runs along an axis, where the DDA's ties and zero steps matter.
    octomap::point3d end(coordinate(rng), coordinate(rng), coordinate(rng));
    if (i % 10 == 0) end = origin + octomap::point3d(0.0f, 0.0f, coordinate(rng));
    if (i % 10 >= 5) {
      for (unsigned a = 0; a < 3; ++a) end(a) = std::round(end(a) / 0.05f) * 0.05f;
    }
    ASSERT_TRUE(tree.computeRayKeys(origin, end, expected));
    std::vector<std::uint64_t> visited;
    ForEachRayKey(tree, origin, end, [&](std::uint64_t packed) { visited.push_back(packed); });
    ASSERT_EQ(visited.size(), expected.size()) << "ray " << i;
    std::size_t k = 0;
    for (const auto& key : expected) ASSERT_EQ(visited[k++], PackKey(key)) << "ray " << i;
  }
}

}  // namespace
}  // namespace sonarbench::mapping
