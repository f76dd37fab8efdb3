#include "beam_wedge.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "key_set.hpp"
#include "wedge_cell_tester.hpp"

namespace sonarbench::mapping {
namespace {

using Eigen::Vector3d;
using wedge_detail::CellTester;
using wedge_detail::kInf;
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
    for (int i = 0; i < 5; ++i) {  // the pyramid's planes n·p <= bound, split by axis
      const Vector3d& n = i < 4 ? wedge.normal(i) : wedge.axis();
      normal_u_[i] = n[u_];
      normal_w_[i] = n[w_];
      bound_[i] = i < 4 ? 0.0 : r_far;
      sign_c_[i] = n[c_] > 0.0 ? 1 : (n[c_] < 0.0 ? -1 : 0);
      inverse_c_[i] = sign_c_[i] != 0 ? 1.0 / n[c_] : 0.0;
    }
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
          const double bound = bound_[i] - normal_u_[i] * pu - normal_w_[i] * pw;
          const double t = bound * inverse_c_[i];
          if (sign_c_[i] > 0) {
            t_hi = std::min(t_hi, t);
          } else if (sign_c_[i] < 0) {
            t_lo = std::max(t_lo, t);
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
  double normal_u_[5], normal_w_[5], bound_[5], inverse_c_[5];
  int sign_c_[5];
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
