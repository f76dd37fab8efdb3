#pragma once
// The per-cell decisions of the exact beam volumes (beam_wedge.cpp): the semantics of
// ExactBeamCells on bounds of a cell's span, and the per-beam tables that settle most cells
// without clipping. Internal to the mapping library.

#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "beam_wedge.hpp"
#include "key_set.hpp"

namespace sonarbench::mapping::wedge_detail {

using Eigen::Vector3d;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Three-valued logic for deciding a cell from bounds on its span.
enum class Tri { kFalse, kTrue, kUnknown };
inline Tri And(Tri a, Tri b) {
  if (a == Tri::kFalse || b == Tri::kFalse) return Tri::kFalse;
  return a == Tri::kTrue && b == Tri::kTrue ? Tri::kTrue : Tri::kUnknown;
}
inline Tri Or(Tri a, Tri b) {
  if (a == Tri::kTrue || b == Tri::kTrue) return Tri::kTrue;
  return a == Tri::kFalse && b == Tri::kFalse ? Tri::kFalse : Tri::kUnknown;
}

enum class Mark {
  kNone,
  kFree,
  kOccupied,
  kFreeIfMeets,  ///< free if the cell meets the wedge, untouched if not
  kUndecided,    ///< the bounds do not settle it
};

// The exact semantics (beam_wedge.hpp) for a cell that meets the wedge (or, for kFreeIfMeets,
// may), from bounds on its span: the squared near end lies in [near_lo, near_hi], the squared
// far end in [far_lo, far_hi]. Squared ranges compare as the ranges do.
inline Mark Decide(double near_lo, double near_hi, double far_lo, double far_hi,
                   std::span<const double> obstacles, double r_first) {
  Tri occupied = Tri::kFalse;
  for (const double range : obstacles) {
    const double r = range * range;
    const Tri near_le = r < near_lo ? Tri::kFalse : (r >= near_hi ? Tri::kTrue : Tri::kUnknown);
    const Tri far_ge = r > far_hi ? Tri::kFalse : (r <= far_lo ? Tri::kTrue : Tri::kUnknown);
    occupied = Or(occupied, And(near_le, far_ge));
  }
  if (occupied == Tri::kTrue) return Mark::kOccupied;
  if (occupied == Tri::kUnknown) return Mark::kUndecided;
  const double r = r_first * r_first;
  if (r_first <= 0.0) return Mark::kNone;
  // With a detection, free means wholly before it; clearing without one, any part before it.
  const double lo = obstacles.empty() ? near_lo : far_lo;
  const double hi = obstacles.empty() ? near_hi : far_hi;
  if (lo >= r) return Mark::kNone;
  return hi < r ? Mark::kFreeIfMeets : Mark::kUndecided;
}

inline double Square(double x) { return x * x; }

// The corner offsets of a cell: σ_j = (±1, ±1, ±1), bit k of j set for +1 along axis k.
inline Vector3d Corner(int j, double half) {
  return {(j & 1) ? half : -half, (j & 2) ? half : -half, (j & 4) ? half : -half};
}

// Per beam: the wedge's planes in a form the per-cell loop reads fast.
struct CellTester {
  const BeamWedge& wedge;
  double half;
  double spread[4];     // half · ‖n_i‖₁: how far n_i·p varies over a cell
  double corner[4][8];  // half · n_i·σ_j
  // Separating axes of a cell and K besides K's planes: the cell's axes and the cross products
  // of its edges with K's edge rays, with half · ‖L‖₁ and on which sides K reaches to infinity.
  struct Axis {
    Vector3d l;
    double spread;
    bool below;  // K has points with L·p < 0
    bool above;  // K has points with L·p > 0
  };
  // Only the axes along which K lies on one side (both sides: the axis cannot separate).
  std::array<Axis, 15> axes;
  int axis_count = 0;
  std::span<const double> obstacles;
  double r_first;
  double r_far;
  double r_near2;  // the square of the least of r_first and the detection ranges

