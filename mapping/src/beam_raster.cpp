#include "beam_raster.hpp"

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
// A visit to a cell: its mark set and its index kept, unless it was marked already.
void Visit(std::uint64_t* marks, std::vector<std::uint64_t>& touched, std::uint64_t index) {
  if (!IsMarked(marks, index)) {
    Mark(marks, index);
    touched.push_back(index);
  }
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
              Visit(marks, touched, index);
            });
  }
  return visits;
}

#if defined(__x86_64__) && defined(__GNUC__)
#define SONARBENCH_HAVE_AVX512_KERNEL 1

constexpr std::size_t kLanes = 8;  // 64-bit lanes of an AVX-512 vector

// A batch of walks laid out by lane for the vector kernels, each array 64-byte aligned.
template <std::size_t kBatch>
struct WalkLanes {
  alignas(64) double t[3][kBatch];
  alignas(64) double delta[3][kBatch];
  alignas(64) std::int64_t step[3][kBatch];  // the index's change per step along each axis
  alignas(64) std::int64_t cell[kBatch];
  alignas(64) std::int64_t last[kBatch];
  alignas(64) double length[kBatch];

  // Lays out walks[first, first + kBatch), as many as there are, and returns how many; lanes
  // without a walk repeat the last one (the kernels keep them inactive).
  std::size_t Fill(std::span<const RayWalk> walks, std::size_t first, const Box& box) {
    const std::int64_t unit[3] = {std::int64_t{1} << box.shift_x, std::int64_t{1} << box.shift_y,
                                  1};
    const std::size_t count = std::min(kBatch, walks.size() - first);
    for (std::size_t l = 0; l < kBatch; ++l) {
      const RayWalk& w = walks[first + std::min(l, count - 1)];
      for (unsigned i = 0; i < 3; ++i) {
        t[i][l] = w.t_max[i];
        delta[i][l] = w.t_delta[i];
        step[i][l] = unit[i] * w.step[i];
      }
      cell[l] = static_cast<std::int64_t>(box.Index(w.origin_key));
      last[l] = static_cast<std::int64_t>(box.Index(w.end_key));
      length[l] = w.length;
    }
    return count;
  }
};

// Visits the cells (`index`) of the lanes whose bits are set in `check`, lowest lane first.
void VisitLanes(unsigned check, const std::uint64_t* index, std::uint64_t* marks,
                std::vector<std::uint64_t>& touched) {
  while (check != 0) {
    const auto l = static_cast<unsigned>(__builtin_ctz(check));
    check &= check - 1;
    Visit(marks, touched, index[l]);
  }
}

// One group of eight walks of the AVX-512 kernel: its state, kept in registers.
struct Group512 {
  __m512d tx, ty, tz;
  __m512i cell;
  __mmask8 active;
};

// The group of walks [o, o + 8) of `batch`, its lanes past `count` inactive.
template <std::size_t kBatch>
__attribute__((target("avx512f"), always_inline)) inline Group512 LoadGroup512(
    const WalkLanes<kBatch>& batch, std::size_t o, std::size_t count) {
  const std::size_t lanes = std::min(kLanes, count - std::min(count, o));
  return {_mm512_load_pd(batch.t[0] + o), _mm512_load_pd(batch.t[1] + o),
          _mm512_load_pd(batch.t[2] + o), _mm512_load_si512(batch.cell + o),
          static_cast<__mmask8>((1u << lanes) - 1)};
}

