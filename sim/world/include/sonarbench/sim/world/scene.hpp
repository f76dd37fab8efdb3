#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/sim/world/budget.hpp"
#include "sonarbench/sim/world/criteria.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

namespace sonarbench::sim {

/// Acoustic properties of a surface.
struct Material {
  std::string name;
  /// Backscatter at normal incidence, as a fraction of a perfect reflector's [0-1].
  double reflectivity = 0.5;
  /// Per-ray echo falls as cos^n of the incidence angle (n = 1 is Lambert's law per ray).
  double backscatter_exponent = 1.0;
  /// Fraction of the incident energy reflected specularly [0-1]: a ray that hits goes on in the
  /// mirror direction, and what it meets echoes back along the same path (multipath).
  double specular = 0.0;
  /// How rough a mirror it is: the standard deviation, per axis across the mirror direction, of
  /// the direction a reflected ray takes [rad] (scene key specular_spread_deg). 0: a perfect
  /// mirror; a few degrees spread each multipath ghost over bins and head angles, and the echo's
  /// way back is tilted independently of its way out.
  double specular_spread_rad = 0.0;
  /// The rough mirror's glint: what it sends towards the receiver around its mirror direction,
  /// as a fraction of a perfect reflector's echo: g · exp(-α²/2σ²), α the angle between the
  /// mirror direction and the way to the receiver, σ specular_spread_rad (so it needs one). A
  /// smooth surface sends more than a perfect diffuse one towards its mirror direction: g is at
  /// most 1/(2σ²), where the lobe holds all the sound the surface meets (25.6 for σ = 8°; a
  /// lobe holding the specular fraction s alone, s/(2σ²)).
  /// Heard wherever the diffuse backscatter is: at normal incidence, and where mirror paths
  /// turn back to the sonar (a corner of two walls and the floor sends sound straight back).
  /// The sonar's mirror image, not sound scattered into the place: it takes the pulse's skirts
  /// but feeds neither the reverberation nor the second trip. 0, the default: none.
  double glint = 0.0;

