#include "sonarbench/sim/world/budget.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "sonarbench/base/error.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {
namespace {

// One mesh's share of the estimate, and the key that sets it.
struct MeshEstimate {
  double triangles = 0.0;
  double area_m2 = 0.0;
  double fill_m3 = 0.0;
  const char* key = "size_m";
};

MeshEstimate EstimateMesh(const MeshSpec& spec) {
  MeshEstimate e;
  const auto& s = spec.size_m;
  switch (spec.type) {
    case MeshSpec::Type::kPlane:
      e = {2, s[0] * s[1], 0, "size_m"};
      break;
    case MeshSpec::Type::kTank:
      e = {10, s[0] * s[1] + 2 * s[2] * (s[0] + s[1]), 0, "size_m"};
      break;
    case MeshSpec::Type::kBox:
      e = {12, 2 * (s[0] * s[1] + s[1] * s[2] + s[2] * s[0]), s[0] * s[1] * s[2], "size_m"};
      break;
    case MeshSpec::Type::kHeightField:
      // As BuildMesh grids it: at least one cell each way.
      e = {2 * std::max(1.0, s[0] / spec.height_field.cell_m) *
               std::max(1.0, s[1] / spec.height_field.cell_m),
           s[0] * s[1], 0, "cell_m"};
      break;
    case MeshSpec::Type::kFile: {
      e.triangles = static_cast<double>(spec.file.triangles.size());
      e.key = "scale";
      const Eigen::Vector3d scale(spec.file.scale[0], spec.file.scale[1], spec.file.scale[2]);
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL);
      Eigen::Vector3d hi = -lo;
      // A vertex that is not finite is CheckMesh's to refuse, with its own message.
      for (const auto& v : spec.file.vertices) {
        if (!v.allFinite()) continue;
        lo = lo.cwiseMin(scale.cwiseProduct(v));
        hi = hi.cwiseMax(scale.cwiseProduct(v));
      }
      for (const auto& t : spec.file.triangles) {
        const Eigen::Vector3d a = scale.cwiseProduct(spec.file.vertices[t[0]]);
        const Eigen::Vector3d b = scale.cwiseProduct(spec.file.vertices[t[1]]);
        const Eigen::Vector3d c = scale.cwiseProduct(spec.file.vertices[t[2]]);
        const double area = 0.5 * (b - a).cross(c - a).norm();
        if (!std::isnan(area)) e.area_m2 += area;
      }
      if ((hi.array() >= lo.array()).all()) e.fill_m3 = (hi - lo).prod();
      break;
    }
  }
  if (!spec.fill) e.fill_m3 = 0.0;
  return e;
}

std::string Number(double value) {
  if (!std::isfinite(value)) return "unbounded number of";
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

[[noreturn]] void Refuse(const std::string& where, const std::string& what, double estimate,
                         const char* unit, double limit, const char* option) {
  throw InputError(where + ": " + what + " an estimated " + Number(estimate) + " " + unit +
                   ", more than the " + Number(limit) + " this run allows (" + option +
                   " raises the limit; expected a scene this machine can hold)");
}

// A mesh's ground-truth cells at `res` [m]: its surface and, when filled, its inside.
double TruthCells(const MeshEstimate& m, double res) {
  return m.area_m2 / (res * res) + m.fill_m3 / (res * res * res);
}

// A mesh or vehicle part with its estimate; `truth` when it is scored (a scene mesh with truth).
struct Weighed {
  const MeshSpec* spec;
  MeshEstimate estimate;
  bool truth;
};

std::vector<Weighed> WeighMeshes(const Scene& scene) {
  std::vector<Weighed> weighed;
  for (const auto* list : {&scene.meshes, &scene.vehicle}) {
    for (const MeshSpec& spec : *list) {
      weighed.push_back({&spec, EstimateMesh(spec), list == &scene.meshes && spec.truth});
    }
  }
  return weighed;
}

}  // namespace

SceneEstimate EstimateScene(const Scene& scene) {
  SceneEstimate e;
  const double res = scene.mapping.resolution_m;
  for (const Weighed& mesh : WeighMeshes(scene)) {
    e.triangles += mesh.estimate.triangles;
    if (mesh.truth) e.truth_cells += TruthCells(mesh.estimate, res);
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL);
  Eigen::Vector3d hi = -lo;
  for (const Waypoint& w : scene.trajectory.waypoints) {
    lo = lo.cwiseMin(w.position_m);
    hi = hi.cwiseMax(w.position_m);
  }
  if (scene.trajectory.waypoints.empty()) lo = hi = Eigen::Vector3d::Zero();
  const double mount = scene.sensor.geometry.T_vehicle_sonar.translation().norm();
  e.map_cells = MapCellsEstimate(scene.sensor.geometry, scene.sensor.geometry.MaxRangeM(), res,
                                 lo.array() - mount, hi.array() + mount);
  return e;
}

double MapCellsEstimate(const mapping::SensorGeometry& sensor, double range_m, double resolution_m,
                        const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  // The zone of a sphere the beams sweep about the head's axis, stretched along each axis by the
  // box the sonar moves in.
  const double r = range_m;
  const double zone = 4.0 / 3.0 * std::numbers::pi * r * r * r *
                      std::sin(0.5 * std::min(sensor.beam_width_vertical_rad, std::numbers::pi));
  const Eigen::Vector3d stretch = Eigen::Vector3d::Ones() + (hi - lo) / (2.0 * r);
  return zone * stretch.prod() / (resolution_m * resolution_m * resolution_m);
}