  CellTester(const BeamWedge& w, double h, std::span<const double> o, double first, double far)
      : wedge(w), half(h), obstacles(o), r_first(first), r_far(far) {
    double nearest = first;
    for (const double r : o) nearest = std::min(nearest, r);
    r_near2 = nearest > 0.0 ? nearest * nearest : -1.0;
    for (int i = 0; i < 4; ++i) {
      const Vector3d& n = w.normal(i);
      spread[i] = h * n.lpNorm<1>();
      for (int j = 0; j < 8; ++j) corner[i][j] = n.dot(Corner(j, h));
    }
    for (int k = 0; k < 3; ++k) {
      for (int e = -1; e < 4; ++e) {
        const Vector3d l = e < 0 ? Vector3d(Vector3d::Unit(k)) : Vector3d::Unit(k).cross(w.edge(e));
        Axis a = {l, h * l.lpNorm<1>(), false, false};
        for (int g = 0; g < 4; ++g) {
          a.below |= l.dot(w.edge(g)) < 0.0;
          a.above |= l.dot(w.edge(g)) > 0.0;
        }
        if (!a.below || !a.above) axes[static_cast<std::size_t>(axis_count++)] = a;
      }
    }
  }

  // Whether the cell centred at `c` meets K: no separating axis (K's planes already passed).
  [[nodiscard]] bool Meets(const Vector3d& c) const {
    for (int i = 0; i < axis_count; ++i) {
      const Axis& a = axes[static_cast<std::size_t>(i)];
      const double d = a.l.dot(c);
      if ((!a.above && d - a.spread > 0.0) || (!a.below && d + a.spread < 0.0)) return false;
    }
    return true;
  }

  // The exact squared span of a cell cut by plane i alone: the far end at a corner on the inner
  // side or where an edge crosses the plane; the near end at the box's point nearest the apex if
  // that is on the inner side, else at clamp(-λ n) with λ > 0 putting it on the plane (the
  // minimum of |p|² over box ∩ {n·p <= 0}, a separable problem with one constraint).
  void SinglePlaneSpan(const Vector3d& c, int i, double s, double& near2, double& far2) const {
    double v[8];
    far2 = 0.0;
    for (int j = 0; j < 8; ++j) {
      v[j] = s + corner[i][j];
      if (v[j] <= 0.0) far2 = std::max(far2, (c + Corner(j, half)).squaredNorm());
    }
    for (int j = 0; j < 8; ++j) {
      for (int bit = 1; bit < 8; bit <<= 1) {
        const int k = j | bit;
        if ((j & bit) != 0 || (v[j] <= 0.0) == (v[k] <= 0.0)) continue;
        const double t = v[j] / (v[j] - v[k]);
        const Vector3d a = c + Corner(j, half);
        far2 = std::max(far2, (a + t * (Corner(k, half) - Corner(j, half))).squaredNorm());
      }
    }
    const Vector3d& n = wedge.normal(i);
    const Vector3d lo = c.array() - half, hi = c.array() + half;
    auto clamp = [&](double lambda) {
      Vector3d p;
      for (int k = 0; k < 3; ++k) p[k] = std::clamp(-lambda * n[k], lo[k], hi[k]);
      return p;
    };
    Vector3d p = clamp(0.0);
    double f = n.dot(p);
    if (f > 0.0) {
      // n·clamp(-λ n) falls with λ, linearly between the breakpoints where a coordinate clamps.
      std::array<double, 7> breaks{};
      int count = 0;
      for (int k = 0; k < 3; ++k) {
        if (n[k] == 0.0) continue;
        for (const double bound : {lo[k], hi[k]}) {
          const double lambda = -bound / n[k];
          if (lambda > 0.0) breaks[static_cast<std::size_t>(count++)] = lambda;
        }
      }
      for (int b = 1; b < count; ++b) {  // insertion sort of at most six
        for (auto j = static_cast<std::size_t>(b); j > 0 && breaks[j - 1] > breaks[j]; --j) {
          std::swap(breaks[j - 1], breaks[j]);
        }
      }
      double lambda_a = 0.0, f_a = f;
      for (int b = 0; b < count; ++b) {
        const double lambda_b = breaks[static_cast<std::size_t>(b)];
        const double f_b = n.dot(clamp(lambda_b));
        if (f_b <= 0.0) {
          p = clamp(lambda_a + f_a * (lambda_b - lambda_a) / (f_a - f_b));
          break;
        }
        lambda_a = lambda_b;
        f_a = f_b;
      }
    }
    near2 = p.squaredNorm();
  }

