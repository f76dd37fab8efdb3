#include "sonarbench/sim/world/scene.hpp"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <sstream>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/mapping_yaml.hpp"
#include "sonarbench/sim/world/mesh_file.hpp"

namespace sonarbench::sim {
namespace {

using mapping::kDegToRad;

Eigen::Vector3d ToVector(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

// A waypoint's position [m]. The ray tracer works in single precision: its step is about a
// millimetre 10 km from the origin.
constexpr double kMaxWaypointM = 1e4;
Eigen::Vector3d CheckedPosition(YamlReader& node, const std::array<double, 3>& position) {
  const Eigen::Vector3d p = ToVector(position);
  if (!(p.cwiseAbs().maxCoeff() <= kMaxWaypointM)) {
    node.Fail("position_m",
              "coordinates within 10000 m of the origin (the ray tracer's single "
              "precision)");
  }
  return p;
}

Eigen::Isometry3d ReadPose(YamlReader& node) {
  std::array<double, 3> position{0, 0, 0};
  std::array<double, 3> rpy_deg{0, 0, 0};
  node.Optional("position_m", position);
  node.Optional("rpy_deg", rpy_deg);
  return mapping::PoseFromXyzRpy(ToVector(position), ToVector(rpy_deg) * kDegToRad);
}

MeshSpec ReadMesh(YamlReader& node, const std::vector<Material>& materials) {
  MeshSpec m;
  std::string type;
  node.Required("name", m.name, Name());
  node.Required("type", type, OneOf({"tank", "box", "plane", "height_field", "file"}));
  m.type = type == "tank"           ? MeshSpec::Type::kTank
           : type == "plane"        ? MeshSpec::Type::kPlane
           : type == "box"          ? MeshSpec::Type::kBox
           : type == "height_field" ? MeshSpec::Type::kHeightField
                                    : MeshSpec::Type::kFile;
  if (type.empty()) {
    // The type was refused (or missing): which of these keys belong is unknown, so none is
    // read and none is reported as unknown.
    for (const char* key :
         {"file", "scale", "size_m", "cell_m", "amplitude_m", "wavelength_m", "roughness_m"}) {
      node.Ignore(key);
    }
  } else if (m.type == MeshSpec::Type::kFile) {
    node.Required("file", m.file.path, NonEmpty());
    m.file.where = node.WhereOf("file");
    node.Optional("scale", m.file.scale,
                  YamlReader::Check<std::array<double, 3>>(
                      [](const std::array<double, 3>& s) -> std::optional<std::string> {
                        if (s[0] > 0 && s[1] > 0 && s[2] > 0) return std::nullopt;
                        return "three positive scale factors [x, y, z]";
                      }));
  } else {
    node.Required("size_m", m.size_m,
                  YamlReader::Check<std::array<double, 3>>(
                      [](const std::array<double, 3>& s) -> std::optional<std::string> {
                        if (s[0] > 0 && s[1] > 0 && s[2] >= 0) return std::nullopt;
                        return "sizes x > 0, y > 0, z >= 0";
                      }));
  }
  m.T_world_mesh = ReadPose(node);
  if (m.type == MeshSpec::Type::kHeightField) {
    node.Required("cell_m", m.height_field.cell_m, Positive());
    node.Optional("amplitude_m", m.height_field.amplitude_m, NonNegative());
    node.Optional("wavelength_m", m.height_field.wavelength_m, Positive());
    node.Optional("roughness_m", m.height_field.roughness_m, NonNegative());
  }
  node.Optional("fill", m.fill);
  node.Optional("truth", m.truth);
  std::string material;
  node.Required("material", material, Name());
  bool found = false;
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (materials[i].name == material) {
      m.material = i;
      found = true;
    }
  }
  if (!found) {
    m.material = materials.size();  // none: no check on the material's properties follows
    if (!material.empty()) {        // an empty one was refused already (missing or "")
      node.Fail("material", "the name of a material under 'materials', got '" + material + "'");
    }
  }
  node.RejectUnknownKeys();
  return m;
}

Trajectory ReadTrajectory(YamlReader& node) {
  Trajectory t;
  std::string type;
  node.Required("type", type, OneOf({"static", "waypoints"}));
  if (type.empty()) {
    // The type was refused (or missing): its keys are neither read nor reported as unknown.
    for (const char* key : {"position_m", "rpy_deg", "waypoints"}) node.Ignore(key);
  } else if (type == "static") {
    Waypoint w;
    std::array<double, 3> position{0, 0, 0};
    std::array<double, 3> rpy_deg{0, 0, 0};
    node.Required("position_m", position);
    node.Optional("rpy_deg", rpy_deg);
    w.position_m = CheckedPosition(node, position);
    w.rpy_rad = ToVector(rpy_deg) * kDegToRad;
    t.waypoints.push_back(w);
  } else {
    for (YamlReader& item : node.Sequence("waypoints")) {
      Waypoint w;
      std::array<double, 3> position{0, 0, 0};
      std::array<double, 3> rpy_deg{0, 0, 0};
      item.Required("time_s", w.time_s, NonNegative());
      item.Required("position_m", position);
      item.Optional("rpy_deg", rpy_deg);
      item.RejectUnknownKeys();
      w.position_m = CheckedPosition(item, position);
      w.rpy_rad = ToVector(rpy_deg) * kDegToRad;
      if (!t.waypoints.empty() && w.time_s <= t.waypoints.back().time_s) {
        item.Fail("time_s", "a time later than the previous waypoint's");
      }
      t.waypoints.push_back(w);
    }
  }
  node.RejectUnknownKeys();
  return t;
}

}  // namespace

Eigen::Isometry3d Trajectory::T_world_vehicle(double time_s) const {
  auto pose_of = [](const Waypoint& w) { return mapping::PoseFromXyzRpy(w.position_m, w.rpy_rad); };
  if (time_s <= waypoints.front().time_s) return pose_of(waypoints.front());
  if (time_s >= waypoints.back().time_s) return pose_of(waypoints.back());
  std::size_t i = 1;
  while (waypoints[i].time_s < time_s) ++i;
  const Waypoint& a = waypoints[i - 1];
  const Waypoint& b = waypoints[i];
  const double s = (time_s - a.time_s) / (b.time_s - a.time_s);
  const Eigen::Quaterniond qa(pose_of(a).linear());
  const Eigen::Quaterniond qb(pose_of(b).linear());
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = qa.slerp(s, qb).toRotationMatrix();
  pose.translation() = (1.0 - s) * a.position_m + s * b.position_m;
  return pose;
}

namespace {

// Scenes may extend one another this deep at most (a chain longer than this is surely a loop).
constexpr std::size_t kMaxExtends = 8;

// The most a rough mirror of spread σ [rad] can glint, as a fraction of a perfect (Lambertian)
// reflector's echo: the lobe g exp(-α²/2σ²) of a reflector sending I(α) = g P/π exp(-α²/2σ²)
// per steradian of the power P it meets carries g P/π · 2πσ² at most (∫ exp(-α²/2σ²) dΩ ≤ 2πσ²),
// so it sends no more than P while g ≤ 1/(2σ²).
double MostGlint(double spread_rad) { return 0.5 / (spread_rad * spread_rad); }

// A scene's materials, by name: with a base, one the base has is replaced and a new one added;
// a name the file itself gave already is refused (which of the two would count is anyone's guess).
void ReadMaterials(YamlReader& root, bool extending, std::vector<Material>& materials) {
  if (extending && !root.Has("materials")) return;
  std::vector<std::string> names;
  for (YamlReader& item : root.Sequence("materials")) {
    Material m;
    item.Required("name", m.name, Name());
    item.Required("reflectivity", m.reflectivity, InRange(0.0, 1.0));
    item.Optional("backscatter_exponent", m.backscatter_exponent, InRange(0.0, 100.0));
    item.Optional("specular", m.specular, InRange(0.0, 1.0));
    double spread_deg = 0.0;
    item.Optional("specular_spread_deg", spread_deg, InRange(0.0, 30.0));
    m.specular_spread_rad = spread_deg * kDegToRad;
    item.Optional("glint", m.glint, NonNegative());
    if (m.glint > 0.0 && m.specular_spread_rad <= 0.0) {
      item.Fail("glint", "specular_spread_deg > 0 (the lobe the glint falls over), got 0");
    } else if (const double most = MostGlint(m.specular_spread_rad); m.glint > most) {
      std::ostringstream expected;
      expected << "at most 1/(2σ²) = " << most << " for specular_spread_deg " << spread_deg
               << " (all the incident sound sent into the glint's lobe), got " << m.glint;
      item.Fail("glint", expected.str());
    }
    item.RejectUnknownKeys();
    if (std::ranges::find(names, m.name) != names.end()) {
      item.Fail("name", "a material name not used before in this file, got '" + m.name + "'");
    }
    names.push_back(m.name);
    const auto same = std::find_if(materials.begin(), materials.end(),
                                   [&](const Material& b) { return b.name == m.name; });
    if (same != materials.end() && extending) {
      *same = m;
    } else {
      materials.push_back(m);
    }
  }
}

// A scene's meshes and vehicle parts, added to its base's: their names must be new in both lists.
void ReadMeshes(YamlReader& root, bool extending, Scene& scene) {
  const auto name_used = [&](const std::string& name) {
    const auto same = [&](const MeshSpec& m) { return m.name == name; };
    return std::ranges::any_of(scene.meshes, same) || std::ranges::any_of(scene.vehicle, same);
  };
  if (!extending || root.Has("meshes")) {
    for (YamlReader& item : root.Sequence("meshes")) {
      MeshSpec mesh = ReadMesh(item, scene.materials);
      if (name_used(mesh.name)) {
        item.Fail("name", "a mesh name not used before in the scene, got '" + mesh.name + "'");
      }
      scene.meshes.push_back(std::move(mesh));
    }
  }
  if (root.Has("vehicle")) {
    for (YamlReader& item : root.Sequence("vehicle")) {
      for (const char* key : {"truth", "fill"}) {
        if (item.Has(key)) {
          item.Fail(key, std::string("no '") + key + "' key: a vehicle part is never ground truth");
        }
      }
      MeshSpec part = ReadMesh(item, scene.materials);
      part.truth = false;
      if (name_used(part.name)) {
        item.Fail("name", "a mesh name not used before in the scene, got '" + part.name + "'");
      }
      if (part.material < scene.materials.size() && scene.materials[part.material].specular > 0.0) {
        item.Fail("material",
                  "a material with specular 0 (the multipath is not traced off the "
                  "vehicle), got '" +
                      scene.materials[part.material].name + "' with specular " +
                      FormatMetricValue(scene.materials[part.material].specular));
      }
      scene.vehicle.push_back(std::move(part));
    }
  }
}

// A scene's navigation error, over its base's.
void ReadNavigation(YamlReader& nav, NavigationError& n) {
  nav.Optional("drift_m_per_s", n.drift_m_per_s);
  nav.Optional("position_noise_m", n.position_noise_m, InRange(0.0, 100.0));
  // Only the keys given change the base's (a round trip through degrees could move it).
  const auto read_degrees = [&](const char* key, double low, double high, double& out_rad) {
    if (!nav.Has(key)) return;
    double degrees = 0.0;
    nav.Required(key, degrees, InRange(low, high));
    out_rad = degrees * kDegToRad;
  };
  read_degrees("heading_drift_deg_per_s", -90.0, 90.0, n.heading_drift_rad_per_s);
  read_degrees("heading_noise_deg", 0.0, 90.0, n.heading_noise_rad);
  nav.RejectUnknownKeys();
}

std::string Resolve(const YamlReader& root, const std::string& file) {
  return ResolveScenePath(root.file(), file);
}

// Said beside a file the scene names that is not there.
std::string WhereLooked(const std::string& resolved) {
  std::error_code error;
  if (std::filesystem::exists(std::filesystem::symlink_status(resolved, error))) return "";
  return " (a relative path is read from the scene file's folder, then from sonarbench's own: " +
         std::string(SONARBENCH_DATA_DIR) + ")";
}

Scene LoadSceneIn(const std::string& path, const Budgets& budgets, std::vector<std::string>& chain);

// The scene that `root` extends, loaded (and its errors reported) first; none if it extends none.
std::optional<Scene> LoadBase(YamlReader& root, const std::string& path, const Budgets& budgets,
                              std::vector<std::string>& chain) {
  std::string extends;
  root.Optional("extends", extends, NonEmpty());
  // A base that is named but refused: what the scene lacks cannot be told without it.
  if (root.Has("extends") && extends.empty()) root.ThrowIfErrors();
  if (extends.empty()) return std::nullopt;
  const std::string base_path = Resolve(root, extends);
  chain.push_back(std::filesystem::path(path).lexically_normal().string());
  if (chain.size() > kMaxExtends) {
    root.Fail("extends", "expected at most " + std::to_string(kMaxExtends) +
                             " scenes extending one another (" + chain.front() + " extends " +
                             std::to_string(chain.size()) + " deep before " + base_path + ")");
    root.ThrowIfErrors();
  }
  if (std::find(chain.begin(), chain.end(), base_path) != chain.end()) {
    std::string loop;
    for (const std::string& file : chain) loop += file + " -> ";
    root.Fail("extends", "a scene outside the chain of extends (" + loop + base_path + ")");
    root.ThrowIfErrors();
  }
  Scene base = LoadSceneIn(base_path, budgets, chain);
  chain.pop_back();
  return base;
}

// The scene's own keys: name, sensor model, seed, sweeps and start angle (over a base's).
void ReadSceneKeys(YamlReader& root, bool has_base, Scene& scene) {
  root.Required("name", scene.name, Name());
  if (!has_base) {
    root.Required("sensor_model", scene.sensor_model_file, NonEmpty());
  } else if (root.Has("sensor_model")) {
    root.Fail("sensor_model", "no sensor_model: a scene that extends another takes its model");
  }
  root.Optional("seed", scene.seed);
  if (has_base) {
    root.Optional("sweeps", scene.sweeps, IntInRange(1, 100000));
  } else {
    root.Required("sweeps", scene.sweeps, IntInRange(1, 100000));
  }
  if (root.Has("start_head_angle_deg")) {
    double start_deg = 0.0;
    root.Required("start_head_angle_deg", start_deg, InRange(-360.0, 360.0));
    scene.start_head_angle_rad = start_deg * kDegToRad;
  }
}

// Reads the mesh files of meshes[first...] (resolved as ResolveScenePath does); each error,
// naming where the scene names the file and the mesh, goes to `errors`.
void LoadMeshFiles(const YamlReader& root, std::vector<MeshSpec>& meshes, std::size_t first,
                   double max_triangles, std::vector<std::string>& errors) {
  for (std::size_t i = first; i < meshes.size(); ++i) {
    MeshSpec& mesh = meshes[i];
    if (mesh.type != MeshSpec::Type::kFile) continue;
    mesh.file.path = Resolve(root, mesh.file.path);
    try {
      MeshFileData data = LoadMeshFile(mesh.file.path, max_triangles);
      mesh.file.vertices = std::move(data.vertices);
      mesh.file.triangles = std::move(data.triangles);
    } catch (const InputError& e) {
      errors.push_back(mesh.file.where + ": mesh '" + mesh.name + "': " + e.what() +
                       WhereLooked(mesh.file.path));
    }
  }
}

// The scene's sections after its meshes: trajectory, navigation, mounting, acoustics (checked
// here, applied over the model later: returned), mapping and criteria.
std::optional<YamlReader> ReadSections(YamlReader& root, bool has_base, Scene& scene,
                                       std::optional<Eigen::Isometry3d>& T_vehicle_sonar) {
  if (!has_base || root.Has("trajectory")) {
    YamlReader trajectory = root.Child("trajectory");
    scene.trajectory = ReadTrajectory(trajectory);
  }
  if (auto nav = root.OptionalChild("navigation")) ReadNavigation(*nav, scene.navigation);
  if (auto mounting = root.OptionalChild("sonar_mounting")) {
    T_vehicle_sonar = ReadPose(*mounting);
    mounting->RejectUnknownKeys();
  }
  // Settings the operator chooses per deployment (gain, AD window) and how much multipath the
  // place needs are the scene's to change.
  std::optional<YamlReader> acoustics = root.OptionalChild("sonar_acoustics");
  if (acoustics) {
    Acoustics checked;
    ReadAcoustics(*acoustics, checked);
    acoustics->RejectUnknownKeys();
  }
  // Checked here, applied over the sensor model's mapping defaults once the model is read.
  if (auto mapping = root.OptionalChild("mapping")) {
    [[maybe_unused]] const mapping::MapperConfig checked =
        io::ReadMapperConfig(*mapping, scene.mapping);
  }
  if (auto criteria = root.OptionalChild("criteria")) {
    std::vector<std::string> mesh_names;
    for (const MeshSpec& mesh : scene.meshes) mesh_names.push_back(mesh.name);
    scene.criteria = ReadCriteria(*criteria, mesh_names, has_base ? &scene.criteria : nullptr);
  }
  return acoustics;
}

// LoadScene, with the files being extended (the chain) that led to `path`.
Scene LoadSceneIn(const std::string& path, const Budgets& budgets,
                  std::vector<std::string>& chain) {
  YamlReader root = YamlReader::FromFile(path);
  const std::optional<Scene> base = LoadBase(root, path, budgets, chain);
  Scene scene = base ? *base : Scene{};
  scene.file = path;
  if (base) scene.extends.insert(scene.extends.begin(), base->file);
  ReadSceneKeys(root, base.has_value(), scene);
  ReadMaterials(root, base.has_value(), scene.materials);
  const std::size_t base_meshes = scene.meshes.size();
  const std::size_t base_vehicle = scene.vehicle.size();
  ReadMeshes(root, base.has_value(), scene);
  std::optional<Eigen::Isometry3d> T_vehicle_sonar;
  std::optional<YamlReader> acoustics =
      ReadSections(root, base.has_value(), scene, T_vehicle_sonar);
  root.RejectUnknownKeys();
  root.ThrowIfErrors();

  // Mesh files and the sensor model are their own files, read (and their errors reported, all
  // at once) only once the scene is sound; a base's were read with it.
  std::vector<std::string> errors;
  LoadMeshFiles(root, scene.meshes, base_meshes, budgets.max_triangles, errors);
  LoadMeshFiles(root, scene.vehicle, base_vehicle, budgets.max_triangles, errors);
  if (!base) {
    scene.sensor_model_file = Resolve(root, scene.sensor_model_file);
    try {
      scene.sensor = LoadSensorModel(scene.sensor_model_file);
      scene.mapping = scene.sensor.mapping;
    } catch (const InputError& e) {
      errors.push_back(root.WhereOf("sensor_model") + ": sensor_model: " + e.what() +
                       WhereLooked(scene.sensor_model_file));
    }
  }
  if (!errors.empty()) {
    std::string all = errors.front();
    for (std::size_t i = 1; i < errors.size(); ++i) all += "\n" + errors[i];
    throw InputError(all);
  }
  if (auto mapping = root.OptionalChild("mapping")) {
    scene.mapping = io::ReadMapperConfig(*mapping, scene.mapping);
    root.ThrowIfErrors();
  }
  if (T_vehicle_sonar) scene.sensor.geometry.T_vehicle_sonar = *T_vehicle_sonar;
  if (acoustics) {
    ReadAcoustics(*acoustics, scene.sensor.acoustics);
    CheckAcoustics(*acoustics, scene.sensor.acoustics, scene.sensor.geometry);
    root.ThrowIfErrors();
  }
  return scene;
}

}  // namespace

std::string ResolveScenePath(const std::string& scene_file, const std::string& file) {
  namespace fs = std::filesystem;
  const fs::path named(file);
  if (!named.is_relative()) return named.lexically_normal().string();
  const fs::path beside = (fs::path(scene_file).parent_path() / named).lexically_normal();
  std::error_code error;
  if (fs::exists(beside, error)) return beside.string();
  const fs::path shipped = (fs::path(SONARBENCH_DATA_DIR) / named).lexically_normal();
  return fs::exists(shipped, error) ? shipped.string() : beside.string();
}

Scene LoadScene(const std::string& path, const Budgets& budgets) {
  std::vector<std::string> chain;
  Scene scene = LoadSceneIn(path, budgets, chain);
  scene.budgets = budgets;
  return scene;
}

}  // namespace sonarbench::sim
