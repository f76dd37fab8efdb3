#include "sonarbench/mapping/detail/beam_wedge.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "sonarbench/mapping/detail/key_set.hpp"

namespace sonarbench::mapping {
namespace {

using Eigen::Vector3d;
constexpr double kInf = std::numeric_limits<double>::infinity();
// Candidate ranges are widened by this much [m] so that a cell touching the volume at a face is
// still examined; examining a cell more only costs time.
constexpr double kSlack = 1e-9;
// Up to this many detection ranges per beam, each shell is examined on its own; with more, the
// whole ball of the farthest.
constexpr std::size_t kMaxRuns = 8;

// A convex polygon: a box face (4 vertices) clipped by up to four planes (one vertex more each).
struct Polygon {
  std::array<Vector3d, 8> v;
  int n = 0;
};

// Sutherland-Hodgman: the part of `in` with n·p <= 0.
Polygon Clip(const Polygon& in, const Vector3d& normal) {
  Polygon out;
  for (int i = 0; i < in.n; ++i) {
    const Vector3d& a = in.v[static_cast<std::size_t>(i)];
    const Vector3d& b = in.v[static_cast<std::size_t>((i + 1) % in.n)];
    const double da = normal.dot(a);
    const double db = normal.dot(b);
    if (da <= 0.0) out.v[static_cast<std::size_t>(out.n++)] = a;
    if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
      out.v[static_cast<std::size_t>(out.n++)] = a + (da / (da - db)) * (b - a);
    }
  }
  return out;
}

// The squared distance from the origin to a convex polygon lying in the plane p[axis] = const.
double NearestSquared(const Polygon& p, int axis) {
  const auto u = static_cast<Eigen::Index>((axis + 1) % 3);
  const auto w = static_cast<Eigen::Index>((axis + 2) % 3);
  const double f = p.v[0][axis];
  bool positive = false;
  bool negative = false;
  double best = kInf;
  for (int i = 0; i < p.n; ++i) {
    const Vector3d& a3 = p.v[static_cast<std::size_t>(i)];
    const Vector3d& b3 = p.v[static_cast<std::size_t>((i + 1) % p.n)];
    const double ax = a3[u], ay = a3[w], bx = b3[u], by = b3[w];
    const double cross = ax * by - ay * bx;  // which side of edge a→b the origin lies on
    positive |= cross > 0.0;
    negative |= cross < 0.0;
    const double dx = bx - ax, dy = by - ay;
    const double length2 = dx * dx + dy * dy;
    const double t = length2 > 0.0 ? std::clamp(-(ax * dx + ay * dy) / length2, 0.0, 1.0) : 0.0;
    const double qx = ax + t * dx, qy = ay + t * dy;
    best = std::min(best, qx * qx + qy * qy);
  }
  // Inside when the origin is on one side of every edge (a polygon of nonzero area).
  const bool inside = (positive != negative);
  return f * f + (inside ? 0.0 : best);
}

// The part [t0, t1] of the segment a + t (b - a), t in [0, 1], with lo <= p[axis] <= hi.
bool ClipToSlab(const Vector3d& a, const Vector3d& b, int axis, double lo, double hi, double& t0,
                double& t1) {
  const double pa = a[axis];
  const double d = b[axis] - pa;
  if (d == 0.0) return pa >= lo && pa <= hi;
  double ta = (lo - pa) / d;
  double tb = (hi - pa) / d;
  if (ta > tb) std::swap(ta, tb);
  t0 = std::max(t0, ta);
  t1 = std::min(t1, tb);
  return t0 <= t1;
}

// Three-valued logic for deciding a cell from bounds on its span.
enum class Tri { kFalse, kTrue, kUnknown };
Tri And(Tri a, Tri b) {
  if (a == Tri::kFalse || b == Tri::kFalse) return Tri::kFalse;
  return a == Tri::kTrue && b == Tri::kTrue ? Tri::kTrue : Tri::kUnknown;
}
Tri Or(Tri a, Tri b) {
  if (a == Tri::kTrue || b == Tri::kTrue) return Tri::kTrue;
  return a == Tri::kFalse && b == Tri::kFalse ? Tri::kFalse : Tri::kUnknown;
}
// near <= r, given near in [lo, hi]; and its mirror for far >= r.
Tri AtMost(double lo, double hi, double r) {
  return r < lo ? Tri::kFalse : (r >= hi ? Tri::kTrue : Tri::kUnknown);
}

enum class Mark { kNone, kFree, kOccupied, kUndecided };

// The exact semantics (beam_wedge.hpp) on a span whose near end lies in [near_lo, near_hi] and
// far end in [far_lo, far_hi]; kUndecided when the bounds do not settle it. `meets` is whether
// the cell is known to meet the wedge.
Mark Decide(double near_lo, double near_hi, double far_lo, double far_hi, bool meets,
            std::span<const double> obstacles, double r_first) {
  Tri occupied = Tri::kFalse;
  for (const double r : obstacles) {
    const Tri far_ge = r > far_hi ? Tri::kFalse : (r <= far_lo ? Tri::kTrue : Tri::kUnknown);
    occupied = Or(occupied, And(AtMost(near_lo, near_hi, r), far_ge));
  }
  if (occupied == Tri::kTrue) return Mark::kOccupied;  // a known end lies inside the wedge
  if (occupied == Tri::kUnknown) return Mark::kUndecided;
  if (r_first <= 0.0 || far_lo >= r_first) return Mark::kNone;
  if (far_hi < r_first) return meets ? Mark::kFree : Mark::kUndecided;
  return Mark::kUndecided;
}

Mark DecideExact(const BeamWedge::Span& s, std::span<const double> obstacles, double r_first) {
  if (!s.meets) return Mark::kNone;
  return Decide(s.near, s.near, s.far, s.far, true, obstacles, r_first);
}

// Per beam: the wedge's planes in a form the per-cell loop reads fast.
struct CellTester {
  const BeamWedge& wedge;
  double half;
  double spread[4];     // half · ‖n_i‖₁: how far n_i·p varies over a cell
  double corner[4][8];  // half · n_i·σ_j for the corner offsets σ_j in {-1, +1}³
  std::span<const double> obstacles;
  double r_first;
  double r_far;

