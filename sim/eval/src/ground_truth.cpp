#include "sonarbench/sim/eval/ground_truth.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <map>
#include <numbers>

namespace sonarbench::sim {
namespace {

using Eigen::Vector3d;

// Adds to `cells` every cell whose half-open box the triangle a, b, c crosses or touches.
void AddTriangleCells(const Vector3d& a, const Vector3d& b, const Vector3d& c,
                      const octomap::OcTree& key_space, mapping::KeySet& cells) {
  const double resolution = key_space.getResolution();
  // Cells are half-open, [lo, hi) on each axis, as OctoMap's coordToKey assigns points: a
  // surface lying exactly on a face between two cells (a floor at z = 0) belongs to the upper
  // cell only. The box tested is [lo, hi - ε] with ε far below any mesh's float precision.
  const double epsilon = 1e-9 * resolution;
  const Vector3d half = Vector3d::Constant(0.5 * (resolution - epsilon));
  const Vector3d lo = a.cwiseMin(b).cwiseMin(c);
  const Vector3d hi = a.cwiseMax(b).cwiseMax(c);
  octomap::OcTreeKey key_lo;
  octomap::OcTreeKey key_hi;
  if (!key_space.coordToKeyChecked(lo.x(), lo.y(), lo.z(), key_lo) ||
      !key_space.coordToKeyChecked(hi.x(), hi.y(), hi.z(), key_hi)) {
    return;  // outside OctoMap's ±(2^15 · resolution) world
  }
  // A vertex on a cell face touches the neighbour too: widen the candidate range by one.
  for (int x = key_lo[0] - 1; x <= key_hi[0] + 1; ++x) {
    for (int y = key_lo[1] - 1; y <= key_hi[1] + 1; ++y) {
      for (int z = key_lo[2] - 1; z <= key_hi[2] + 1; ++z) {
        const octomap::OcTreeKey key(static_cast<octomap::key_type>(x),
                                     static_cast<octomap::key_type>(y),
                                     static_cast<octomap::key_type>(z));
        // Centres in double: OctoMap's float point3d rounds 0.05 up, and a surface lying exactly
        // on a cell face would then touch neither cell.
        const Vector3d centre = Vector3d(key_space.keyToCoord(key[0]), key_space.keyToCoord(key[1]),
                                         key_space.keyToCoord(key[2])) -
                                Vector3d::Constant(0.5 * epsilon);
        if (TriangleBoxOverlap(centre, half, a, b, c)) {
          cells.insert(key);
        }
      }
    }
  }
}

// Adds every cell whose centre lies inside the closed mesh.
// The keys of the corners of a mesh's bounding box.
std::pair<octomap::OcTreeKey, octomap::OcTreeKey> KeyBounds(const TriangleMesh& mesh,
                                                            const octomap::OcTree& key_space) {
  Vector3d lo = Vector3d::Constant(1e300);
  Vector3d hi = Vector3d::Constant(-1e300);
  for (const auto& v : mesh.vertices) {
    lo = lo.cwiseMin(v.cast<double>());
    hi = hi.cwiseMax(v.cast<double>());
  }
  return {key_space.coordToKey(lo.x(), lo.y(), lo.z()),
          key_space.coordToKey(hi.x(), hi.y(), hi.z())};
}

// Rows of cells AddInteriorCells walks (one per y key).
std::size_t FillRows(const TriangleMesh& mesh, const octomap::OcTree& key_space) {
  if (!mesh.fill || !mesh.truth || mesh.triangles.empty()) return 0;
  const auto [k_lo, k_hi] = KeyBounds(mesh, key_space);
  return static_cast<std::size_t>(k_hi[1] - k_lo[1] + 1);
}

void AddInteriorCells(const TriangleMesh& mesh, const octomap::OcTree& key_space,
                      mapping::KeySet& cells, const std::function<void()>& row_done) {
  if (mesh.triangles.empty()) return;
  const auto [k_lo, k_hi] = KeyBounds(mesh, key_space);
  const double res = key_space.getResolution();
  // A row of cell centres along x crosses the closed surface an even number of times; the cells
  // between the 1st and 2nd, 3rd and 4th, ... crossing are inside. The row is nudged off the
  // centres by far more than float rounding and far less than a cell, so that it never runs
  // exactly through an edge or a vertex (which would count one crossing twice).
  const double dy = 1.234567e-4 * res;
  const double dz = 2.345678e-4 * res;
  std::vector<double> crossings;
  for (int y = k_lo[1]; y <= k_hi[1]; ++y) {
    for (int z = k_lo[2]; z <= k_hi[2]; ++z) {
      const double py = key_space.keyToCoord(static_cast<octomap::key_type>(y)) + dy;
      const double pz = key_space.keyToCoord(static_cast<octomap::key_type>(z)) + dz;
      crossings.clear();
      for (const auto& t : mesh.triangles) {
        const Vector3d a = mesh.vertices[t[0]].cast<double>();
        const Vector3d b = mesh.vertices[t[1]].cast<double>();
        const Vector3d c = mesh.vertices[t[2]].cast<double>();
        // Barycentric coordinates of (py, pz) in the triangle's projection on the y-z plane.
        const double d = (b.y() - a.y()) * (c.z() - a.z()) - (c.y() - a.y()) * (b.z() - a.z());
        if (d == 0.0) continue;  // edge-on to the row
        const double u = ((py - a.y()) * (c.z() - a.z()) - (c.y() - a.y()) * (pz - a.z())) / d;
        const double v = ((b.y() - a.y()) * (pz - a.z()) - (py - a.y()) * (b.z() - a.z())) / d;
        if (u < 0.0 || v < 0.0 || u + v > 1.0) continue;
        crossings.push_back(a.x() + u * (b.x() - a.x()) + v * (c.x() - a.x()));
      }
      std::sort(crossings.begin(), crossings.end());
      for (std::size_t i = 0; i + 1 < crossings.size(); i += 2) {
        const octomap::OcTreeKey from = key_space.coordToKey(crossings[i], py, pz);
        for (int x = from[0]; x <= k_hi[0]; ++x) {
          const double cx = key_space.keyToCoord(static_cast<octomap::key_type>(x));
          if (cx > crossings[i + 1]) break;
          if (cx >= crossings[i]) {
            cells.insert(octomap::OcTreeKey(static_cast<octomap::key_type>(x),
                                            static_cast<octomap::key_type>(y),
                                            static_cast<octomap::key_type>(z)));
          }
        }
      }
    }
    row_done();
  }
}

}  // namespace

mapping::KeySet VoxelizeMeshes(std::span<const TriangleMesh> meshes,
                               const octomap::OcTree& key_space, const StageProgress& progress) {
  std::size_t total = 0;
  std::size_t done = 0;
  for (const TriangleMesh& mesh : meshes) {
    total += mesh.truth ? mesh.triangles.size() + FillRows(mesh, key_space) : 0;
  }
  const auto step = [&] {
    if (progress && (++done % 1024 == 0 || done == total)) progress(done, total);
  };
  mapping::KeySet cells;
  for (const TriangleMesh& mesh : meshes) {
    if (!mesh.truth) continue;
    for (const auto& t : mesh.triangles) {
      AddTriangleCells(mesh.vertices[t[0]].cast<double>(), mesh.vertices[t[1]].cast<double>(),
                       mesh.vertices[t[2]].cast<double>(), key_space, cells);
      step();
    }
    if (mesh.fill) AddInteriorCells(mesh, key_space, cells, step);
  }
  return cells;
}

namespace {

// Each beam's index among the distinct beams (the same pose and head angle, bit for bit), and
// whether it is the first of its kind.
std::vector<std::size_t> DistinctBeams(std::span<const BeamPose> beams, std::vector<bool>& first,
                                       std::size_t& distinct) {
  std::map<std::array<double, 13>, std::size_t> seen;
  std::vector<std::size_t> index(beams.size());
  first.assign(beams.size(), false);
  for (std::size_t b = 0; b < beams.size(); ++b) {
    std::array<double, 13> pose{};
    const Eigen::Matrix4d& m = beams[b].T_world_sonar.matrix();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) pose[static_cast<std::size_t>(4 * r + c)] = m(r, c);
    }
    pose[12] = beams[b].head_angle_rad;
    const auto [it, inserted] = seen.emplace(pose, seen.size());
    index[b] = it->second;
    first[b] = inserted;
  }
  distinct = seen.size();
  return index;
}