// One step of WalkRay for each active walk of the group [o, o + 8) of `batch`, with masks
// instead of branches (the same IEEE additions and comparisons, so the same cells). Visits the
// cells stepped into, counts them in `visits` and returns the lanes still active.
template <std::size_t kBatch>
__attribute__((target("avx512f"), always_inline)) inline unsigned StepGroup512(
    Group512& g, const WalkLanes<kBatch>& batch, std::size_t o, std::uint64_t* marks,
    std::vector<std::uint64_t>& touched, std::size_t& visits) {
  const __mmask8 x_first = _mm512_cmp_pd_mask(g.tx, g.ty, _CMP_LT_OQ);
  const __mmask8 step_x = g.active & x_first & _mm512_cmp_pd_mask(g.tx, g.tz, _CMP_LT_OQ);
  const __mmask8 step_y =
      g.active & static_cast<__mmask8>(~x_first) & _mm512_cmp_pd_mask(g.ty, g.tz, _CMP_LT_OQ);
  const __mmask8 step_z = g.active & static_cast<__mmask8>(~(step_x | step_y));
  g.tx = _mm512_mask_add_pd(g.tx, step_x, g.tx, _mm512_load_pd(batch.delta[0] + o));
  g.ty = _mm512_mask_add_pd(g.ty, step_y, g.ty, _mm512_load_pd(batch.delta[1] + o));
  g.tz = _mm512_mask_add_pd(g.tz, step_z, g.tz, _mm512_load_pd(batch.delta[2] + o));
  g.cell = _mm512_mask_add_epi64(g.cell, step_x, g.cell, _mm512_load_si512(batch.step[0] + o));
  g.cell = _mm512_mask_add_epi64(g.cell, step_y, g.cell, _mm512_load_si512(batch.step[1] + o));
  g.cell = _mm512_mask_add_epi64(g.cell, step_z, g.cell, _mm512_load_si512(batch.step[2] + o));
  // min(tx, ty, tz) > length, as three comparisons.
  const __m512d length = _mm512_load_pd(batch.length + o);
  const __mmask8 done =
      _mm512_cmpeq_epi64_mask(g.cell, _mm512_load_si512(batch.last + o)) |
      (_mm512_cmp_pd_mask(g.tx, length, _CMP_GT_OQ) & _mm512_cmp_pd_mask(g.ty, length, _CMP_GT_OQ) &
       _mm512_cmp_pd_mask(g.tz, length, _CMP_GT_OQ));
  g.active = g.active & static_cast<__mmask8>(~done);
  // Most visits repeat a cell (≈70 per distinct cell of a beam). Walks from one origin stand in
  // the same cell only after the same number of steps (each step is one cell along one axis),
  // and neighbouring rays sit in neighbouring lanes: a lane on the same cell as the lane before
  // it is not checked against the marks, being that lane's visit again. The others are checked
  // one by one (on these processors faster than a gather).
  const __m512i before = _mm512_maskz_alignr_epi64(0xff, g.cell, g.cell, 7);
  const __mmask8 repeat = _mm512_mask_cmpeq_epi64_mask(
      static_cast<__mmask8>(g.active & (g.active << 1)), g.cell, before);
  const unsigned check = g.active & static_cast<__mmask8>(~repeat);
  if (check != 0) {
    alignas(64) std::uint64_t index[kLanes];
    _mm512_store_si512(index, g.cell);
    VisitLanes(check, index, marks, touched);
  }
  visits += static_cast<std::size_t>(__builtin_popcount(g.active));
  return g.active;
}

// The AVX-512 kernel: eight walks side by side, one per 64-bit lane, each stepped by
// StepGroup512.
__attribute__((target("avx512f"))) std::size_t WalkAvx512(std::span<const RayWalk> walks,
                                                          const Box& box, std::uint64_t* marks,
                                                          std::vector<std::uint64_t>& touched) {
  // kGroups independent groups of eight walks step in turn: one group's step waits on its
  // previous step's comparisons (≈20 cycles), the others' fill that wait. The group loop is
  // unrolled so that each group's state stays in registers.
  constexpr std::size_t kGroups = 4;
  constexpr std::size_t kBatch = kGroups * kLanes;
  std::size_t visits = 0;
  WalkLanes<kBatch> batch;
  for (std::size_t first = 0; first < walks.size(); first += kBatch) {
    const std::size_t count = batch.Fill(walks, first, box);
    // Every walk starts by visiting the origin's cell.
    Visit(marks, touched, static_cast<std::uint64_t>(batch.cell[0]));
    visits += count;
    Group512 group[kGroups];
    for (std::size_t g = 0; g < kGroups; ++g) group[g] = LoadGroup512(batch, g * kLanes, count);
    for (;;) {
      unsigned any = 0;
#pragma GCC unroll 4
      for (std::size_t g = 0; g < kGroups; ++g) {
        any |= StepGroup512(group[g], batch, g * kLanes, marks, touched, visits);
      }
      if (any == 0) break;
    }
  }
  return visits;
}

