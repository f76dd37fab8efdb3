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
Mark Decide(double near_lo, double near_hi, double far_lo, double far_hi,
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

double Square(double x) { return x * x; }

// The corner offsets of a cell: σ_j = (±1, ±1, ±1), bit k of j set for +1 along axis k.
Vector3d Corner(int j, double half) {
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
  std::array<Axis, 15> axes;
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
        Axis& a = axes[static_cast<std::size_t>(k * 5 + e + 1)];
        a = {l, h * l.lpNorm<1>(), false, false};
        for (int g = 0; g < 4; ++g) {
          a.below |= l.dot(w.edge(g)) < 0.0;
          a.above |= l.dot(w.edge(g)) > 0.0;
        }
      }
    }
  }

  // Whether the cell centred at `c` meets K: no separating axis (K's planes already passed).
  [[nodiscard]] bool Meets(const Vector3d& c) const {
    for (const Axis& a : axes) {
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
      std::sort(breaks.begin(), breaks.begin() + count);
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
};

// The pyramid's edges within one row of cells (a slab along u), as segments with their extent
// along w: what the row's columns need of them.
struct RowEdges {
  int n = 0;
  Vector3d a[8], b[8];
  double w_lo[8], w_hi[8];
};

// One beam's cells, row by row and column by column: columns run along the world axis `c`
// nearest the beam's elevation axis (the wedge's long side), rows along u, w across.
class WedgeScan {
 public:
  WedgeScan(const octomap::OcTree& tree, const BeamWedge& wedge, std::span<const double> obstacles,
            double r_first, double r_far)
      : tree_(tree),
        wedge_(wedge),
        obstacles_(obstacles),
        res_(tree.getResolution()),
        r_first_(r_first),
        r_far_(r_far),
        pyramid_(wedge, r_far),
        tester_(wedge, 0.5 * tree.getResolution(), obstacles, r_first, r_far) {
    wedge.up().cwiseAbs().maxCoeff(&c_);
    u_ = (c_ + 1) % 3;
    w_ = (c_ + 2) % 3;
    for (int k = 0; k < 3; ++k) {  // keys of the pyramid's bounding box
      double min = 0.0, max = 0.0;
      for (const Vector3d& p : pyramid_.corner) {
        min = std::min(min, p[k]);
        max = std::max(max, p[k]);
      }
      lo_[k] = KeyOf(k, min - kSlack);
      hi_[k] = KeyOf(k, max + kSlack);
    }
  }

  WedgeCellCounts Run(std::vector<std::uint64_t>& free_keys,
                      std::vector<std::uint64_t>& occupied_keys) const {
    WedgeCellCounts counts;
    for (int ku = lo_[u_]; ku <= hi_[u_]; ++ku) {
      RowEdges edges;
      double w_min = kInf, w_max = -kInf;
      const double cu = Rel(u_, ku);
      if (!Row(cu, edges, w_min, w_max)) continue;
      const int kw_hi = std::min(hi_[w_], KeyOf(w_, w_max + kSlack));
      for (int kw = std::max(lo_[w_], KeyOf(w_, w_min - kSlack)); kw <= kw_hi; ++kw) {
        Column(ku, kw, edges, free_keys, occupied_keys, counts);
      }
    }
    return counts;
  }

 private:
  // The key of the cell holding coordinate `relative` (to the origin) along `axis`, clamped to
  // the key range.
  [[nodiscard]] int KeyOf(int axis, double relative) const {
    const double k = std::floor((wedge_.origin()[axis] + relative) / res_) +
                     static_cast<double>(tree_.coordToKey(0.0));
    return static_cast<int>(std::clamp(k, 0.0, 65535.0));
  }
  // The centre of key `key`'s cells along `axis`, relative to the origin.
  [[nodiscard]] double Rel(int axis, int key) const {
    return tree_.keyToCoord(static_cast<octomap::key_type>(key)) - wedge_.origin()[axis];
  }

  // The pyramid's edges within the row of cells centred at u = cu, and the row's extent along w.
  bool Row(double cu, RowEdges& edges, double& w_min, double& w_max) const {
    const double half = 0.5 * res_;
    for (const auto& e : Pyramid::kEdges) {
      const Vector3d& a = pyramid_.corner[e[0]];
      const Vector3d& b = pyramid_.corner[e[1]];
      double t0 = 0.0, t1 = 1.0;
      if (!ClipToSlab(a, b, u_, cu - half - kSlack, cu + half + kSlack, t0, t1)) continue;
      const auto i = static_cast<std::size_t>(edges.n++);
      edges.a[i] = a + t0 * (b - a);
      edges.b[i] = a + t1 * (b - a);
      edges.w_lo[i] = std::min(edges.a[i][w_], edges.b[i][w_]);
      edges.w_hi[i] = std::max(edges.a[i][w_], edges.b[i][w_]);
      w_min = std::min(w_min, edges.w_lo[i]);
      w_max = std::max(w_max, edges.w_hi[i]);
    }
    return edges.n > 0;
  }

  // The extent along c of the pyramid's part within the column [u0, u1] × [w0, w1]: at the
  // row's edges within the column, or on the column's four lines within the pyramid.
  bool ColumnExtent(const RowEdges& edges, double u0, double u1, double w0, double w1,
                    double& c_min, double& c_max) const {
    for (int i = 0; i < edges.n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (edges.w_hi[k] < w0 - kSlack || edges.w_lo[k] > w1 + kSlack) continue;
      double t0 = 0.0, t1 = 1.0;
      if (!ClipToSlab(edges.a[k], edges.b[k], w_, w0 - kSlack, w1 + kSlack, t0, t1)) continue;
      for (const double t : {t0, t1}) {
        const double v = edges.a[k][c_] + t * (edges.b[k][c_] - edges.a[k][c_]);
        c_min = std::min(c_min, v);
        c_max = std::max(c_max, v);
      }
    }
    for (const double pu : {u0, u1}) {
      for (const double pw : {w0, w1}) {
        double t_lo = -kInf, t_hi = kInf;
        for (int i = 0; i < 5; ++i) {
          const Vector3d& n = i < 4 ? wedge_.normal(i) : wedge_.axis();
          const double bound = (i < 4 ? 0.0 : r_far_) - n[u_] * pu - n[w_] * pw;
          if (n[c_] > 0.0) {
            t_hi = std::min(t_hi, bound / n[c_]);
          } else if (n[c_] < 0.0) {
            t_lo = std::max(t_lo, bound / n[c_]);
          } else if (bound < 0.0) {
            t_hi = -kInf;
          }
        }
        if (t_lo > t_hi) continue;
        c_min = std::min(c_min, t_lo);
        c_max = std::max(c_max, t_hi);
      }
    }
    return c_min <= c_max;
  }

  // The runs of keys along c to examine in the column (sorted; they may overlap): the cells
  // within the first range's ball (free or on its shell), and for each later range those its
  // sphere passes through. Returns how many.
  int Runs(double u0, double u1, double w0, double w1, double c_min, double c_max,
           std::array<int, 2>* runs) const {
    const double du = std::max({u0, -u1, 0.0}), dw = std::max({w0, -w1, 0.0});
    const double Du = std::max(-u0, u1), Dw = std::max(-w0, w1);
    int n = 0;
    auto add_run = [&](double lo_c, double hi_c) {
      lo_c = std::max(lo_c, c_min);
      hi_c = std::min(hi_c, c_max);
      if (lo_c > hi_c) return;
      runs[n++] = {std::max(lo_[c_], KeyOf(c_, lo_c - kSlack)),
                   std::min(hi_[c_], KeyOf(c_, hi_c + kSlack))};
    };
    // With many ranges, one run over the farthest range's ball holds them all.
    const bool one_run = obstacles_.size() >= kMaxRuns;
    for (std::size_t k = 0; k <= (one_run ? 0 : obstacles_.size()); ++k) {
      const double r = one_run ? r_far_ : k == 0 ? r_first_ : obstacles_[k - 1];
      if (k > 0 && r <= r_first_) continue;
      const double ball2 = r * r - du * du - dw * dw;
      if (ball2 < 0.0) continue;
      const double ball = std::sqrt(ball2);
      const double shell2 = r * r - Du * Du - Dw * Dw;  // a cell reaches r if its |c| does this
      if (k == 0 || shell2 <= 0.0) {
        add_run(-ball, ball);
      } else {
        const double shell = std::sqrt(shell2);
        add_run(-ball, -shell + res_);
        add_run(shell - res_, ball);
      }
    }
    std::sort(runs, runs + n);
    return n;
  }

  void Column(int ku, int kw, const RowEdges& edges, std::vector<std::uint64_t>& free_keys,
              std::vector<std::uint64_t>& occupied_keys, WedgeCellCounts& counts) const {
    const double half = 0.5 * res_;
    const double cu = Rel(u_, ku), cw = Rel(w_, kw);
    double c_min = kInf, c_max = -kInf;
    if (!ColumnExtent(edges, cu - half, cu + half, cw - half, cw + half, c_min, c_max)) return;
    std::array<int, 2> runs[2 * kMaxRuns];
    const int n = Runs(cu - half, cu + half, cw - half, cw + half, c_min, c_max, runs);
    Vector3d centre;
    centre[u_] = cu;
    centre[w_] = cw;
    octomap::OcTreeKey key;
    key[static_cast<unsigned>(u_)] = static_cast<octomap::key_type>(ku);
    key[static_cast<unsigned>(w_)] = static_cast<octomap::key_type>(kw);
    int next = std::numeric_limits<int>::min();  // the first key not yet examined
    for (int i = 0; i < n; ++i) {
      const int first = std::max(runs[i][0], next);
      if (first > runs[i][1]) continue;
      counts.examined += static_cast<std::size_t>(runs[i][1] - first + 1);
      tester_.Column(centre, c_, Rel(c_, first), first, runs[i][1], res_, key, free_keys,
                     occupied_keys, counts.clipped);
      next = std::max(next, runs[i][1] + 1);
    }
  }

  const octomap::OcTree& tree_;
  const BeamWedge& wedge_;
  std::span<const double> obstacles_;
  double res_;
  double r_first_;
  double r_far_;
  Pyramid pyramid_;
  CellTester tester_;
  int c_ = 0, u_ = 1, w_ = 2;
  int lo_[3], hi_[3];
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
  const double r_first = obstacle_ranges_m.empty() ? free_range_m : obstacle_ranges_m.front();
  double r_far = r_first;
  for (const double r : obstacle_ranges_m) r_far = std::max(r_far, r);
  if (r_far <= 0.0) return {};
  return WedgeScan(tree, wedge, obstacle_ranges_m, r_first, r_far).Run(free_keys, occupied_keys);
}

}  // namespace sonarbench::mapping
