#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "sim_fixtures.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/mapping_yaml.hpp"
#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/world/budget.hpp"
#include "sonarbench/sim/world/scene.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

using test::ThrowsInputErrorWith;

// `message` is one error, the one that holds `expected`.
::testing::AssertionResult IsTheOneError(const std::string& message, const std::string& expected) {
  if (message.find(expected) == std::string::npos || message.find('\n') != std::string::npos) {
    return ::testing::AssertionFailure() << "expected only \"" << expected << "\"; message was:\n"
                                         << message;
  }
  return ::testing::AssertionSuccess();
}

TEST(SceneFile, ShippedScenesLoad) {
  for (const char* name : {"scenes/cras-tank.yaml", "scenes/seabed.yaml"}) {
    SCOPED_TRACE(name);
    const sim::Scene scene = sim::LoadScene(test::SourcePath(name));
    EXPECT_FALSE(scene.meshes.empty());
    EXPECT_EQ(scene.sensor.geometry.num_bins, 399);
    EXPECT_EQ(scene.sensor.geometry.BeamsPerSweep(), 200);
  }
}

TEST(SceneFile, BadSceneNamesItsFileAndKey) {
  test::TempDir dir;
  const std::string path = (dir.path() / "bad.yaml").string();
  std::ifstream in(test::SourcePath("scenes/cras-tank.yaml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("sweeps: 27"), 10, "sweeps: -3");
  text.replace(text.find("sensor_model: ../sensor-models/shad-micron.yaml"), 47,
               "sensor_model: " + test::SourcePath("sensor-models/shad-micron.yaml"));
  std::ofstream(path) << text;
  EXPECT_TRUE(
      ThrowsInputErrorWith([&] { (void)sim::LoadScene(path); }, {path, "'sweeps'", "got '-3'"}));
}

// A mesh whose type is not one is reported by its type alone: its size or file is neither
// asked for nor unknown, since which it should have is what the type would say. So is a
// trajectory's: its position is neither asked for nor unknown.
TEST(SceneFile, AMeshOfNoKnownTypeIsReportedByItsTypeAlone) {
  EXPECT_TRUE(IsTheOneError(
      SmallSceneRefusal(kRock, "{name: m, type: plain, size_m: [1, 1, 0], material: rock}",
                        kStatic),
      "bad.yaml:7:21: key 'meshes[0].type': expected one of: tank, box, plane, height_field, "
      "file, got 'plain'"));
  EXPECT_TRUE(
      IsTheOneError(SmallSceneRefusal(kRock, kPlane, "{type: still, position_m: [0, 0, 0]}"),
                    "key 'trajectory.type': expected one of: static, waypoints, got 'still'"));
}

// A check across keys waits for their values: a glint's spread that is refused is reported as
// refused, not again as the default 0 the glint's check would see; a material whose name is
// refused is not reported again as missing by the mesh that names it.
TEST(SceneFile, ARefusedValueIsNotReportedAgainByTheChecksOnIt) {
  EXPECT_TRUE(IsTheOneError(
      SmallSceneRefusal("{name: rock, reflectivity: 0.5, glint: 0.3, specular_spread_deg: wide}",
                        kPlane, kStatic),
      "key 'materials[0].specular_spread_deg': expected a finite number, got 'wide'"));
  EXPECT_TRUE(IsTheOneError(SmallSceneRefusal("{name: [rock], reflectivity: 0.5}", kPlane, kStatic),
                            "key 'materials[0].name': expected a string, got a list"));
}

// Two materials of one name in one file are refused (the mesh naming it would get either); a
// scene that extends another may still replace the base's.
TEST(SceneFile, AMaterialNamedTwiceInOneFileIsRefused) {
  EXPECT_TRUE(IsTheOneError(
      SmallSceneRefusal("{name: rock, reflectivity: 0.5}\n  - {name: rock, reflectivity: 0.1}",
                        kPlane, kStatic),
      "bad.yaml:6:12: key 'materials[1].name': a material name not used before in this file, got "
      "'rock'"));
}

// "" names no material, mesh or file: refused where it stands, not taken as "none given" (a
// mesh whose material was "" once went on without one and ran out of memory).
TEST(SceneFile, EmptyNamesAreRefused) {
  const char* kEmpty = "expected a non-empty string of at most 4096 bytes, got ''";
  const char* kEmptyName = "expected a name of 1 to 200 bytes, got ''";
  EXPECT_TRUE(IsTheOneError(
      SmallSceneRefusal(kRock, "{name: m, type: plane, size_m: [1, 1, 0], material: ''}", kStatic),
      std::string("bad.yaml:7:57: key 'meshes[0].material': ") + kEmptyName));
  EXPECT_TRUE(IsTheOneError(
      SmallSceneRefusal(kRock, "{name: '', type: plane, size_m: [1, 1, 0], material: rock}",
                        kStatic),
      std::string("key 'meshes[0].name': ") + kEmptyName));
  EXPECT_TRUE(IsTheOneError(
      SmallSceneRefusal(kRock, "{name: m, type: file, file: '', material: rock}", kStatic),
      std::string("key 'meshes[0].file': ") + kEmpty));
  // The material's name is refused; the mesh that names a material it cannot find then is not
  // reported as well.
  EXPECT_TRUE(IsTheOneError(SmallSceneRefusal("{name: '', reflectivity: 0.5}", kPlane, kStatic),
                            std::string("key 'materials[0].name': ") + kEmptyName));
  // Names land in reports: one past the limit is refused, and the message quotes it cut short.
  const std::string long_name(sonarbench::kMaxNameBytes + 1, 'n');
  const std::string refusal = SmallSceneRefusal(
      kRock, "{name: " + long_name + ", type: plane, size_m: [1, 1, 0], material: rock}", kStatic);
  EXPECT_NE(refusal.find("key 'meshes[0].name': expected a name of 1 to 200 bytes"),
            std::string::npos)
      << refusal;
  EXPECT_LT(refusal.size(), 400u);
  test::TempDir dir;
  const std::string model = test::SourcePath("sensor-models/shad-micron.yaml");
  const std::string scene_tail =
      "\nsweeps: 1\nmaterials: [{name: m, reflectivity: 0.5}]\n"
      "meshes: [{name: bed, type: plane, size_m: [1, 1, 0], material: m}]\n"
      "trajectory: {type: static, position_m: [0, 0, 1]}\n";
  for (const auto& [text, key, expected] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {"name: ''\nsensor_model: " + model + scene_tail, "'name'", kEmptyName},
           {"name: x\nsensor_model: ''" + scene_tail, "'sensor_model'", kEmpty},
           {"name: x\nextends: ''\n", "'extends'", kEmpty}}) {
    SCOPED_TRACE(text);
    const std::string path = test::WriteFile(dir, "empty.yaml", text);
    EXPECT_TRUE(ThrowsInputErrorWith([&] { (void)sim::LoadScene(path); },
                                     {"empty.yaml:", "key " + key, expected}));
  }
  // A refused base is the one error: the keys it would have given are not reported missing.
  const std::string refused_base =
      test::WriteFile(dir, "refused_base.yaml", "name: x\nextends: [a]\n");
  EXPECT_EQ(test::InputErrorOf([&] { (void)sim::LoadScene(refused_base); }),
            refused_base + ":2:10: key 'extends': expected a string, got a list");
}

TEST(SceneFile, UnknownMaterialIsNamed) {
  EXPECT_TRUE(IsTheOneError(
      SmallSceneRefusal(kRock, "{name: m, type: plane, size_m: [1, 1, 0], material: mud}", kStatic),
      "bad.yaml:7:57: key 'meshes[0].material': the name of a material under 'materials', got "
      "'mud'"));
}

// The scenes built on the fitted tank (the two that must fail, and the crate) extend it: they
// must keep its acoustics, materials and detection, or they no longer test what their comments
// say. The two must-fail scenes also keep the tank's criteria, only expecting them to fail, and
// change only what they hold: 16 vertical rays, a drifting navigation.
TEST(SceneFile, TankScenesShareTheFittedTank) {
  const sim::Scene tank = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  for (const char* name : {"scenes/cras-tank-sparse-rays.yaml", "scenes/cras-tank-nav-drift.yaml",
                           "scenes/tank-crate.yaml"}) {
    SCOPED_TRACE(name);
    const sim::Scene scene = sim::LoadScene(test::SourcePath(name));
    EXPECT_EQ(scene.sensor.acoustics, tank.sensor.acoustics);
    EXPECT_EQ(scene.mapping.detection, tank.mapping.detection);
    ASSERT_EQ(scene.vehicle.size(), tank.vehicle.size());
    for (std::size_t i = 0; i < tank.vehicle.size(); ++i) {
      EXPECT_EQ(scene.vehicle[i].name, tank.vehicle[i].name);
    }
    for (const sim::Material& material : tank.materials) {
      const auto same = std::ranges::find(scene.materials, material.name, &sim::Material::name);
      ASSERT_NE(same, scene.materials.end()) << material.name;
      EXPECT_EQ(*same, material);
    }
    if (std::string(name).starts_with("scenes/cras-tank-")) {
      EXPECT_TRUE(scene.criteria.expect_fail);
      EXPECT_EQ(scene.criteria.metrics, tank.criteria.metrics);
    }
    EXPECT_EQ(scene.extends, std::vector<std::string>{test::SourcePath("scenes/cras-tank.yaml")});
  }
  const sim::Scene sparse = sim::LoadScene(test::SourcePath("scenes/cras-tank-sparse-rays.yaml"));
  EXPECT_EQ(sparse.mapping.rays_vertical, 16);
  EXPECT_EQ(sparse.mapping.rays_horizontal, tank.mapping.rays_horizontal);
  const sim::Scene drift = sim::LoadScene(test::SourcePath("scenes/cras-tank-nav-drift.yaml"));
  EXPECT_EQ(drift.navigation.position_noise_m, 0.02);
  EXPECT_EQ(drift.mapping.rays_vertical, tank.mapping.rays_vertical);
}

// A scene that extends another: the base first, then only what the derived file names changes
// it (key by key, materials by name, meshes added, criteria metrics whole), and a scene that
// extends none is read as before.
TEST(SceneFile, ExtendsChangesOnlyWhatItNames) {
  test::TempDir dir;
  const auto write = [&](const std::string& name, const std::string& text) {
    return test::WriteFile(dir, name, text);
  };
  write("base.yaml",
        "name: base\nsensor_model: " + test::SourcePath("sensor-models/shad-micron.yaml") +
            "\nseed: 4\nsweeps: 3\nstart_head_angle_deg: 90\n"
            "sonar_acoustics: {gain_db: 6.0, max_bounces: 2}\n"
            "materials:\n"
            "  - {name: rock, reflectivity: 0.8}\n"
            "  - {name: sand, reflectivity: 0.3, backscatter_exponent: 0.5}\n"
            "meshes:\n"
            "  - {name: bed, type: plane, size_m: [10, 10, 0], material: sand}\n"
            "trajectory: {type: static, position_m: [0, 0, 2]}\n"
            "navigation: {position_noise_m: 0.01, heading_noise_deg: 0.5}\n"
            "mapping: {resolution_m: 0.1, detection: {method: canny, canny_low: 40, "
            "canny_high: 90}}\n"
            "criteria:\n  metrics:\n    coverage: {min: 0.5}\n");
  const std::string derived_path =
      write("derived.yaml",
            "name: derived\nextends: base.yaml\nsweeps: 5\n"
            "sonar_acoustics: {noise_level_db: -50.0}\n"
            "materials:\n"
            "  - {name: sand, reflectivity: 0.1}\n"
            "  - {name: steel, reflectivity: 0.9}\n"
            "meshes:\n"
            "  - {name: pipe, type: box, size_m: [0.3, 4, 0.3], material: steel}\n"
            "navigation: {heading_noise_deg: 1.0}\n"
            "mapping: {detection: {canny_high: 120}}\n"
            "criteria: {expect: fail}\n");
  const sim::Scene base = sim::LoadScene((dir.path() / "base.yaml").string());
  const sim::Scene derived = sim::LoadScene(derived_path);
  EXPECT_EQ(derived.name, "derived");
  EXPECT_EQ(derived.file, derived_path);
  EXPECT_EQ(derived.extends, std::vector<std::string>{(dir.path() / "base.yaml").string()});
  EXPECT_TRUE(base.extends.empty());
  EXPECT_EQ(derived.sensor_model_file, base.sensor_model_file);
  EXPECT_EQ(derived.seed, 4u);
  EXPECT_EQ(derived.sweeps, 5);
  EXPECT_EQ(derived.start_head_angle_rad, base.start_head_angle_rad);
  // Acoustics: the base's gain and bounces kept, the noise changed.
  sim::Acoustics acoustics = base.sensor.acoustics;
  acoustics.noise.level_db = -50.0;
  EXPECT_EQ(derived.sensor.acoustics, acoustics);
  // Materials by name: sand replaced whole (its exponent back to the default), steel added.
  ASSERT_EQ(derived.materials.size(), 3u);
  EXPECT_EQ(derived.materials[0], base.materials[0]);
  EXPECT_EQ(derived.materials[1].name, "sand");
  EXPECT_EQ(derived.materials[1].reflectivity, 0.1);
  EXPECT_EQ(derived.materials[1].backscatter_exponent, sim::Material{}.backscatter_exponent);
  EXPECT_EQ(derived.materials[2].name, "steel");
  // Meshes added; the bed keeps its material (sand, replaced), the pipe takes steel.
  ASSERT_EQ(derived.meshes.size(), 2u);
  EXPECT_EQ(derived.meshes[0].name, "bed");
  EXPECT_EQ(derived.meshes[0].material, 1u);
  EXPECT_EQ(derived.meshes[1].name, "pipe");
  EXPECT_EQ(derived.meshes[1].material, 2u);
  // Navigation and mapping key by key.
  EXPECT_EQ(derived.navigation.position_noise_m, 0.01);
  EXPECT_NEAR(derived.navigation.heading_noise_rad, 1.0 * mapping::kDegToRad, 1e-15);
  EXPECT_EQ(derived.mapping.resolution_m, 0.1);
  EXPECT_EQ(derived.mapping.detection.method, mapping::DetectionConfig::Method::kCanny);
  EXPECT_EQ(derived.mapping.detection.canny_low, 40.0);
  EXPECT_EQ(derived.mapping.detection.canny_high, 120.0);
  // Criteria: expect replaced, the metrics kept.
  EXPECT_TRUE(derived.criteria.expect_fail);
  EXPECT_EQ(derived.criteria.metrics, base.criteria.metrics);
  // The dataset's configuration hash covers the base: change it, and the derived scene's
  // changes too.
  const std::string hash = sim::SceneConfigHash(derived, 1);
  write(
      "base.yaml", "# edited\n" + [&] {
        std::ifstream in((dir.path() / "base.yaml").string());
        return std::string(std::istreambuf_iterator<char>(in), {});
      }());
  EXPECT_NE(sim::SceneConfigHash(sim::LoadScene(derived_path), 1), hash);
}

// What a derived scene may not do, each a clear error naming the file, line and key: take its
// own sensor model, reuse a mesh name, extend in a loop (or itself), or extend a broken base
// (named in the base's own file).
TEST(SceneFile, ExtendsRefusesWhatItCannotMean) {
  test::TempDir dir;
  const auto write = [&](const std::string& name, const std::string& text) {
    return test::WriteFile(dir, name, text);
  };
  const std::string model = test::SourcePath("sensor-models/shad-micron.yaml");
  write("base.yaml", "name: base\nsensor_model: " + model +
                         "\nsweeps: 1\nmaterials: [{name: m, reflectivity: 0.5}]\n"
                         "meshes: [{name: bed, type: plane, size_m: [1, 1, 0], material: m}]\n"
                         "trajectory: {type: static, position_m: [0, 0, 1]}\n");
  const std::string own_model =
      write("own_model.yaml", "name: x\nextends: base.yaml\nsensor_model: " + model + "\n");
  EXPECT_TRUE(ThrowsInputErrorWith([&] { (void)sim::LoadScene(own_model); },
                                   {"own_model.yaml:3:", "'sensor_model'", "takes its model"}));
  const std::string same_mesh =
      write("same_mesh.yaml",
            "name: x\nextends: base.yaml\n"
            "meshes:\n  - {name: bed, type: plane, size_m: [2, 2, 0], material: m}\n");
  EXPECT_TRUE(ThrowsInputErrorWith([&] { (void)sim::LoadScene(same_mesh); },
                                   {"same_mesh.yaml:4:", "'meshes[0].name'", "not used before"}));
  write("a.yaml", "name: a\nextends: b.yaml\n");
  const std::string b = write("b.yaml", "name: b\nextends: a.yaml\n");
  EXPECT_TRUE(ThrowsInputErrorWith([&] { (void)sim::LoadScene(b); },
                                   {"a.yaml:2:", "'extends'", "outside the chain"}));
  const std::string self = write("self.yaml", "name: s\nextends: self.yaml\n");
  EXPECT_TRUE(ThrowsInputErrorWith([&] { (void)sim::LoadScene(self); },
                                   {"self.yaml:2:", "'extends'", "outside the chain"}));
  write("broken.yaml", "name: broken\nsensor_model: " + model + "\nsweeps: 0\n");
  const std::string on_broken = write("on_broken.yaml", "name: x\nextends: broken.yaml\n");
  EXPECT_TRUE(ThrowsInputErrorWith([&] { (void)sim::LoadScene(on_broken); },
                                   {"broken.yaml:3:", "'sweeps'"}));
}

// The vehicle's parts are meshes in the vehicle's frame, with their own names and diffuse
// materials, never truth; a derived scene adds to the base's.
TEST(SceneFile, VehiclePartsAreReadAndRefusedWithReasons) {
  test::TempDir dir;
  const std::string model = test::SourcePath("sensor-models/shad-micron.yaml");
  const std::string head = "name: x\nsensor_model: " + model +
                           "\nsweeps: 1\nmaterials:\n  - {name: hull, reflectivity: 0.3}\n"
                           "  - {name: glass, reflectivity: 0.1, specular: 0.5}\n"
                           "meshes: [{name: bed, type: plane, size_m: [9, 9, 0], material: hull}]\n"
                           "trajectory: {type: static, position_m: [0, 0, 1]}\n";
  const std::string good =
      test::WriteFile(dir, "good.yaml",
                      head +
                          "vehicle:\n  - {name: skid, type: box, size_m: [0.4, 0.1, 0.1], "
                          "position_m: [0.5, 0.2, -0.1], material: hull}\n");
  const sim::Scene scene = sim::LoadScene(good);
  ASSERT_EQ(scene.vehicle.size(), 1u);
  EXPECT_EQ(scene.vehicle[0].name, "skid");
  EXPECT_FALSE(scene.vehicle[0].truth);
  EXPECT_EQ(scene.vehicle[0].material, 0u);
  EXPECT_NEAR(scene.vehicle[0].T_world_mesh.translation().x(), 0.5, 1e-12);
  EXPECT_EQ(scene.meshes.size(), 1u);
  const std::string derived =
      test::WriteFile(dir, "derived.yaml",
                      "name: y\nextends: good.yaml\nvehicle:\n  - {name: fin, type: plane, "
                      "size_m: [0.1, 0.1, 0], material: hull}\n");
  EXPECT_EQ(sim::LoadScene(derived).vehicle.size(), 2u);

  // A part from a mesh file: the dataset's configuration hash covers the file's bytes.
  const std::string obj =
      test::WriteFile(dir, "fin.obj", "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nf 1 2 3\n");
  const std::string with_file = test::WriteFile(
      dir, "with_file.yaml",
      head + "vehicle:\n  - {name: fin, type: file, file: fin.obj, material: hull}\n");
  const std::string hash = sim::SceneConfigHash(sim::LoadScene(with_file), 1);
  test::WriteFile(dir, "fin.obj", "v 0 0 0\nv 0.2 0 0\nv 0 0.1 0\nf 1 2 3\n");
  EXPECT_NE(sim::SceneConfigHash(sim::LoadScene(with_file), 1), hash);

  const auto refused = [&](const std::string& name, const std::string& part,
                           const std::vector<std::string>& parts) {
    const std::string path = test::WriteFile(dir, name, head + "vehicle:\n  - " + part + "\n");
    return ThrowsInputErrorWith([&] { (void)sim::LoadScene(path); }, parts);
  };
  EXPECT_TRUE(refused("mirror.yaml", "{name: p, type: plane, size_m: [1, 1, 0], material: glass}",
                      {"mirror.yaml:10:", "'vehicle[0].material'", "specular 0", "'glass'"}));
  EXPECT_TRUE(refused("truth.yaml",
                      "{name: p, type: plane, size_m: [1, 1, 0], material: hull, truth: true}",
                      {"truth.yaml:10:", "'vehicle[0].truth'", "never ground truth"}));
  EXPECT_TRUE(refused("clash.yaml", "{name: bed, type: plane, size_m: [1, 1, 0], material: hull}",
                      {"clash.yaml:10:", "'vehicle[0].name'", "not used before", "'bed'"}));
  EXPECT_TRUE(refused("mud.yaml", "{name: p, type: plane, size_m: [1, 1, 0], material: mud}",
                      {"mud.yaml:10:", "'vehicle[0].material'", "'mud'"}));
  // An unknown material is reported alone, not also as the scene's first one, a mirror here.
  const std::string glass_first = test::WriteFile(
      dir, "glass_first.yaml",
      "name: x\nsensor_model: " + model +
          "\nsweeps: 1\nmaterials:\n  - {name: glass, reflectivity: 0.1, specular: 0.5}\n"
          "meshes: [{name: bed, type: plane, size_m: [9, 9, 0], material: glass}]\n"
          "trajectory: {type: static, position_m: [0, 0, 1]}\n"
          "vehicle:\n  - {name: p, type: plane, size_m: [1, 1, 0], material: mud}\n");
  const std::string message = test::InputErrorOf([&] { (void)sim::LoadScene(glass_first); });
  EXPECT_NE(message.find("key 'vehicle[0].material': the name of a material under 'materials', "
                         "got 'mud'"),
            std::string::npos)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(SceneFile, MissingFileIsAnInputError) {
  EXPECT_TRUE(ThrowsInputErrorWith(
      [] { (void)sim::LoadScene("/nonexistent/scene.yaml"); },
      {"/nonexistent/scene.yaml", "cannot be read (No such file or directory)"}));
}

// A FIFO or a device as the scene or its base is refused by its type (never waited on or read
// for ever); a scene past 2 MiB by its size; a chain of extends past 8 says so.
TEST(SceneFile, SpecialOrHugeFilesAndDeepChainsAreRefusedByName) {
  test::TempDir dir;
  const auto fifo = dir.path() / "fifo.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_TRUE(ThrowsInputErrorWith([&] { (void)sim::LoadScene(fifo.string()); },
                                   {"fifo.yaml: is a FIFO (expected a regular file)"}));
  const std::string zero = test::WriteFile(dir, "zero.yaml", "extends: /dev/zero\nname: z\n");
  EXPECT_TRUE(ThrowsInputErrorWith([&] { (void)sim::LoadScene(zero); },
                                   {"/dev/zero: is a character device"}));
  const std::string big = test::WriteFile(dir, "big.yaml", std::string(3 << 20, '#'));
  EXPECT_TRUE(ThrowsInputErrorWith([&] { (void)sim::LoadScene(big); },
                                   {"big.yaml: holds 3 MiB, more than the 2 MiB"}));
  (void)test::WriteFile(dir, "s20.yaml",
                        "extends: " + test::SourcePath("scenes/cras-tank.yaml") + "\nname: s\n");
  for (int i = 19; i >= 0; --i) {
    std::ostringstream name, text;
    name << "s" << i << ".yaml";
    text << "extends: s" << i + 1 << ".yaml\nname: s\n";
    (void)test::WriteFile(dir, name.str(), text.str());
  }
  EXPECT_TRUE(
      ThrowsInputErrorWith([&] { (void)sim::LoadScene((dir.path() / "s0.yaml").string()); },
                           {"key 'extends': expected at most 8 scenes extending one another"}));
  EXPECT_NO_THROW((void)sim::LoadScene((dir.path() / "s13.yaml").string()));
}