  bool operator==(const Material&) const = default;
};

/// A height field's relief: height = amplitude·sin(2πx/λ)·cos(2πy/λ) plus a seeded random
/// roughness of the given standard deviation, on a grid of `cell_m` [m].
struct HeightFieldSpec {
  double cell_m = 0.1;
  double amplitude_m = 0.0;
  double wavelength_m = 5.0;
  double roughness_m = 0.0;
};

/// A mesh file: its path (resolved as ResolveScenePath does), where the scene names it
/// ("FILE:LINE:COLUMN", for messages), the scale applied to its coordinates along its own x, y, z
/// before the pose, and its triangles as loaded.
struct MeshFileSpec {
  std::string path;
  std::string where;
  std::array<double, 3> scale{1, 1, 1};
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// A mesh, as the scene file describes it: procedural, or loaded from a mesh file.
struct MeshSpec {
  enum class Type { kTank, kBox, kPlane, kHeightField, kFile };
  std::string name;
  Type type = Type::kBox;
  /// kTank: inner size x, y, wall height; kBox: size; kPlane: size x, y (z ignored);
  /// kHeightField: extent x, y (z ignored) [m].
  std::array<double, 3> size_m{1, 1, 1};
  /// Pose of the mesh frame in the world. kTank: centre of the floor; kBox: centre;
  /// kPlane: centre, normal along the frame's z; kHeightField: centre at height 0.
  Eigen::Isometry3d T_world_mesh = Eigen::Isometry3d::Identity();
  HeightFieldSpec height_field;  ///< kHeightField
  MeshFileSpec file;             ///< kFile
  std::size_t material = 0;
  /// Count the cells inside the (closed) mesh as occupied truth, not only its surface.
  bool fill = false;
  /// Part of the ground truth the map is scored against. False for a surface the sonar hears but
  /// a map should not hold, such as the water surface (a mirror for multipath).
  bool truth = true;
};

/// A waypoint of the vehicle: time [s] and pose of the vehicle in the world.
struct Waypoint {
  double time_s = 0.0;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy_rad = Eigen::Vector3d::Zero();
};

/// Vehicle poses over time: linear in position, spherical-linear in attitude between waypoints,
/// held constant before the first and after the last. One waypoint is a static vehicle.
struct Trajectory {
  std::vector<Waypoint> waypoints;
  [[nodiscard]] Eigen::Isometry3d T_world_vehicle(double time_s) const;
};

/// Error of the navigation solution the mapper is given (the simulator renders from the true
/// poses). The reported vehicle pose at time t is the true one with its position moved by
/// drift_m_per_s · t plus zero-mean Gaussian noise of σ position_noise_m per axis, and its yaw
/// turned by heading_drift_deg_per_s · t plus noise of σ heading_noise_deg. The noise of beam b
/// draws only from DeriveSeed(seed, b) of its own stream, so it is the same for any thread count.
struct NavigationError {
  std::array<double, 3> drift_m_per_s{0, 0, 0};
  double heading_drift_rad_per_s = 0.0;
  double position_noise_m = 0.0;
  double heading_noise_rad = 0.0;
  [[nodiscard]] bool Any() const {
    return drift_m_per_s != std::array<double, 3>{0, 0, 0} || heading_drift_rad_per_s != 0.0 ||
           position_noise_m != 0.0 || heading_noise_rad != 0.0;
  }
};

/// A scenario: what is in the water, how the vehicle moves, the sonar, and how to map.
struct Scene {
  std::string name;
  std::string file;
  /// The scenes this one extends (`extends:`), its base first, then the base's base and so on.
  std::vector<std::string> extends;
  std::string sensor_model_file;
  /// The sensor model; the scene's optional `sonar_mounting` (position_m, rpy_deg) replaces the
  /// model's mounting, since where the sonar sits is the vehicle's business, not the sonar's, and
  /// its optional `sonar_acoustics` (keys of the model's `acoustics`) replaces those it names:
  /// gain and AD window are set per deployment, and a tank needs more multipath than open water.
  SensorModel sensor;
  std::vector<Material> materials;
  std::vector<MeshSpec> meshes;
  /// Parts of the vehicle the sonar hears (`vehicle:`, meshes as under `meshes`), posed in the
  /// vehicle's body frame (the trajectory's; the sonar sits in it at `sonar_mounting`): they move
  /// with the vehicle, echo and shadow the primary rays that reach them, and are never ground
  /// truth. Their materials are diffuse (specular 0): the multipath is not traced off them.
  std::vector<MeshSpec> vehicle;
  Trajectory trajectory;
  /// The navigation error on the poses the mapper gets (none by default).
  NavigationError navigation;
  /// Full head revolutions to simulate.
  int sweeps = 1;
  /// Head angle of the first beam [rad].
  double start_head_angle_rad = 0.0;
  /// Seed of every random draw in the run (overridable on the command line).
  std::uint64_t seed = 1;
  mapping::MapperConfig mapping;
  /// Pass/fail bounds on the map's metrics (none: the scenario passes when it runs).
  Criteria criteria;
  /// What a run of it may build: set by the command line, not the scene file; checked by
  /// BuildSceneMeshes before anything is built.
  Budgets budgets;
};

/// Loads a scene YAML file and the sensor model it names (relative to the scene file).
///
/// A scene may extend another (`extends: FILE`, relative to it; chains allowed, loops refused):
/// the base is loaded first (its errors name its file), then this file's keys change it:
/// - `name` is required; `sensor_model` is refused (the base's model, as it set it); `seed`,
///   `sweeps` and `start_head_angle_deg` replace the base's;
/// - `materials`: one named as a base material replaces it, a new name is added;
/// - `meshes` and `vehicle`: added to the base's (a name either list uses is an error);
/// - `trajectory` and `sonar_mounting` replace the base's whole;
/// - `navigation`, `sonar_acoustics` and `mapping` (with its `detection`): key by key over
///   the base's;
/// - `criteria`: `expect` replaces the base's, and `metrics`, when given, replace its metrics
///   whole (absent, they stay).
/// A path `file` a scene (or sensor model) names: relative to the folder of `scene_file`; a
/// relative path not found there is looked up in sonarbench's own folder (its sensor-models/ and
/// scenes/meshes/), so a scene saved anywhere can name the shipped models and meshes.
[[nodiscard]] std::string ResolveScenePath(const std::string& scene_file, const std::string& file);

/// Mesh files over `budgets.max_triangles` are refused before they are built; the scene keeps
/// `budgets`.
[[nodiscard]] Scene LoadScene(const std::string& path, const Budgets& budgets = {});

}  // namespace sonarbench::sim