  CellTester(const BeamWedge& w, double h, std::span<const double> o, double first, double far)
      : wedge(w), half(h), obstacles(o), r_first(first), r_far(far) {
    for (int i = 0; i < 4; ++i) {
      const Vector3d& n = w.normal(i);
      spread[i] = h * n.lpNorm<1>();
      for (int j = 0; j < 8; ++j) {
        const Vector3d sigma((j & 1) ? h : -h, (j & 2) ? h : -h, (j & 4) ? h : -h);
        corner[i][j] = n.dot(sigma);
      }
    }
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
    const double near_lo = (a - Vector3d::Constant(half)).cwiseMax(0.0).norm();
    if (near_lo > r_far) return Mark::kNone;
    const double far_hi = (a + Vector3d::Constant(half)).norm();
    if (cut == 0) return Decide(near_lo, near_lo, far_hi, far_hi, true, obstacles, r_first);
    // The corners inside K bound the span from within.
    double near_hi = kInf;
    double far_lo = -kInf;
    for (int j = 0; j < 8; ++j) {
      bool in = true;
      for (int i = 0; i < 4; ++i) in &= s[i] + corner[i][j] <= 0.0;
      if (!in) continue;
      const double r =
          (c + Vector3d((j & 1) ? half : -half, (j & 2) ? half : -half, (j & 4) ? half : -half))
              .norm();
      near_hi = std::min(near_hi, r);
      far_lo = std::max(far_lo, r);
    }
    // Cut by one plane only, the cell meets K: its part on the inner side is not empty.
    const bool meets = near_hi < kInf || std::has_single_bit(cut);
    const Mark m = Decide(near_lo, near_hi, far_lo, far_hi, meets, obstacles, r_first);
    if (m != Mark::kUndecided) return m;
    ++clipped;
    return DecideExact(wedge.CellSpan(c, half), obstacles, r_first);
  }
};

// The pyramid K ∩ {axis·p <= r}, which holds the wedge's cells within range r: its apex and
// base corners, and its edges as pairs of corner indices (apex = 4).
struct Pyramid {
  Vector3d corner[5];
  static constexpr int kEdges[8][2] = {{4, 0}, {4, 1}, {4, 2}, {4, 3},
                                       {0, 1}, {2, 3}, {0, 2}, {1, 3}};