// A relative path is the scene file's folder's, then sonarbench's own: a scene saved anywhere
// names the shipped model and meshes. What cannot be read is reported at once, each with the
// scene's line and column and the path as resolved.
TEST(SceneFile, PathsResolveBesideTheSceneThenInSonarbenchsFolder) {
  test::TempDir dir;
  const std::string ok = test::WriteFile(
      dir, "ok.yaml",
      "name: s\nsensor_model: sensor-models/shad-micron.yaml\nsweeps: 1\n"
      "materials:\n  - {name: m, reflectivity: 0.3}\n"
      "meshes:\n  - {name: rock, type: file, file: scenes/meshes/rock.obj, material: m}\n"
      "trajectory: {type: static, position_m: [0, 0, 1]}\n");
  const sim::Scene scene = sim::LoadScene(ok);
  EXPECT_EQ(scene.sensor_model_file, test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(scene.meshes[0].file.path, test::SourcePath("scenes/meshes/rock.obj"));
  const std::string bad =
      test::WriteFile(dir, "bad.yaml",
                      "name: s\nsensor_model: models/none.yaml\nsweeps: 1\n"
                      "materials:\n  - {name: m, reflectivity: 0.3}\n"
                      "meshes:\n  - {name: a, type: file, file: a.obj, material: m}\n"
                      "  - {name: b, type: file, file: b.stl, material: m}\n"
                      "trajectory: {type: static, position_m: [0, 0, 1]}\n");
  const std::string error = test::InputErrorOf([&] { (void)sim::LoadScene(bad); });
  const std::string folder = dir.path().string();
  for (const std::string& part :
       {bad + ":7:33: mesh 'a': " + folder + "/a.obj: no such mesh file",
        bad + ":8:33: mesh 'b': " + folder + "/b.stl: no such mesh file",
        bad + ":2:15: sensor_model: " + folder + "/models/none.yaml: cannot be read",
        std::string("then from sonarbench's own")}) {
    EXPECT_NE(error.find(part), std::string::npos) << part << "\n" << error;
  }
}

// The sweeps' beams are counted against --max-beams before anything is built.
TEST(SceneFile, SweepsPastTheBeamBudgetAreRefused) {
  test::TempDir dir;
  const std::string path = test::WriteFile(
      dir, "long.yaml",
      "extends: " + test::SourcePath("scenes/cras-tank.yaml") + "\nname: s\nsweeps: 100000\n");
  sim::Scene scene = sim::LoadScene(path);
  EXPECT_TRUE(ThrowsInputErrorWith(
      [&] { sim::CheckBudgets(scene, scene.budgets); },
      {"long.yaml: 'sweeps' 100000", "2e+07 beams, more than the 2e+06", "--max-beams"}));
  scene.budgets.max_beams = 2e7;
  EXPECT_NO_THROW(sim::CheckBudgets(scene, scene.budgets));
}

}  // namespace
}  // namespace sonarbench