// Four 64-bit integers from 32-byte aligned memory.
__attribute__((target("avx2"), always_inline)) inline __m256i LoadLanes(const std::int64_t* p) {
  return _mm256_load_si256(reinterpret_cast<const __m256i*>(p));
}

constexpr std::size_t kLanes4 = 4;  // 64-bit lanes of an AVX2 vector

// One group of four walks of the AVX2 kernel, its masks held as vector lanes of all ones.
struct Group256 {
  __m256d tx, ty, tz;
  __m256i cell;
  __m256d active;
};

// The group of walks [o, o + 4) of `batch`, its lanes past `count` inactive.
template <std::size_t kBatch>
__attribute__((target("avx2"), always_inline)) inline Group256 LoadGroup256(
    const WalkLanes<kBatch>& batch, std::size_t o, std::size_t count) {
  const std::size_t lanes = std::min(kLanes4, count - std::min(count, o));
  const __m256i lane_number = _mm256_set_epi64x(3, 2, 1, 0);
  return {_mm256_load_pd(batch.t[0] + o), _mm256_load_pd(batch.t[1] + o),
          _mm256_load_pd(batch.t[2] + o), LoadLanes(batch.cell + o),
          _mm256_castsi256_pd(_mm256_cmpgt_epi64(
              _mm256_set1_epi64x(static_cast<std::int64_t>(lanes)), lane_number))};
}

// StepGroup512 on four lanes: the masks' and, andnot and or as vector operations, the masked
// additions as blends (doubles: the same sum or the same value, bit for bit) or additions of a
// step and-ed with the mask (integers).
template <std::size_t kBatch>
__attribute__((target("avx2"), always_inline)) inline unsigned StepGroup256(
    Group256& g, const WalkLanes<kBatch>& batch, std::size_t o, std::uint64_t* marks,
    std::vector<std::uint64_t>& touched, std::size_t& visits) {
  const __m256d x_first = _mm256_cmp_pd(g.tx, g.ty, _CMP_LT_OQ);
  const __m256d step_x =
      _mm256_and_pd(_mm256_and_pd(g.active, x_first), _mm256_cmp_pd(g.tx, g.tz, _CMP_LT_OQ));
  const __m256d step_y =
      _mm256_and_pd(_mm256_andnot_pd(x_first, g.active), _mm256_cmp_pd(g.ty, g.tz, _CMP_LT_OQ));
  const __m256d step_z = _mm256_andnot_pd(_mm256_or_pd(step_x, step_y), g.active);
  g.tx = _mm256_blendv_pd(g.tx, _mm256_add_pd(g.tx, _mm256_load_pd(batch.delta[0] + o)), step_x);
  g.ty = _mm256_blendv_pd(g.ty, _mm256_add_pd(g.ty, _mm256_load_pd(batch.delta[1] + o)), step_y);
  g.tz = _mm256_blendv_pd(g.tz, _mm256_add_pd(g.tz, _mm256_load_pd(batch.delta[2] + o)), step_z);
  g.cell = _mm256_add_epi64(
      g.cell, _mm256_and_si256(_mm256_castpd_si256(step_x), LoadLanes(batch.step[0] + o)));
  g.cell = _mm256_add_epi64(
      g.cell, _mm256_and_si256(_mm256_castpd_si256(step_y), LoadLanes(batch.step[1] + o)));
  g.cell = _mm256_add_epi64(
      g.cell, _mm256_and_si256(_mm256_castpd_si256(step_z), LoadLanes(batch.step[2] + o)));
  const __m256d length = _mm256_load_pd(batch.length + o);
  const __m256d done =
      _mm256_or_pd(_mm256_castsi256_pd(_mm256_cmpeq_epi64(g.cell, LoadLanes(batch.last + o))),
                   _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(g.tx, length, _CMP_GT_OQ),
                                               _mm256_cmp_pd(g.ty, length, _CMP_GT_OQ)),
                                 _mm256_cmp_pd(g.tz, length, _CMP_GT_OQ)));
  g.active = _mm256_andnot_pd(done, g.active);
  const auto bits = static_cast<unsigned>(_mm256_movemask_pd(g.active));
  // Lane l against lane l - 1 (lane 0 against lane 3, which the mask leaves out).
  const __m256i before = _mm256_permute4x64_epi64(g.cell, _MM_SHUFFLE(2, 1, 0, 3));
  const auto repeat = static_cast<unsigned>(
      _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpeq_epi64(g.cell, before))));
  const unsigned check = bits & ~(repeat & bits & (bits << 1));
  if (check != 0) {
    alignas(32) std::uint64_t index[kLanes4];
    _mm256_store_si256(reinterpret_cast<__m256i*>(index), g.cell);
    VisitLanes(check, index, marks, touched);
  }
  visits += static_cast<std::size_t>(__builtin_popcount(bits));
  return bits;
}