  Pyramid(const BeamWedge& w, double r) {
    for (int i = 0; i < 4; ++i) corner[i] = (r / w.edge(i).dot(w.axis())) * w.edge(i);
    corner[4] = Vector3d::Zero();
  }

  // The extent along `axis` of the pyramid's part within the slabs lo <= p[s] <= hi (s = 0 or
  // 1 of `slab_axes`), over its edges. Returns false when no edge meets the slabs.
  bool EdgeExtent(int axis, int slabs, const int* slab_axes, const double* lo, const double* hi,
                  double& min, double& max) const {
    bool any = false;
    for (const auto& e : kEdges) {
      const Vector3d& a = corner[e[0]];
      const Vector3d& b = corner[e[1]];
      double t0 = 0.0, t1 = 1.0;
      bool in = true;
      for (int k = 0; k < slabs && in; ++k)
        in = ClipToSlab(a, b, slab_axes[k], lo[k], hi[k], t0, t1);
      if (!in) continue;
      any = true;
      for (const double t : {t0, t1}) {
        const double v = a[axis] + t * (b[axis] - a[axis]);
        min = std::min(min, v);
        max = std::max(max, v);
      }
    }
    return any;
  }
};

}  // namespace

BeamWedge::BeamWedge(const SensorGeometry& sensor, const Beam& beam) {
  const Eigen::Matrix3d R =
      beam.T_world_sonar.linear() *
      Eigen::AngleAxisd(beam.head_angle_rad, Vector3d::UnitZ()).toRotationMatrix();
  origin_ = beam.T_world_sonar.translation();
  const double a = 0.5 * sensor.beam_width_horizontal_rad;
  const double t_out = std::tan(0.5 * sensor.beam_width_vertical_rad) / std::cos(a);
  normals_[0] = R * Vector3d(-std::sin(a), std::cos(a), 0.0);   // azimuth <= a
  normals_[1] = R * Vector3d(-std::sin(a), -std::cos(a), 0.0);  // azimuth >= -a
  normals_[2] = R * Vector3d(-t_out, 0.0, 1.0).normalized();    // through the upper corners
  normals_[3] = R * Vector3d(-t_out, 0.0, -1.0).normalized();   // through the lower corners
  for (int i = 0; i < 4; ++i) {
    const double elevation_sign = (i & 1) ? -1.0 : 1.0;
    const double azimuth_sign = (i & 2) ? -1.0 : 1.0;
    edges_[i] = R * Vector3d(1.0, azimuth_sign * std::tan(a), elevation_sign * t_out).normalized();
  }
  axis_ = R * Vector3d::UnitX();
  up_ = R * Vector3d::UnitZ();
}

