#include "sonarbench/mapping/beam_raster.hpp"

#include <algorithm>
#include <bit>
#include <limits>

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
  // previous step's comparisons (≈20 cycles), the others' fill that wait. The group loop is
  // unrolled so that each group's state stays in registers.
  constexpr std::size_t kGroups = 4;
  constexpr std::size_t kBatch = kGroups * kLanes;
  const std::int64_t unit[3] = {std::int64_t{1} << box.shift_x, std::int64_t{1} << box.shift_y, 1};
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
#pragma GCC unroll 4
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
        // Most visits repeat a cell (≈70 per distinct cell of a beam). Walks from one origin
        // stand in the same cell only after the same number of steps (each step is one cell
        // along one axis), and neighbouring rays sit in neighbouring lanes: a lane on the same
        // cell as the lane before it is not checked against the marks, being that lane's visit
        // again. The others are checked one by one (on these processors faster than a gather).
        const __m512i before = _mm512_maskz_alignr_epi64(0xff, cell[g], cell[g], 7);
        const __mmask8 repeat = _mm512_mask_cmpeq_epi64_mask(
            static_cast<__mmask8>(active[g] & (active[g] << 1)), cell[g], before);
        unsigned check = active[g] & static_cast<__mmask8>(~repeat);
        if (check != 0) {
          _mm512_store_si512(index, cell[g]);
          do {
            const unsigned l = static_cast<unsigned>(__builtin_ctz(check));
            check &= check - 1;
            if (!IsMarked(marks, index[l])) {
              Mark(marks, index[l]);
              touched.push_back(index[l]);
            }
          } while (check != 0);
        }
        visits += static_cast<std::size_t>(__builtin_popcount(active[g]));
      }
      if (any == 0) break;
    }
  }
  return visits;
}

