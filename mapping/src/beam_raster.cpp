#include "sonarbench/mapping/beam_raster.hpp"

#include <algorithm>
#include <bit>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace sonarbench::mapping {
namespace {

// The box of cells the rays may visit, and the bitmap index of a cell in it: x, y and z offsets
// from the box's low corner, each in a power-of-two field, so a step along an axis adds a
// constant and an index splits back into a key with shifts and masks.
struct Box {
  int low[3];
  unsigned shift_y;  // bits of the z field
  unsigned shift_x;  // bits of the y and z fields
  std::uint64_t cells;

  [[nodiscard]] std::uint64_t Index(const octomap::OcTreeKey& key) const {
    return (static_cast<std::uint64_t>(key[0] - low[0]) << shift_x) |
           (static_cast<std::uint64_t>(key[1] - low[1]) << shift_y) |
           static_cast<std::uint64_t>(key[2] - low[2]);
  }
  [[nodiscard]] std::uint64_t PackedKey(std::uint64_t index) const {
    const std::uint64_t x = (index >> shift_x) + static_cast<std::uint64_t>(low[0]);
    const std::uint64_t y = ((index >> shift_y) & ((std::uint64_t{1} << (shift_x - shift_y)) - 1)) +
                            static_cast<std::uint64_t>(low[1]);
    const std::uint64_t z =
        (index & ((std::uint64_t{1} << shift_y) - 1)) + static_cast<std::uint64_t>(low[2]);
    return (x << 32) | (y << 16) | z;
  }
};

// A box over the origin's and the end points' cells with two cells to spare on every side: a
// DDA step enters a cell at a ray parameter no larger than the segment's length, so a walk
// stays within one cell (rounding) of the segment's box.
Box MakeBox(std::span<const RayWalk> walks) {
  int low[3];
  int high[3];
  for (unsigned i = 0; i < 3; ++i) low[i] = high[i] = walks.front().origin_key[i];
  for (const RayWalk& walk : walks) {
    for (unsigned i = 0; i < 3; ++i) {
      low[i] = std::min(low[i], static_cast<int>(walk.end_key[i]));
      high[i] = std::max(high[i], static_cast<int>(walk.end_key[i]));
    }
  }
  constexpr int kSpare = 2;
  Box box{};
  unsigned bits[3];
  for (unsigned i = 0; i < 3; ++i) {
    box.low[i] = low[i] - kSpare;
    const auto extent = static_cast<unsigned>(high[i] - low[i] + 2 * kSpare + 1);
    bits[i] = static_cast<unsigned>(std::bit_width(extent - 1));
  }
  box.shift_y = bits[2];
  box.shift_x = bits[1] + bits[2];
  box.cells = std::uint64_t{1} << (bits[0] + bits[1] + bits[2]);
  return box;
}

// One bit per cell of the box.
bool IsMarked(const std::uint64_t* marks, std::uint64_t index) {
  return ((marks[index >> 6] >> (index & 63)) & 1u) != 0;
}
void Mark(std::uint64_t* marks, std::uint64_t index) {
  marks[index >> 6] |= std::uint64_t{1} << (index & 63);
}

// The portable kernel: one walk after another, each visit checked against the marks.
std::size_t WalkPortable(std::span<const RayWalk> walks, const Box& box, std::uint64_t* marks,
                         std::vector<std::uint64_t>& touched) {
  const std::uint64_t unit[3] = {std::uint64_t{1} << box.shift_x, std::uint64_t{1} << box.shift_y,
                                 1};
  std::size_t visits = 0;
  for (const RayWalk& walk : walks) {
    WalkRay(walk, box.Index(walk.origin_key), box.Index(walk.end_key), unit,
            [&](std::uint64_t index) {
              ++visits;
              if (!IsMarked(marks, index)) {
                Mark(marks, index);
                touched.push_back(index);
              }
            });
  }
  return visits;
}

#if defined(__x86_64__) && defined(__GNUC__)
#define SONARBENCH_HAVE_AVX512_KERNEL 1

constexpr std::size_t kLanes = 8;  // 64-bit lanes of an AVX-512 vector

// The AVX-512 kernel: eight walks side by side, one per 64-bit lane, each step of WalkRay done
// for all eight with masks instead of branches (the same IEEE additions and comparisons, so the
// same cells).
__attribute__((target("avx512f"))) std::size_t WalkAvx512(std::span<const RayWalk> walks,
                                                          const Box& box, std::uint64_t* marks,
                                                          std::vector<std::uint64_t>& touched) {
  // kGroups independent groups of eight walks step in turn: one group's step waits on its
  // previous step's comparisons (≈20 cycles), the others' fill that wait.
  constexpr std::size_t kGroups = 4;
  constexpr std::size_t kBatch = kGroups * kLanes;
  const std::int64_t unit[3] = {std::int64_t{1} << box.shift_x, std::int64_t{1} << box.shift_y, 1};
  const __m512i low6 = _mm512_set1_epi64(63);
  const __m512i one = _mm512_set1_epi64(1);
  std::size_t visits = 0;
  alignas(64) double lane_t[3][kBatch];
  alignas(64) double lane_delta[3][kBatch];
  alignas(64) std::int64_t lane_step[3][kBatch];
  alignas(64) std::int64_t lane_cell[kBatch];
  alignas(64) std::int64_t lane_last[kBatch];
  alignas(64) double lane_length[kBatch];
  alignas(64) std::uint64_t index[kLanes];
  for (std::size_t first = 0; first < walks.size(); first += kBatch) {
    const std::size_t count = std::min(kBatch, walks.size() - first);
    for (std::size_t l = 0; l < kBatch; ++l) {
      // Lanes without a walk repeat the last one, inactive.
      const RayWalk& w = walks[first + std::min(l, count - 1)];
      for (unsigned i = 0; i < 3; ++i) {
        lane_t[i][l] = w.t_max[i];
        lane_delta[i][l] = w.t_delta[i];
        lane_step[i][l] = unit[i] * w.step[i];
      }
      lane_cell[l] = static_cast<std::int64_t>(box.Index(w.origin_key));
      lane_last[l] = static_cast<std::int64_t>(box.Index(w.end_key));
      lane_length[l] = w.length;
    }
    // Every walk starts by visiting the origin's cell.
    const auto origin = static_cast<std::uint64_t>(lane_cell[0]);
    if (!IsMarked(marks, origin)) {
      Mark(marks, origin);
      touched.push_back(origin);
    }
    visits += count;
    __m512d tx[kGroups], ty[kGroups], tz[kGroups];
    __m512i cell[kGroups];
    __mmask8 active[kGroups];
    for (std::size_t g = 0; g < kGroups; ++g) {
      tx[g] = _mm512_load_pd(lane_t[0] + g * kLanes);
      ty[g] = _mm512_load_pd(lane_t[1] + g * kLanes);
      tz[g] = _mm512_load_pd(lane_t[2] + g * kLanes);
      cell[g] = _mm512_load_si512(lane_cell + g * kLanes);
      const std::size_t lanes = std::min(kLanes, count - std::min(count, g * kLanes));
      active[g] = static_cast<__mmask8>((1u << lanes) - 1);
    }
    for (;;) {
      unsigned any = 0;
      for (std::size_t g = 0; g < kGroups; ++g) {
        const std::size_t o = g * kLanes;
        const __mmask8 x_first = _mm512_cmp_pd_mask(tx[g], ty[g], _CMP_LT_OQ);
        const __mmask8 step_x = active[g] & x_first & _mm512_cmp_pd_mask(tx[g], tz[g], _CMP_LT_OQ);
        const __mmask8 step_y = active[g] & static_cast<__mmask8>(~x_first) &
                                _mm512_cmp_pd_mask(ty[g], tz[g], _CMP_LT_OQ);
        const __mmask8 step_z = active[g] & static_cast<__mmask8>(~(step_x | step_y));
        tx[g] = _mm512_mask_add_pd(tx[g], step_x, tx[g], _mm512_load_pd(lane_delta[0] + o));
        ty[g] = _mm512_mask_add_pd(ty[g], step_y, ty[g], _mm512_load_pd(lane_delta[1] + o));
        tz[g] = _mm512_mask_add_pd(tz[g], step_z, tz[g], _mm512_load_pd(lane_delta[2] + o));
        cell[g] =
            _mm512_mask_add_epi64(cell[g], step_x, cell[g], _mm512_load_si512(lane_step[0] + o));
        cell[g] =
            _mm512_mask_add_epi64(cell[g], step_y, cell[g], _mm512_load_si512(lane_step[1] + o));
        cell[g] =
            _mm512_mask_add_epi64(cell[g], step_z, cell[g], _mm512_load_si512(lane_step[2] + o));
        // min(tx, ty, tz) > length, as three comparisons.
        const __m512d length = _mm512_load_pd(lane_length + o);
        const __mmask8 done = _mm512_cmpeq_epi64_mask(cell[g], _mm512_load_si512(lane_last + o)) |
                              (_mm512_cmp_pd_mask(tx[g], length, _CMP_GT_OQ) &
                               _mm512_cmp_pd_mask(ty[g], length, _CMP_GT_OQ) &
                               _mm512_cmp_pd_mask(tz[g], length, _CMP_GT_OQ));
        active[g] = active[g] & static_cast<__mmask8>(~done);
        any |= active[g];
        // Most visits repeat a cell (≈70 per distinct cell of a beam): the words holding the
        // lanes' marks are gathered at once, and only lanes on an unmarked cell go on, one by
        // one, to set it.
        const __m512i words = _mm512_mask_i64gather_epi64(_mm512_setzero_si512(), active[g],
                                                          _mm512_maskz_srli_epi64(0xff, cell[g], 6),
                                                          static_cast<const void*>(marks), 8);
        const __m512i bits = _mm512_maskz_srlv_epi64(0xff, words, _mm512_and_si512(cell[g], low6));
        const __mmask8 fresh =
            active[g] & static_cast<__mmask8>(~_mm512_test_epi64_mask(bits, one));
        if (fresh != 0) {
          _mm512_store_si512(index, cell[g]);
          for (unsigned l = 0; l < kLanes; ++l) {
            // Two lanes may share a fresh cell: the mark is checked again.
            if (((fresh >> l) & 1u) != 0 && !IsMarked(marks, index[l])) {
              Mark(marks, index[l]);
              touched.push_back(index[l]);
            }
          }
        }
        visits += static_cast<std::size_t>(__builtin_popcount(active[g]));
      }
      if (any == 0) break;
    }
  }
  return visits;
}
#endif

}  // namespace