// Appends [lo, hi] to sorted disjoint `intervals`, merged with the last when they overlap.
void AppendInterval(std::vector<std::pair<double, double>>& intervals, double lo, double hi) {
  if (!intervals.empty() && lo <= intervals.back().second) {
    intervals.back().second = hi;
  } else {
    intervals.emplace_back(lo, hi);
  }
}

// Sorted ranges [m] merged into disjoint intervals, each widened by `tolerance` on both sides.
std::vector<std::pair<double, double>> RangeIntervals(std::vector<float>& hits, double tolerance) {
  std::sort(hits.begin(), hits.end());
  std::vector<std::pair<double, double>> intervals;
  for (const float hit : hits) AppendInterval(intervals, hit - tolerance, hit + tolerance);
  return intervals;
}

// The head's frame in the world: x along the beam, z up (the sonar's axis).
Eigen::Matrix3d WorldFromHead(const BeamPose& pose) {
  return pose.T_world_sonar.linear() *
         Eigen::AngleAxisd(pose.head_angle_rad, Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

DirectEchoes DirectEchoesOf(const mapping::SensorGeometry& sensor, double tolerance_m) {
  DirectEchoes direct;
  direct.half_width_horizontal_rad = 0.5 * sensor.beam_width_horizontal_rad;
  direct.half_width_vertical_rad = 0.5 * sensor.beam_width_vertical_rad;
  direct.tolerance_m = tolerance_m;
  return direct;
}

DirectEchoes::Beam LabelledDirectBeam(const BeamPose& pose, std::span<const BinLabel> labels,
                                      double bin_size_m, double tolerance_m) {
  DirectEchoes::Beam beam;
  beam.origin = pose.T_world_sonar.translation();
  beam.world_to_head = WorldFromHead(pose).transpose();
  for (std::size_t k = 0; k < labels.size(); ++k) {
    if (labels[k].mesh == kNoMesh) continue;
    AppendInterval(beam.ranges, static_cast<double>(k) * bin_size_m - tolerance_m,
                   static_cast<double>(k + 1) * bin_size_m + tolerance_m);
  }
  return beam;
}

bool DirectEchoes::Explains(const Vector3d& centre, double cell_half_diagonal_m) const {
  // A cell's angular radius stays under 30° beyond two half-diagonals, so a direction further
  // than that past the aperture's edge cannot be in it: a cheap test before the angles.
  const double limit = half_width_horizontal_rad + std::numbers::pi / 6.0;
  const double tan_limit = limit < 0.5 * std::numbers::pi ? std::tan(limit) : INFINITY;
  for (const Beam& beam : beams) {
    const Vector3d v = beam.world_to_head * (centre - beam.origin);
    const double range = v.norm();
    if (range > 2.0 * cell_half_diagonal_m &&
        (v.x() <= 0.0 || std::abs(v.y()) > tan_limit * v.x())) {
      continue;
    }
    const double widen = std::asin(std::min(1.0, cell_half_diagonal_m / range));
    if (std::abs(std::atan2(v.y(), v.x())) > half_width_horizontal_rad + widen ||
        std::abs(std::atan2(v.z(), std::hypot(v.x(), v.y()))) > half_width_vertical_rad + widen) {
      continue;
    }
    const auto after = std::upper_bound(
        beam.ranges.begin(), beam.ranges.end(), range,
        [](double r, const std::pair<double, double>& interval) { return r < interval.first; });
    if (after != beam.ranges.begin() && range <= std::prev(after)->second) return true;
  }
  return false;
}

mapping::KeySet ObservableSurfaceCells(const RayTracer& tracer, std::span<const BeamPose> beams,
                                       const mapping::SensorGeometry& sensor, int rays_horizontal,
                                       int rays_vertical, const octomap::OcTree& key_space,
                                       const StageProgress& progress, DirectEchoes* direct) {
  const std::vector<Eigen::Vector3d> directions =
      mapping::BeamRayDirections(sensor, rays_horizontal, rays_vertical);
  const auto max_range = static_cast<float>(sensor.MaxRangeM());
  // Beams alike see alike: each distinct beam is traced once.
  std::vector<bool> first;
  std::size_t distinct = 0;
  const std::vector<std::size_t> index = DistinctBeams(beams, first, distinct);
  if (direct) {
    *direct = DirectEchoesOf(sensor,
                             0.5 * std::sqrt(3.0) * key_space.getResolution() + sensor.bin_size_m);
    direct->beams.assign(distinct, {});
  }
  std::vector<mapping::KeySet> per_thread(static_cast<std::size_t>(omp_get_max_threads()));
  const auto count = static_cast<std::int64_t>(beams.size());
  std::atomic<std::size_t> done = 0;
#pragma omp parallel for schedule(dynamic, 8)
  for (std::int64_t b = 0; b < count; ++b) {
    // The first thread alone reports, so the callback needs no lock.
    const std::size_t finished = done.fetch_add(1, std::memory_order_relaxed);
    if (progress && omp_get_thread_num() == 0) progress(finished, beams.size());
    if (!first[static_cast<std::size_t>(b)]) continue;
    const BeamPose& pose = beams[static_cast<std::size_t>(b)];
    mapping::KeySet& cells = per_thread[static_cast<std::size_t>(omp_get_thread_num())];
    const Eigen::Matrix3d R = WorldFromHead(pose);
    const Eigen::Vector3f origin = pose.T_world_sonar.translation().cast<float>();
    std::vector<float> hits;
    for (const Vector3d& d : directions) {
      const Eigen::Vector3f direction = (R * d).cast<float>();
      if (const auto hit = tracer.Intersect(origin, direction, max_range)) {
        const Eigen::Vector3f p = origin + hit->distance * direction;
        octomap::OcTreeKey key;
        if (key_space.coordToKeyChecked(p.x(), p.y(), p.z(), key)) cells.insert(key);
        if (direct) hits.push_back(hit->distance);
      }
    }
    if (direct) {
      direct->beams[index[static_cast<std::size_t>(b)]] = {
          pose.T_world_sonar.translation(), R.transpose(),
          RangeIntervals(hits, direct->tolerance_m)};
    }
  }
  if (progress) progress(beams.size(), beams.size());
  mapping::KeySet all;
  for (const auto& cells : per_thread) all.insert(cells.begin(), cells.end());
  return all;
}

mapping::KeySet PerfectSensorCells(const RayTracer& tracer, std::span<const BeamPose> beams,
                                   const mapping::SensorGeometry& sensor,
                                   const Acoustics& acoustics, const octomap::OcTree& key_space,
                                   const StageProgress& progress, DirectEchoes* direct) {
  return ObservableSurfaceCells(tracer, beams, sensor, 2 * acoustics.pattern.rays_horizontal,
                                2 * acoustics.pattern.rays_vertical, key_space, progress, direct);
}

}  // namespace sonarbench::sim