BeamWedge::Span BeamWedge::CellSpan(const Vector3d& c, double half) const {
  Span span;
  unsigned cut = 0;
  for (int i = 0; i < 4; ++i) {
    const double d = normals_[i].dot(c);
    const double e = half * normals_[i].lpNorm<1>();
    if (d - e > 0.0) return span;
    if (d + e > 0.0) cut |= 1u << i;
  }
  double near2 = kInf;
  double far2 = 0.0;
  // Every vertex of box ∩ K but the apex lies on a face of the box (K's planes meet only at the
  // apex), and the point of box ∩ K nearest the apex lies on a face unless the box holds the
  // apex: the faces clipped by K give both ends of the span.
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3;
    const int w = (axis + 2) % 3;
    for (const double side : {-1.0, 1.0}) {
      Polygon p;
      p.n = 4;
      const double su[4] = {-1, 1, 1, -1};
      const double sw[4] = {-1, -1, 1, 1};
      for (std::size_t k = 0; k < 4; ++k) {
        Vector3d v = c;
        v[axis] += side * half;
        v[u] += su[k] * half;
        v[w] += sw[k] * half;
        p.v[k] = v;
      }
      for (int i = 0; i < 4 && p.n > 0; ++i) {
        if ((cut >> i) & 1u) p = Clip(p, normals_[i]);
      }
      if (p.n == 0) continue;
      span.meets = true;
      for (int k = 0; k < p.n; ++k)
        far2 = std::max(far2, p.v[static_cast<std::size_t>(k)].squaredNorm());
      near2 = std::min(near2, NearestSquared(p, axis));
    }
  }
  if ((c.cwiseAbs().array() <= half).all()) {
    span.meets = true;
    near2 = 0.0;
  }
  if (!span.meets) return span;
  span.near = std::sqrt(near2);
  span.far = std::sqrt(far2);
  return span;
}