  // The cell centred at `c` (relative to the origin); `clipped` counts the exact clippings.
  Mark Classify(const Vector3d& c, std::size_t& clipped) const {
    double s[4];
    unsigned cut = 0;
    for (int i = 0; i < 4; ++i) {
      s[i] = wedge.normal(i).dot(c);
      if (s[i] - spread[i] > 0.0) return Mark::kNone;
      if (s[i] + spread[i] > 0.0) cut |= 1u << i;
    }
    const Vector3d a = c.cwiseAbs();
    const double near_lo = (a.array() - half).cwiseMax(0.0).matrix().squaredNorm();
    if (near_lo > r_far * r_far) return Mark::kNone;
    const double far_hi = (a.array() + half).matrix().squaredNorm();
    if (cut == 0) return DecideMet(Decide(near_lo, near_lo, far_hi, far_hi, obstacles, r_first));
    // Most cells lie away from every shell: the box's own ranges settle them.
    const Mark by_box = Decide(near_lo, kInf, -kInf, far_hi, obstacles, r_first);
    if (by_box == Mark::kNone) return by_box;
    if (by_box == Mark::kFreeIfMeets && std::has_single_bit(cut)) return Mark::kFree;
    // The corners inside K bound the span from within.
    double near_hi = kInf, far_lo = -kInf;
    for (int j = 0; j < 8; ++j) {
      bool in = true;
      for (int i = 0; i < 4; ++i) in &= ((cut >> i) & 1u) == 0 || s[i] + corner[i][j] <= 0.0;
      if (!in) continue;
      const double r = (c + Corner(j, half)).squaredNorm();
      near_hi = std::min(near_hi, r);
      far_lo = std::max(far_lo, r);
    }
    const Mark m = Decide(near_lo, near_hi, far_lo, far_hi, obstacles, r_first);
    if (std::has_single_bit(cut)) {  // the cell meets K: its part on the inner side is not empty
      if (m != Mark::kUndecided) return DecideMet(m);
      const int i = std::countr_zero(cut);
      double near2, far2;
      SinglePlaneSpan(c, i, s[i], near2, far2);
      return DecideMet(Decide(near2, near2, far2, far2, obstacles, r_first));
    }
    if (m == Mark::kFreeIfMeets) return near_hi < kInf || Meets(c) ? Mark::kFree : Mark::kNone;
    if (m != Mark::kUndecided) return m;
    if (near_hi == kInf && !Meets(c)) return Mark::kNone;
    ++clipped;
    const BeamWedge::Span span = wedge.CellSpan(c, half);
    if (!span.meets) return Mark::kNone;
    const double n2 = span.near * span.near, f2 = span.far * span.far;
    return DecideMet(Decide(n2, n2, f2, f2, obstacles, r_first));
  }

  // Classifies the cells kc_lo..kc_hi of a column along axis `c` (`centre`'s other coordinates
  // set, `c0` the first cell's), appending their keys (`key`'s other coordinates set). A cell
  // whose box lies wholly nearer than every detection range, and which one plane at most cuts,
  // is free if it lies inside K's other planes: the fast path most cells take.
  void Column(Vector3d centre, int c, double c0, int kc_lo, int kc_hi, double res,
              octomap::OcTreeKey key, std::vector<std::uint64_t>& free_keys,
              std::vector<std::uint64_t>& occupied_keys, std::size_t& clipped) const {
    const int u = (c + 1) % 3, w = (c + 2) % 3;
    const double across = Square(std::abs(centre[u]) + half) + Square(std::abs(centre[w]) + half);
    double s0[4], ds[4];
    for (int i = 0; i < 4; ++i) {
      const Vector3d& n = wedge.normal(i);
      s0[i] = n[u] * centre[u] + n[w] * centre[w];
      ds[i] = n[c];
    }
    for (int kc = kc_lo; kc <= kc_hi; ++kc) {
      const double cc = c0 + (kc - kc_lo) * res;
      if (across + Square(std::abs(cc) + half) < r_near2) {
        int cuts = 0;
        bool outside = false;
        for (int i = 0; i < 4; ++i) {
          const double si = s0[i] + ds[i] * cc;
          outside |= si - spread[i] > 0.0;
          cuts += si + spread[i] > 0.0 ? 1 : 0;
        }
        if (outside) continue;
        centre[c] = cc;
        // A scanned cell overlaps its column's part of the wedge's pyramid, so it meets the
        // wedge; the test settles only cells that touch it within the scan's slack.
        if (cuts >= 2 && !Meets(centre)) continue;
        key[c] = static_cast<octomap::key_type>(kc);
        free_keys.push_back(PackKey(key));
        continue;
      }
      centre[c] = cc;
      const Mark m = Classify(centre, clipped);
      if (m == Mark::kNone) continue;
      key[c] = static_cast<octomap::key_type>(kc);
      (m == Mark::kOccupied ? occupied_keys : free_keys).push_back(PackKey(key));
    }
  }

  // A decision on a cell known to meet K.
  static Mark DecideMet(Mark m) { return m == Mark::kFreeIfMeets ? Mark::kFree : m; }
};

}  // namespace sonarbench::mapping::wedge_detail