void CheckMapCells(double estimate, const Budgets& budgets, const std::string& what) {
  if (!(estimate <= budgets.max_cells)) {
    Refuse(what, "'mapping.resolution_m' and the sonar's range give a map of", estimate, "cells",
           budgets.max_cells, "--max-cells");
  }
}

void CheckBeamsMapCells(std::span<const mapping::Beam> beams, const mapping::SensorGeometry& sensor,
                        double resolution_m, const Budgets& budgets, const std::string& what) {
  // The map reaches as far as the longest beam, whatever the sensor model says.
  Eigen::Vector3d lo = Eigen::Vector3d::Zero();
  Eigen::Vector3d hi = Eigen::Vector3d::Zero();
  double reach_m = sensor.MaxRangeM();
  // OctoMap's keys address 2^15 cells each way from the origin.
  const double half_range_m = 32768.0 * resolution_m;
  for (std::size_t b = 0; b < beams.size(); ++b) {
    const Eigen::Vector3d p = beams[b].T_world_sonar.translation();
    lo = b == 0 ? p : lo.cwiseMin(p);
    hi = b == 0 ? p : hi.cwiseMax(p);
    const double beam_reach_m =
        beams[b].bin_size_m * static_cast<double>(beams[b].intensities.size());
    reach_m = std::max(reach_m, beam_reach_m);
    if (!(p.cwiseAbs().maxCoeff() + beam_reach_m < half_range_m)) {
      throw InputError(what + ": beam " + std::to_string(b) + " at (" + Number(p.x()) + ", " +
                       Number(p.y()) + ", " + Number(p.z()) + ") m reaching " +
                       Number(beam_reach_m) + " m leaves the +-" + Number(half_range_m) +
                       " m a map at 'mapping.resolution_m' " + Number(resolution_m) +
                       " addresses (OctoMap's 16-bit keys)");
    }
  }
  const double estimate = MapCellsEstimate(sensor, reach_m, resolution_m, lo, hi);
  if (!(estimate <= budgets.max_cells)) {
    Refuse(what,
           "its beams reach " + Number(reach_m) +
               " m (the longest: bin size x bins) from poses "
               "spanning " +
               Number((hi - lo).maxCoeff()) + " m; at 'mapping.resolution_m' " +
               Number(resolution_m) + " that gives a map of",
           estimate, "cells", budgets.max_cells, "--max-cells");
  }
}

void CheckBudgets(const Scene& scene, const Budgets& budgets) {
  const SceneEstimate e = EstimateScene(scene);
  const bool triangles = !(e.triangles <= budgets.max_triangles);
  const bool cells = !(e.truth_cells <= budgets.max_cells);
  const double res = scene.mapping.resolution_m;
  // The mesh that weighs most in what is over its limit names the key to change.
  const MeshSpec* heaviest = nullptr;
  const char* key = "size_m";
  double most = -1.0;
  if (triangles || cells) {
    for (const Weighed& mesh : WeighMeshes(scene)) {
      if (!triangles && !mesh.truth) continue;
      const MeshEstimate& m = mesh.estimate;
      const double weight = triangles ? m.triangles : TruthCells(m, res);
      if (weight > most || std::isnan(weight)) {
        most = weight;
        heaviest = mesh.spec;
        key = triangles && mesh.spec->type == MeshSpec::Type::kFile ? "file"
              : !triangles && m.fill_m3 > 0                         ? "fill"
                                                                    : m.key;
      }
    }
  }
  const std::string where =
      heaviest ? scene.file + ": mesh '" + heaviest->name + "' '" + key + "'" : scene.file;
  if (triangles) {
    Refuse(where, "its meshes make", e.triangles, "triangles", budgets.max_triangles,
           "--max-triangles");
  }
  if (cells) {
    Refuse(where + " at 'mapping.resolution_m' " + Number(res), "its ground truth takes",
           e.truth_cells, "cells", budgets.max_cells, "--max-cells");
  }
  if (!(e.map_cells <= budgets.max_cells)) {
    // The trajectory's extent, when it is what makes the map large, is the key to change.
    Eigen::Vector3d lo = Eigen::Vector3d::Zero();
    Eigen::Vector3d hi = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < scene.trajectory.waypoints.size(); ++i) {
      const Eigen::Vector3d& p = scene.trajectory.waypoints[i].position_m;
      lo = i == 0 ? p : lo.cwiseMin(p);
      hi = i == 0 ? p : hi.cwiseMax(p);
    }
    const double span = (hi - lo).maxCoeff();
    if (span > 2.0 * scene.sensor.geometry.MaxRangeM()) {
      Refuse(scene.file + ": 'trajectory' (its waypoints span " + Number(span) + " m)",
             "with 'mapping.resolution_m' " + Number(res) + " it gives a map of", e.map_cells,
             "cells", budgets.max_cells, "--max-cells");
    }
  }
  CheckMapCells(e.map_cells, budgets, scene.file);
  const double beams = scene.sweeps * scene.sensor.geometry.BeamsPerSweep();
  if (!(beams <= budgets.max_beams)) {
    Refuse(scene.file + ": 'sweeps' " + std::to_string(scene.sweeps), "its sweeps make", beams,
           "beams", budgets.max_beams, "--max-beams");
  }
}

}  // namespace sonarbench::sim