// The AVX2 kernel, for processors without AVX-512: WalkAvx512 on four 64-bit lanes.
__attribute__((target("avx2"))) std::size_t WalkAvx2(std::span<const RayWalk> walks, const Box& box,
                                                     std::uint64_t* marks,
                                                     std::vector<std::uint64_t>& touched) {
  constexpr std::size_t kGroups = 4;
  constexpr std::size_t kBatch = kGroups * kLanes4;
  std::size_t visits = 0;
  WalkLanes<kBatch> batch;
  for (std::size_t first = 0; first < walks.size(); first += kBatch) {
    const std::size_t count = batch.Fill(walks, first, box);
    // Every walk starts by visiting the origin's cell.
    Visit(marks, touched, static_cast<std::uint64_t>(batch.cell[0]));
    visits += count;
    Group256 group[kGroups];
    for (std::size_t g = 0; g < kGroups; ++g) group[g] = LoadGroup256(batch, g * kLanes4, count);
    for (;;) {
      unsigned any = 0;
#pragma GCC unroll 4
      for (std::size_t g = 0; g < kGroups; ++g) {
        any |= StepGroup256(group[g], batch, g * kLanes4, marks, touched, visits);
      }
      if (any == 0) break;
    }
  }
  return visits;
}

// Eight segments from one origin laid out by lane, as StartWalksAvx512 computes them.
struct StartLanes {
  alignas(64) float coordinate[3][kLanes];  // the segments' ends
  alignas(64) std::int64_t key[3][kLanes];  // the ends' keys
  alignas(64) double t_max[3][kLanes];
  alignas(64) double t_delta[3][kLanes];
  alignas(64) double length[kLanes];
  __mmask8 up[3];    // lanes stepping +1 along each axis
  __mmask8 down[3];  // and -1
};

