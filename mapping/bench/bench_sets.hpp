#pragma once

// The sets the benchmarks compare, with what each needs to be used as a mapper key set.
#include <absl/container/flat_hash_set.h>
#include <absl/hash/hash.h>

#include "beam_volume.hpp"
#include "key_set.hpp"

namespace sonarbench::mapping::bench {

/// abseil's flat set hashes keys with its own strong hash of the packed key (given OctoMap's
/// KeyHash it would inherit that hash's weak low bits).
struct AbslKeyHash {
  std::size_t operator()(const octomap::OcTreeKey& key) const {
    return absl::Hash<std::uint64_t>{}(PackKey(key));
  }
};
using AbslKeySet = absl::flat_hash_set<octomap::OcTreeKey, AbslKeyHash>;

using Linear = OpenKeySet<Probing::kLinear, Resize::kInPlace>;
using Quadratic = OpenKeySet<Probing::kQuadratic, Resize::kInPlace>;
using Double = OpenKeySet<Probing::kDouble, Resize::kInPlace>;
using QuadraticAllAtOnce = OpenKeySet<Probing::kQuadratic, Resize::kAllAtOnce>;
using QuadraticCached = OpenKeySet<Probing::kQuadratic, Resize::kInPlace, true>;

}  // namespace sonarbench::mapping::bench
