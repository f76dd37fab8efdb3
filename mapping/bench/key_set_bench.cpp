// Google Benchmark of the key sets, the seed paper's figures 1-7 measured here:
//   fig 1  insert time per probing scheme          BM_Insert<Linear|Quadratic|Double>
//   fig 2  the cost of resizes                     BM_Insert vs BM_InsertReserved
//   fig 3  collisions                              counter "collisions/insert"
//   fig 4  merge with and without the reserve      BM_Merge vs BM_MergeNoReserve
//   fig 5  in-place vs all-at-once resize          BM_Insert<Quadratic> vs <QuadraticAllAtOnce>,
//                                                  counter "peak_MiB"
//   fig 6/7 against std::unordered_set (OctoMap's KeySet) without and with reserve, and against
//          abseil's flat_hash_set.
// Keys are distinct cells of a 256 x 256 x 64 block, in random order, like a map's cells.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "bench_sets.hpp"

namespace sonarbench::mapping::bench {
namespace {

const std::vector<octomap::OcTreeKey>& Keys(std::size_t n) {
  static std::vector<octomap::OcTreeKey> keys = [] {
    std::vector<std::uint32_t> index(256u * 256u * 64u);
    std::iota(index.begin(), index.end(), 0u);
    std::shuffle(index.begin(), index.end(), std::mt19937_64(42));
    std::vector<octomap::OcTreeKey> out;
    out.reserve(index.size());
    for (const std::uint32_t i : index) {
      out.emplace_back(static_cast<octomap::key_type>(32640 + (i & 255)),
                       static_cast<octomap::key_type>(32640 + ((i >> 8) & 255)),
                       static_cast<octomap::key_type>(32736 + (i >> 16)));
    }
    return out;
  }();
  static_cast<void>(n);
  return keys;
}

template <typename Set>
void Reserve(Set& set, std::size_t n) {
  set.reserve(n);
}

template <typename Set>
void BM_Insert(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const auto& keys = Keys(n);
  double collisions = 0;
  double peak = 0;
  for (auto _ : state) {
    Set set;
    for (std::size_t i = 0; i < n; ++i) set.insert(keys[i]);
    benchmark::DoNotOptimize(set);
    if constexpr (requires { set.collisions(); }) {
      collisions = static_cast<double>(set.collisions());
      peak = static_cast<double>(set.peak_bytes());
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
  if constexpr (requires(Set s) { s.collisions(); }) {
    state.counters["collisions/insert"] = collisions / static_cast<double>(n);
    state.counters["peak_MiB"] = peak / (1 << 20);
  }
}

template <typename Set>
void BM_InsertReserved(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const auto& keys = Keys(n);
  for (auto _ : state) {
    Set set;
    Reserve(set, n);
    for (std::size_t i = 0; i < n; ++i) set.insert(keys[i]);
    benchmark::DoNotOptimize(set);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
}

// Merges two sets of n keys that share half their keys.
template <typename Set, bool kReserve>
void BM_Merge(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const auto& keys = Keys(n);
  Set a;
  Set b;
  for (std::size_t i = 0; i < n; ++i) {
    a.insert(keys[i]);
    b.insert(keys[i + n / 2]);
  }
  for (auto _ : state) {
    state.PauseTiming();
    Set target = a;
    state.ResumeTiming();
    if constexpr (kReserve) {
      target.merge(b);
    } else {
      target.merge_without_reserve(b);
    }
    benchmark::DoNotOptimize(target);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
}

constexpr std::int64_t kMin = 1 << 16;
constexpr std::int64_t kMax = 1 << 22;  // ≈ 4 M, the paper's insert count

#define SONARBENCH_SETS(BM)                  \
  BENCHMARK_TEMPLATE(BM, Linear)             \
      ->RangeMultiplier(4)                   \
      ->Range(kMin, kMax)                    \
      ->Unit(benchmark::kMillisecond);       \
  BENCHMARK_TEMPLATE(BM, Quadratic)          \
      ->RangeMultiplier(4)                   \
      ->Range(kMin, kMax)                    \
      ->Unit(benchmark::kMillisecond);       \
  BENCHMARK_TEMPLATE(BM, Double)             \
      ->RangeMultiplier(4)                   \
      ->Range(kMin, kMax)                    \
      ->Unit(benchmark::kMillisecond);       \
  BENCHMARK_TEMPLATE(BM, QuadraticAllAtOnce) \
      ->RangeMultiplier(4)                   \
      ->Range(kMin, kMax)                    \
      ->Unit(benchmark::kMillisecond);       \
  BENCHMARK_TEMPLATE(BM, QuadraticCached)    \
      ->RangeMultiplier(4)                   \
      ->Range(kMin, kMax)                    \
      ->Unit(benchmark::kMillisecond);       \
  BENCHMARK_TEMPLATE(BM, KeySet)             \
      ->RangeMultiplier(4)                   \
      ->Range(kMin, kMax)                    \
      ->Unit(benchmark::kMillisecond);       \
  BENCHMARK_TEMPLATE(BM, AbslKeySet)         \
      ->RangeMultiplier(4)                   \
      ->Range(kMin, kMax)                    \
      ->Unit(benchmark::kMillisecond);

SONARBENCH_SETS(BM_Insert)
SONARBENCH_SETS(BM_InsertReserved)
BENCHMARK_TEMPLATE(BM_Merge, Quadratic, true)
    ->RangeMultiplier(4)
    ->Range(kMin, kMax / 4)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Merge, Quadratic, false)
    ->RangeMultiplier(4)
    ->Range(kMin, kMax / 4)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace sonarbench::mapping::bench

BENCHMARK_MAIN();