// coordToKeyChecked for the ends of `lanes` into lanes.key: (int) floor(resolution_factor *
// coordinate) + tree_max_val, valid in [0, 2 tree_max_val); returns the valid lanes. `d` gets
// each end's float difference from `origin`.
__attribute__((target("avx512f"), always_inline)) inline __mmask8 EndKeysAvx512(
    double factor, std::int64_t max_val, const octomap::point3d& origin, StartLanes& lanes,
    __m256 d[3]) {
  __mmask8 valid = 0xff;
  for (unsigned i = 0; i < 3; ++i) {
    const __m256 c = _mm256_load_ps(lanes.coordinate[i]);
    const __m512d scaled = _mm512_maskz_roundscale_pd(
        0xff, _mm512_mul_pd(_mm512_set1_pd(factor), _mm512_maskz_cvtps_pd(0xff, c)),
        _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    // (int): outside the int range the conversion gives INT_MIN, which fails the check (as
    // the scalar conversion does on this processor).
    const __m512i k =
        _mm512_add_epi64(_mm512_maskz_cvtepi32_epi64(0xff, _mm512_maskz_cvttpd_epi32(0xff, scaled)),
                         _mm512_set1_epi64(max_val));
    valid &= _mm512_cmpge_epi64_mask(k, _mm512_setzero_si512()) &
             _mm512_cmplt_epi64_mask(k, _mm512_set1_epi64(2 * max_val));
    _mm512_store_si512(lanes.key[i], k);
    d[i] = _mm256_sub_ps(c, _mm256_set1_ps(origin(i)));
  }
  return valid;
}

// The walks' lengths, steps and borders from the differences `d`: the float norm (as OctoMap's
// Vector3::norm: float squares summed in float, the square root in double, rounded to float),
// the float division, then the double arithmetic of the borders and steps.
__attribute__((target("avx512f"), always_inline)) inline void WalkStartsAvx512(
    const __m256 d[3], const octomap::point3d& origin, const double border_up[3],
    const double border_down[3], double resolution, StartLanes& lanes) {
  const __m256 norm_sq =
      _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(d[0], d[0]), _mm256_mul_ps(d[1], d[1])),
                    _mm256_mul_ps(d[2], d[2]));
  const __m256 len =
      _mm512_maskz_cvtpd_ps(0xff, _mm512_maskz_sqrt_pd(0xff, _mm512_maskz_cvtps_pd(0xff, norm_sq)));
  _mm512_store_pd(lanes.length, _mm512_maskz_cvtps_pd(0xff, len));
  const __m512d v_max = _mm512_set1_pd(std::numeric_limits<double>::max());
  for (unsigned i = 0; i < 3; ++i) {
    const __m512d u = _mm512_maskz_cvtps_pd(0xff, _mm256_div_ps(d[i], len));  // exact widening
    lanes.up[i] = _mm512_cmp_pd_mask(u, _mm512_setzero_pd(), _CMP_GT_OQ);
    lanes.down[i] = _mm512_cmp_pd_mask(u, _mm512_setzero_pd(), _CMP_LT_OQ);
    const __m512d border = _mm512_mask_blend_pd(lanes.up[i], _mm512_set1_pd(border_down[i]),
                                                _mm512_set1_pd(border_up[i]));
    const __m512d from = _mm512_set1_pd(static_cast<double>(origin(i)));
    const auto moving = static_cast<__mmask8>(lanes.up[i] | lanes.down[i]);
    _mm512_store_pd(lanes.t_max[i],
                    _mm512_mask_div_pd(v_max, moving, _mm512_sub_pd(border, from), u));
    _mm512_store_pd(lanes.t_delta[i], _mm512_mask_div_pd(v_max, moving, _mm512_set1_pd(resolution),
                                                         _mm512_abs_pd(u)));
  }
}

// The walks of the first `count` lanes whose keys are `valid` and whose end is not the origin's
// cell, appended to `walks` in lane order.
void AppendWalks(const StartLanes& lanes, std::size_t count, unsigned valid,
                 const octomap::OcTreeKey& origin_key, std::vector<RayWalk>& walks) {
  for (std::size_t l = 0; l < count; ++l) {
    if (((valid >> l) & 1u) == 0) continue;
    RayWalk walk;
    walk.origin_key = origin_key;
    for (unsigned i = 0; i < 3; ++i) {
      walk.end_key[i] = static_cast<octomap::key_type>(lanes.key[i][l]);
    }
    if (walk.end_key == origin_key) continue;
    for (unsigned i = 0; i < 3; ++i) {
      walk.t_max[i] = lanes.t_max[i][l];
      walk.t_delta[i] = lanes.t_delta[i][l];
      walk.step[i] =
          static_cast<int>((lanes.up[i] >> l) & 1u) - static_cast<int>((lanes.down[i] >> l) & 1u);
    }
    walk.length = lanes.length[l];
    walks.push_back(walk);
  }
}

// StartRayWalkFromKey for eight segments at a time, each operation rounding as the scalar
// code's does (the file is compiled without contraction into fused multiply-adds).
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
  StartLanes lanes;
  for (std::size_t first = 0; first < ends.size(); first += kLanes) {
    const std::size_t count = std::min(kLanes, ends.size() - first);
    for (std::size_t l = 0; l < kLanes; ++l) {
      const octomap::point3d& end = ends[first + std::min(l, count - 1)];
      for (unsigned i = 0; i < 3; ++i) lanes.coordinate[i][l] = end(i);
    }
    __m256 d[3];
    const __mmask8 valid = EndKeysAvx512(factor, max_val, origin, lanes, d);
    WalkStartsAvx512(d, origin, border_up, border_down, resolution, lanes);
    AppendWalks(lanes, count, valid, origin_key, walks);
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

bool BeamRaster::HasAvx2Kernel() {
#ifdef SONARBENCH_HAVE_AVX512_KERNEL
  return __builtin_cpu_supports("avx2") != 0;
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
  } else if (kernel_ != Kernel::kPortable && HasAvx2Kernel()) {
    visits = WalkAvx2(walks_, box, marks, touched_);
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