// StartRayWalkFromKey for eight segments at a time: the float difference, the float norm (as
// OctoMap's Vector3::norm: float squares summed in float, the square root in double, rounded to
// float), the float division, then the double arithmetic of the borders and steps. The file is
// compiled without contraction into fused multiply-adds, so each operation rounds as the
// scalar code's does.
__attribute__((target("avx512f"))) void StartWalksAvx512(const octomap::OcTree& tree,
                                                         const octomap::point3d& origin,
                                                         const octomap::OcTreeKey& origin_key,
                                                         std::span<const octomap::point3d> ends,
                                                         std::vector<RayWalk>& walks) {
  const double resolution = tree.getResolution();
  const double factor = 1.0 / resolution;  // OcTreeBaseImpl's resolution_factor
  const auto max_val = static_cast<std::int64_t>(tree.coordToKey(0.0));  // tree_max_val
  // The cell border a walk first meets, per axis, for a step of +1 and of -1.
  double border_up[3];
  double border_down[3];
  for (unsigned i = 0; i < 3; ++i) {
    const double centre = tree.keyToCoord(origin_key[i]);
    border_up[i] = centre + static_cast<float>(1 * resolution * 0.5);
    border_down[i] = centre + static_cast<float>(-1 * resolution * 0.5);
  }
  const __m512d v_factor = _mm512_set1_pd(factor);
  const __m512d v_resolution = _mm512_set1_pd(resolution);
  const __m512d v_max = _mm512_set1_pd(std::numeric_limits<double>::max());
  const __m512i v_max_val = _mm512_set1_epi64(max_val);
  const __m512i v_key_limit = _mm512_set1_epi64(2 * max_val);
  alignas(64) float coordinate[3][kLanes];
  alignas(64) std::int64_t key[3][kLanes];
  alignas(64) double t_max[3][kLanes];
  alignas(64) double t_delta[3][kLanes];
  alignas(64) double length[kLanes];
  for (std::size_t first = 0; first < ends.size(); first += kLanes) {
    const std::size_t count = std::min(kLanes, ends.size() - first);
    for (std::size_t l = 0; l < kLanes; ++l) {
      const octomap::point3d& end = ends[first + std::min(l, count - 1)];
      for (unsigned i = 0; i < 3; ++i) coordinate[i][l] = end(i);
    }
    __mmask8 valid = static_cast<__mmask8>((1u << count) - 1);
    __m256 d[3];
    for (unsigned i = 0; i < 3; ++i) {
      // coordToKeyChecked: (int) floor(resolution_factor * coordinate) + tree_max_val, in
      // [0, 2 tree_max_val).
      const __m256 c = _mm256_load_ps(coordinate[i]);
      const __m512d scaled =
          _mm512_maskz_roundscale_pd(0xff, _mm512_mul_pd(v_factor, _mm512_maskz_cvtps_pd(0xff, c)),
                                     _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
      // (int): outside the int range the conversion gives INT_MIN, which fails the check (as
      // the scalar conversion does on this processor).
      const __m512i k = _mm512_add_epi64(
          _mm512_maskz_cvtepi32_epi64(0xff, _mm512_maskz_cvttpd_epi32(0xff, scaled)), v_max_val);
      valid &= _mm512_cmpge_epi64_mask(k, _mm512_setzero_si512()) &
               _mm512_cmplt_epi64_mask(k, v_key_limit);
      _mm512_store_si512(key[i], k);
      d[i] = _mm256_sub_ps(c, _mm256_set1_ps(origin(i)));
    }
    // Vector3::norm(), rounded to float as StartRayWalkFromKey does.
    const __m256 norm_sq =
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(d[0], d[0]), _mm256_mul_ps(d[1], d[1])),
                      _mm256_mul_ps(d[2], d[2]));
    const __m256 len = _mm512_maskz_cvtpd_ps(
        0xff, _mm512_maskz_sqrt_pd(0xff, _mm512_maskz_cvtps_pd(0xff, norm_sq)));
    _mm512_store_pd(length, _mm512_maskz_cvtps_pd(0xff, len));
    __mmask8 up[3];
    __mmask8 down[3];
    for (unsigned i = 0; i < 3; ++i) {
      const __m512d u = _mm512_maskz_cvtps_pd(0xff, _mm256_div_ps(d[i], len));  // exact widening
      up[i] = _mm512_cmp_pd_mask(u, _mm512_setzero_pd(), _CMP_GT_OQ);
      down[i] = _mm512_cmp_pd_mask(u, _mm512_setzero_pd(), _CMP_LT_OQ);
      const __m512d border =
          _mm512_mask_blend_pd(up[i], _mm512_set1_pd(border_down[i]), _mm512_set1_pd(border_up[i]));
      const __m512d from = _mm512_set1_pd(static_cast<double>(origin(i)));
      const auto moving = static_cast<__mmask8>(up[i] | down[i]);
      _mm512_store_pd(t_max[i], _mm512_mask_div_pd(v_max, moving, _mm512_sub_pd(border, from), u));
      _mm512_store_pd(t_delta[i],
                      _mm512_mask_div_pd(v_max, moving, v_resolution, _mm512_abs_pd(u)));
    }
    for (std::size_t l = 0; l < count; ++l) {
      if (((valid >> l) & 1u) == 0) continue;
      RayWalk walk;
      walk.origin_key = origin_key;
      for (unsigned i = 0; i < 3; ++i) {
        walk.end_key[i] = static_cast<octomap::key_type>(key[i][l]);
      }
      if (walk.end_key == origin_key) continue;
      for (unsigned i = 0; i < 3; ++i) {
        walk.t_max[i] = t_max[i][l];
        walk.t_delta[i] = t_delta[i][l];
        walk.step[i] = static_cast<int>((up[i] >> l) & 1u) - static_cast<int>((down[i] >> l) & 1u);
      }
      walk.length = length[l];
      walks.push_back(walk);
    }
  }
}
#endif

}  // namespace

void StartRayWalks(const octomap::OcTree& tree, const octomap::point3d& origin,
                   std::span<const octomap::point3d> ends, bool vector,
                   std::vector<RayWalk>& walks) {
  RayWalk walk;
  if (!tree.coordToKeyChecked(origin, walk.origin_key)) return;
#ifdef SONARBENCH_HAVE_AVX512_KERNEL
  if (vector && BeamRaster::HasVectorKernel()) {
    StartWalksAvx512(tree, origin, walk.origin_key, ends, walks);
    return;
  }
#endif
  for (const octomap::point3d& end : ends) {
    if (StartRayWalkFromKey(tree, origin, end, walk) && walk.origin_key != walk.end_key) {
      walks.push_back(walk);
    }
  }
}

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
  StartRayWalks(tree, origin, ends, kernel_ == Kernel::kFastest, walks_);
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
