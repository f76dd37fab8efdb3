#pragma once

// Scenes, sensors and beams the simulator's tests share.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "sonarbench/io/yaml_reader.hpp"
#include "sonarbench/sim/sonar/beam_synthesizer.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/criteria.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/random.hpp"
#include "sonarbench/sim/world/scene.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

using mapping::kDegToRad;

// A sensor with no noise, speckle or self-reflection, and range losses that cancel (spreading
// equals the time-varied gain, no absorption), so echoes can be predicted exactly.
inline SensorModel QuietSensor() {
  SensorModel model;
  model.acoustics.speckle.on = false;
  model.acoustics.noise.level_db = -300.0;
  model.acoustics.gain.absorption_db_per_m = 0.0;
  model.acoustics.gain.spreading_db_per_decade = 20.0;
  model.acoustics.gain.tvg_db_per_decade = 20.0;
  model.acoustics.gain.gain_db = 0.0;
  return model;
}

// A 20 m × 20 m plane `range` metres along the sonar's x axis, turned by `incidence_rad` about z.
inline std::vector<TriangleMesh> Wall(double range, double incidence_rad) {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kPlane;
  spec.size_m = {20.0, 20.0, 0.0};
  spec.T_world_mesh = mapping::PoseFromXyzRpy({range, 0, 0}, {0, 0, 0}) *
                      Eigen::AngleAxisd(incidence_rad, Eigen::Vector3d::UnitZ()) *
                      Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY());
  return {BuildMesh(spec, 0)};
}

// Kolmogorov-Smirnov distance of `sample` from the continuous distribution function `cdf`.
template <typename Cdf>
inline double KsDistance(std::vector<double> sample, Cdf cdf) {
  std::sort(sample.begin(), sample.end());
  const auto n = static_cast<double>(sample.size());
  double d = 0.0;
  for (std::size_t i = 0; i < sample.size(); ++i) {
    const double f = cdf(sample[i]);
    d = std::max({d, f - static_cast<double>(i) / n, static_cast<double>(i + 1) / n - f});
  }
  return d;
}

inline SynthesizedBeam Ping(const SensorModel& sensor, const std::vector<TriangleMesh>& meshes,
                            std::uint64_t seed = 11) {
  const RayTracer tracer(meshes);
  Material material;
  material.reflectivity = 0.5;
  material.backscatter_exponent = 1.0;
  const BeamSynthesizer synthesizer(sensor, tracer, {material});
  return synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), seed);
}

inline double TotalPower(const SynthesizedBeam& beam) {
  return std::accumulate(beam.echo_power.begin(), beam.echo_power.end(), 0.0);
}

// A plate `height` m tall facing the sonar from `range` m along azimuth `azimuth_rad`, spanning
// azimuths azimuth ± half_angle_rad (a chord, so its edges lie exactly on those bearings).
inline std::vector<TriangleMesh> Plate(double range, double azimuth_rad, double half_angle_rad,
                                       double height) {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kPlane;
  spec.size_m = {height, 2.0 * range * std::tan(half_angle_rad), 0.0};
  spec.T_world_mesh =
      mapping::PoseFromXyzRpy({range * std::cos(azimuth_rad), range * std::sin(azimuth_rad), 0},
                              {0, 0, 0}) *
      Eigen::AngleAxisd(azimuth_rad, Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY());
  return {BuildMesh(spec, 0)};
}

// A 0.98 m square plane at z = 0.012 m, centred over the origin.
inline TriangleMesh SmallPlane() {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kPlane;
  spec.size_m = {0.98, 0.98, 0.0};
  spec.T_world_mesh.translation() = Eigen::Vector3d(0, 0, 0.012);
  return BuildMesh(spec, 0);
}

// The criteria of a scene with the meshes "tank" and "crate".
inline Criteria ParseCriteria(const std::string& yaml) {
  YamlReader reader = YamlReader::FromString(yaml, "scene.yaml");
  Criteria criteria = ReadCriteria(reader, {"tank", "crate"});
  reader.ThrowIfErrors();
  return criteria;
}

}  // namespace
}  // namespace sonarbench::sim

namespace sonarbench {
namespace {

// The message a small scene (one material, one mesh, the trajectory; `acoustics`, if any, as its
// sonar_acoustics from line 5) is refused with; "" if it is not.
inline std::string SmallSceneRefusal(const std::string& material, const std::string& mesh,
                                     const std::string& trajectory,
                                     const std::string& acoustics = "") {
  test::TempDir dir;
  const std::string path = (dir.path() / "bad.yaml").string();
  std::ofstream(path) << "name: x\nsensor_model: "
                      << test::SourcePath("sensor-models/shad-micron.yaml") << "\nsweeps: 1\n"
                      << (acoustics.empty() ? "" : "sonar_acoustics:\n" + acoustics)
                      << "materials:\n  - " << material << "\nmeshes:\n  - " << mesh
                      << "\ntrajectory: " << trajectory << "\n";
  return test::InputErrorOf([&] { (void)sim::LoadScene(path); });
}

constexpr const char* kRock = "{name: rock, reflectivity: 0.5}";

constexpr const char* kPlane = "{name: m, type: plane, size_m: [1, 1, 0], material: rock}";

constexpr const char* kStatic = "{type: static, position_m: [0, 0, 0]}";

}  // namespace
}  // namespace sonarbench
