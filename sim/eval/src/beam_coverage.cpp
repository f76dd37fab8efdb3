#include "sonarbench/sim/eval/beam_coverage.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <optional>
#include <utility>

#include "sonarbench/mapping/beam_cells.hpp"

namespace sonarbench::sim {
namespace {

using Eigen::Vector3d;

// Half-spaces a·p <= b, p relative to the sonar.
struct HalfSpace {
  Vector3d a;
  double b;
};

constexpr double kFeasibilityTolerance = 1e-10;  // m; cells are centimetres

// The smallest |p| over the polytope {p : a_i·p <= b_i}, or nullopt when it is empty. The
// minimiser lies in the relative interior of one face, and is then the projection of the origin
// onto that face's affine hull, which 0 to 3 linearly independent active constraints span: every
// such subset is tried, and the feasible projection of least norm is the answer.
std::optional<double> MinNorm(const std::array<HalfSpace, 10>& c) {
  std::optional<double> best;
  auto consider = [&](const Vector3d& p) {
    for (const HalfSpace& h : c) {
      if (h.a.dot(p) > h.b + kFeasibilityTolerance) return;
    }
    const double n = p.norm();
    if (!best || n < *best) best = n;
  };
  consider(Vector3d::Zero());
  const int n = static_cast<int>(c.size());
  for (int i = 0; i < n; ++i) {
    consider(c[i].a * (c[i].b / c[i].a.squaredNorm()));
    for (int j = i + 1; j < n; ++j) {
      Eigen::Matrix<double, 2, 3> A;
      A << c[i].a.transpose(), c[j].a.transpose();
      const Eigen::Matrix2d G = A * A.transpose();
      if (std::abs(G.determinant()) > 1e-12 * G.trace() * G.trace()) {
        consider(A.transpose() * G.inverse() * Eigen::Vector2d(c[i].b, c[j].b));
      }
      for (int k = j + 1; k < n; ++k) {
        Eigen::Matrix3d M;
        M << c[i].a.transpose(), c[j].a.transpose(), c[k].a.transpose();
        const double det = M.determinant();
        if (std::abs(det) > 1e-12 * M.rowwise().norm().prod()) {
          consider(M.inverse() * Vector3d(c[i].b, c[j].b, c[k].b));
        }
      }
    }
  }
  return best;
}

// The wedge's side planes through the sonar, as world-frame normals n with n·p <= 0 inside:
// its azimuth edges, and the fan's elevation edges on the axis (inner) and at the azimuth edges
// (outer, the wider).
struct WedgePlanes {
  Vector3d left;
  Vector3d right;
  std::array<Vector3d, 2> inner;
  std::array<Vector3d, 2> outer;
};

// The keys of the corners of a box holding the wedge (its corners at full range, the far cap's
// bulges and the apex), one cell wider each way.
std::pair<octomap::OcTreeKey, octomap::OcTreeKey> WedgeKeyBounds(
    const Eigen::Matrix3d& R_world_beam, const Vector3d& origin, double a, double t_out,
    double range_m, const octomap::OcTree& key_space) {
  // Candidates: the cells of the wedge's bounding box (its corners at full range, and the apex).
  Vector3d lo = origin;
  Vector3d hi = origin;
  for (double sa : {-1.0, 1.0}) {
    for (double se : {-1.0, 1.0}) {
      const double el = std::atan(t_out) * se;
      const Vector3d d(std::cos(el) * std::cos(sa * a), std::cos(el) * std::sin(sa * a),
                       std::sin(el));
      lo = lo.cwiseMin(origin + range_m * (R_world_beam * d));
      hi = hi.cwiseMax(origin + range_m * (R_world_beam * d));
    }
  }
  // The far cap bulges beyond its corners: along the axis, and at zero elevation on the edges.
  for (const Vector3d& d :
       {Vector3d(1, 0, 0), Vector3d(std::cos(a), std::sin(a), 0),
        Vector3d(std::cos(a), -std::sin(a), 0), Vector3d(1, 0, t_out), Vector3d(1, 0, -t_out)}) {
    const Vector3d w = origin + range_m * (R_world_beam * d.normalized());
    lo = lo.cwiseMin(w);
    hi = hi.cwiseMax(w);
  }
  const double res = key_space.getResolution();
  lo -= Vector3d::Constant(res);
  hi += Vector3d::Constant(res);
  return {key_space.coordToKey(lo.x(), lo.y(), lo.z()),
          key_space.coordToKey(hi.x(), hi.y(), hi.z())};
}

enum class CellInWedge { kOutside, kInside, kUndecided };

// Whether the cell box centred at `centre` (relative to the sonar), `half` wide each way, meets
// the wedge within `range_m`: inside if it meets the inner (narrower) wedge, undecided if only
// the outer one.
CellInWedge Classify(const Vector3d& centre, double half, double range_m, const WedgePlanes& w) {
  std::array<HalfSpace, 10> c;
  for (int i = 0; i < 3; ++i) {
    Vector3d e = Vector3d::Zero();
    e[i] = 1.0;
    c[2 * i] = {e, centre[i] + half};
    c[2 * i + 1] = {-e, -(centre[i] - half)};
  }
  c[6] = {w.left, 0.0};
  c[7] = {w.right, 0.0};
  c[8] = {w.outer[0], 0.0};
  c[9] = {w.outer[1], 0.0};
  const auto outer_distance = MinNorm(c);
  if (!outer_distance || *outer_distance > range_m) return CellInWedge::kOutside;
  c[8] = {w.inner[0], 0.0};
  c[9] = {w.inner[1], 0.0};
  const auto inner_distance = MinNorm(c);
  return inner_distance && *inner_distance <= range_m ? CellInWedge::kInside
                                                      : CellInWedge::kUndecided;
}

}  // namespace

WedgeCells ExactWedgeCells(const mapping::Beam& beam, const mapping::SensorGeometry& sensor,
                           double range_m, const octomap::OcTree& key_space) {
  const Eigen::Matrix3d R_world_beam =
      beam.T_world_sonar.linear() *
      Eigen::AngleAxisd(beam.head_angle_rad, Vector3d::UnitZ()).toRotationMatrix();
  const Vector3d origin = beam.T_world_sonar.translation();
  const double a = 0.5 * sensor.beam_width_horizontal_rad;
  const double t = std::tan(0.5 * sensor.beam_width_vertical_rad);
  const double t_out = t / std::cos(a);
  auto world = [&](const Vector3d& n) { return Vector3d(R_world_beam * n); };
  const WedgePlanes planes{world({-std::sin(a), std::cos(a), 0.0}),   // azimuth <= a
                           world({-std::sin(a), -std::cos(a), 0.0}),  // azimuth >= -a
                           {world({-t, 0, 1}), world({-t, 0, -1})},
                           {world({-t_out, 0, 1}), world({-t_out, 0, -1})}};
  const auto [k_lo, k_hi] = WedgeKeyBounds(R_world_beam, origin, a, t_out, range_m, key_space);
  WedgeCells out;
  const double half = 0.5 * key_space.getResolution();
  for (int x = k_lo[0]; x <= k_hi[0]; ++x) {
    for (int y = k_lo[1]; y <= k_hi[1]; ++y) {
      for (int z = k_lo[2]; z <= k_hi[2]; ++z) {
        const octomap::OcTreeKey key(static_cast<octomap::key_type>(x),
                                     static_cast<octomap::key_type>(y),
                                     static_cast<octomap::key_type>(z));
        const Vector3d centre = Vector3d(key_space.keyToCoord(key[0]), key_space.keyToCoord(key[1]),
                                         key_space.keyToCoord(key[2])) -
                                origin;
        // Quick rejection: the box's nearest point is beyond range.
        const Vector3d nearest = centre.cwiseAbs() - Vector3d::Constant(half);
        if (nearest.cwiseMax(0.0).norm() > range_m) continue;
        const CellInWedge in = Classify(centre, half, range_m, planes);
        if (in == CellInWedge::kInside) out.inside.insert(key);
        if (in == CellInWedge::kUndecided) out.undecided.insert(key);
      }
    }
  }
  return out;
}

BeamCoverage MeasureBeamCoverage(const mapping::Beam& beam, const mapping::SensorGeometry& sensor,
                                 double range_m, int rays_horizontal, int rays_vertical,
                                 const octomap::OcTree& key_space) {
  return MeasureBeamCoverage(beam, sensor, range_m, rays_horizontal, rays_vertical, key_space,
                             ExactWedgeCells(beam, sensor, range_m, key_space));
}

namespace {

// The coverage of `wedge` by the cells a beam marked (`visited`, after `visits` cell visits).
BeamCoverage CoverageOf(const mapping::KeySet& visited, std::size_t visits,
                        const WedgeCells& wedge) {
  BeamCoverage c;
  c.wedge_cells = wedge.inside.size();
  c.undecided_cells = wedge.undecided.size();
  c.visited_cells = visited.size();
  c.visits = visits;
  std::size_t visited_undecided = 0;
  for (const auto& key : visited) {
    if (wedge.inside.contains(key)) {
      ++c.covered_cells;
    } else if (wedge.undecided.contains(key)) {
      ++visited_undecided;
    } else {
      ++c.visited_outside;
    }
  }
  auto ratio = [](std::size_t n, std::size_t d) {
    return d == 0 ? 0.0 : static_cast<double>(n) / static_cast<double>(d);
  };
  c.coverage = ratio(c.covered_cells, c.wedge_cells);
  // The exact set is `inside` plus some of `undecided`: the worst case adds the unvisited ones,
  // the best case the visited ones.
  c.coverage_lower =
      ratio(c.covered_cells, c.wedge_cells + (c.undecided_cells - visited_undecided));
  c.coverage_upper = ratio(c.covered_cells + visited_undecided, c.wedge_cells + visited_undecided);
  c.visits_per_cell = ratio(c.visits, c.visited_cells);
  return c;
}

}  // namespace

BeamCoverage MeasureBeamCoverage(const mapping::Beam& beam, const mapping::SensorGeometry& sensor,
                                 double range_m, int rays_horizontal, int rays_vertical,
                                 const octomap::OcTree& key_space, const WedgeCells& wedge) {
  const auto directions = mapping::BeamRayDirections(sensor, rays_horizontal, rays_vertical);
  const double obstacle[] = {range_m};
  mapping::BeamKeys keys = mapping::RayCastBeamKeys(key_space, beam, directions, obstacle, 0.0);
  keys.free.insert(keys.occupied.begin(), keys.occupied.end());
  return CoverageOf(keys.free, keys.visits, wedge);
}

BeamCoverage MeasureExactBeamCoverage(const mapping::Beam& beam,
                                      const mapping::SensorGeometry& sensor, double range_m,
                                      const octomap::OcTree& key_space, const WedgeCells& wedge) {
  const double obstacle[] = {range_m};
  mapping::BeamKeys keys = mapping::ExactBeamKeys(key_space, sensor, beam, obstacle, 0.0);
  keys.free.insert(keys.occupied.begin(), keys.occupied.end());
  return CoverageOf(keys.free, keys.visits, wedge);
}

}  // namespace sonarbench::sim