bool BeamRaster::HasVectorKernel() {
#ifdef SONARBENCH_HAVE_AVX512_KERNEL
  return __builtin_cpu_supports("avx512f") != 0;
#else
  return false;
#endif
}

std::size_t BeamRaster::Trace(const octomap::OcTree& tree, const octomap::point3d& origin,
                              std::span<const octomap::point3d> ends,
                              std::vector<std::uint64_t>& free_keys) {
  used_fallback_ = false;
  walks_.clear();
  RayWalk walk;
  if (!tree.coordToKeyChecked(origin, walk.origin_key)) return 0;
  for (const octomap::point3d& end : ends) {
    if (StartRayWalkFromKey(tree, origin, end, walk) && walk.origin_key != walk.end_key) {
      walks_.push_back(walk);
    }
  }
  if (walks_.empty()) return 0;
  const Box box = MakeBox(walks_);
  // Keys near the edge of the key range would put the spare cells outside it.
  const std::uint64_t extent[3] = {box.cells >> box.shift_x,
                                   std::uint64_t{1} << (box.shift_x - box.shift_y),
                                   std::uint64_t{1} << box.shift_y};
  bool near_edge = false;
  for (unsigned i = 0; i < 3; ++i) {
    near_edge |= box.low[i] < 0 || static_cast<std::uint64_t>(box.low[i]) + extent[i] > 0x10000;
  }
  if (box.cells > kMaxBoxCells || near_edge) return TraceOneByOne(free_keys);
  if (marks_.size() < box.cells / 64 + 1) marks_.resize(box.cells / 64 + 1, 0);
  std::uint64_t* const marks = marks_.data();
  touched_.clear();
  std::size_t visits = 0;
#ifdef SONARBENCH_HAVE_AVX512_KERNEL
  if (kernel_ == Kernel::kFastest && HasVectorKernel()) {
    visits = WalkAvx512(walks_, box, marks, touched_);
  } else {
    visits = WalkPortable(walks_, box, marks, touched_);
  }
#else
  visits = WalkPortable(walks_, box, marks, touched_);
#endif
  free_keys.reserve(free_keys.size() + touched_.size());
  for (const std::uint64_t index : touched_) {
    free_keys.push_back(box.PackedKey(index));
    marks[index >> 6] = 0;
  }
  return visits;
}

std::size_t BeamRaster::TraceOneByOne(std::vector<std::uint64_t>& free_keys) {
  used_fallback_ = true;
  seen_.clear();
  std::size_t visits = 0;
  for (const RayWalk& walk : walks_) {
    WalkRay(walk, PackKey(walk.origin_key), PackKey(walk.end_key), kPackedKeyUnit,
            [&](std::uint64_t packed) {
              ++visits;
              if (seen_.insert_packed(packed)) free_keys.push_back(packed);
            });
  }
  return visits;
}

}  // namespace sonarbench::mapping