WedgeCellCounts ExactBeamCells(const octomap::OcTree& tree, const BeamWedge& wedge,
                               std::span<const double> obstacle_ranges_m, double free_range_m,
                               std::vector<std::uint64_t>& free_keys,
                               std::vector<std::uint64_t>& occupied_keys) {
  WedgeCellCounts counts;
  const double r_first = obstacle_ranges_m.empty() ? free_range_m : obstacle_ranges_m.front();
  double r_far = r_first;
  for (const double r : obstacle_ranges_m) r_far = std::max(r_far, r);
  if (r_far <= 0.0) return counts;
  const double res = tree.getResolution();
  const double half = 0.5 * res;
  const Vector3d& o = wedge.origin();
  const Pyramid pyramid(wedge, r_far);
  // Columns run along the world axis nearest the beam's elevation axis (the wedge's long side).
  int c = 0;
  wedge.up().cwiseAbs().maxCoeff(&c);
  const int u = (c + 1) % 3;
  const int w = (c + 2) % 3;
  // Keys of the pyramid's bounding box, within the key range.
  auto key_of = [&](double coordinate) {
    const double k = std::floor(coordinate / res) + static_cast<double>(tree.coordToKey(0.0));
    return static_cast<int>(std::clamp(k, 0.0, 65535.0));
  };
  int lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    double min = 0.0, max = 0.0;
    for (const Vector3d& p : pyramid.corner) {
      min = std::min(min, p[k]);
      max = std::max(max, p[k]);
    }
    lo[k] = key_of(o[k] + min - kSlack);
    hi[k] = key_of(o[k] + max + kSlack);
  }
  const CellTester tester(wedge, half, obstacle_ranges_m, r_first, r_far);
  auto rel = [&](int axis, int key) {
    return tree.keyToCoord(static_cast<octomap::key_type>(key)) - o[axis];
  };
  for (int ku = lo[u]; ku <= hi[u]; ++ku) {
    const double u0 = rel(u, ku) - half, u1 = rel(u, ku) + half;
    double w_min = kInf, w_max = -kInf;
    const int row_axes[1] = {u};
    const double row_lo[1] = {u0 - kSlack}, row_hi[1] = {u1 + kSlack};
    if (!pyramid.EdgeExtent(w, 1, row_axes, row_lo, row_hi, w_min, w_max)) continue;
    const int kw_lo = std::max(lo[w], key_of(o[w] + w_min - kSlack));
    const int kw_hi = std::min(hi[w], key_of(o[w] + w_max + kSlack));
    for (int kw = kw_lo; kw <= kw_hi; ++kw) {
      const double w0 = rel(w, kw) - half, w1 = rel(w, kw) + half;
      // The column's extent along c: the pyramid's edges within it, its four lines within the
      // pyramid, then the ball.
      double c_min = kInf, c_max = -kInf;
      const int axes[2] = {u, w};
      const double col_lo[2] = {u0 - kSlack, w0 - kSlack}, col_hi[2] = {u1 + kSlack, w1 + kSlack};
      pyramid.EdgeExtent(c, 2, axes, col_lo, col_hi, c_min, c_max);
      for (const double pu : {u0, u1}) {
        for (const double pw : {w0, w1}) {
          double t_lo = -kInf, t_hi = kInf;
          for (int i = 0; i < 5; ++i) {
            const Vector3d& n = i < 4 ? wedge.normal(i) : wedge.axis();
            const double bound = (i < 4 ? 0.0 : r_far) - n[u] * pu - n[w] * pw;
            if (n[c] > 0.0)
              t_hi = std::min(t_hi, bound / n[c]);
            else if (n[c] < 0.0)
              t_lo = std::max(t_lo, bound / n[c]);
            else if (bound < 0.0)
              t_hi = -kInf;
          }
          if (t_lo > t_hi) continue;
          c_min = std::min(c_min, t_lo);
          c_max = std::max(c_max, t_hi);
        }
      }
      if (c_min > c_max) continue;
      // The cells to examine: those within the first range's ball (free or on its shell), and
      // for each later range those its sphere passes through.
      const double du = std::max({u0, -u1, 0.0}), dw = std::max({w0, -w1, 0.0});
      const double Du = std::max(-u0, u1), Dw = std::max(-w0, w1);
      std::array<int, 2> runs[2 * kMaxRuns];
      int n = 0;
      auto add_run = [&](double lo_c, double hi_c) {
        lo_c = std::max(lo_c, c_min);
        hi_c = std::min(hi_c, c_max);
        if (lo_c > hi_c) return;
        runs[n][0] = std::max(lo[c], key_of(o[c] + lo_c - kSlack));
        runs[n][1] = std::min(hi[c], key_of(o[c] + hi_c + kSlack));
        ++n;
      };
      // With many ranges, one run over the farthest range's ball holds them all.
      const bool one_run = obstacle_ranges_m.size() >= kMaxRuns;
      for (std::size_t k = 0; k <= (one_run ? 0 : obstacle_ranges_m.size()); ++k) {
        const double r = one_run ? r_far : k == 0 ? r_first : obstacle_ranges_m[k - 1];
        if (k > 0 && r <= r_first) continue;
        const double ball2 = r * r - du * du - dw * dw;
        if (ball2 < 0.0) continue;
        const double ball = std::sqrt(ball2);
        const double shell2 = r * r - Du * Du - Dw * Dw;  // a cell reaches r if its |c| does this
        if (k == 0 || shell2 <= 0.0) {
          add_run(-ball, ball);
        } else {
          const double shell = std::sqrt(shell2);
          add_run(-ball, -shell + res);
          add_run(shell - res, ball);
        }
      }
      std::sort(runs, runs + n);
      Vector3d centre;
      centre[u] = rel(u, ku);
      centre[w] = rel(w, kw);
      octomap::OcTreeKey key;
      key[u] = static_cast<octomap::key_type>(ku);
      key[w] = static_cast<octomap::key_type>(kw);
      int next = std::numeric_limits<int>::min();  // the first key not yet examined
      for (int i = 0; i < n; ++i) {
        for (int kc = std::max(runs[i][0], next); kc <= runs[i][1]; ++kc) {
          centre[c] = rel(c, kc);
          ++counts.examined;
          const Mark m = tester.Classify(centre, counts.clipped);
          if (m == Mark::kNone) continue;
          key[c] = static_cast<octomap::key_type>(kc);
          (m == Mark::kOccupied ? occupied_keys : free_keys).push_back(PackKey(key));
        }
        next = std::max(next, runs[i][1] + 1);
      }
    }
  }
  return counts;
}

}  // namespace sonarbench::mapping
