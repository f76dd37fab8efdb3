#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <tuple>
#include <vector>

#include "sonarbench/io/mapping_yaml.hpp"
#include "sonarbench/mapping/error.hpp"
#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/sim/dataset_writer.hpp"
#include "sonarbench/sim/scene.hpp"
#include "sonarbench/sim/sensor_model.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

// The message of the InputError that `f` throws, or a failure if it throws none.
template <typename F>
::testing::AssertionResult ThrowsInputErrorWith(F&& f, const std::vector<std::string>& parts) {
  try {
    f();
  } catch (const InputError& e) {
    const std::string message = e.what();
    for (const auto& part : parts) {
      if (message.find(part) == std::string::npos) {
        return ::testing::AssertionFailure() << "message lacks \"" << part << "\"; message was:\n"
                                             << message;
      }
    }
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "no InputError thrown";
}

mapping::MapperConfig ReadMapping(const std::string& text) {
  YamlReader reader = YamlReader::FromString(text, "scene.yaml");
  mapping::MapperConfig config = mapping::ReadMapperConfig(reader);
  reader.ThrowIfErrors();
  return config;
}

TEST(YamlReader, DefaultsComeFromTheStruct) {
  const mapping::MapperConfig config = ReadMapping("resolution_m: 0.1\n");
  EXPECT_DOUBLE_EQ(config.resolution_m, 0.1);
  EXPECT_EQ(config.rays_horizontal, mapping::MapperConfig{}.rays_horizontal);
  EXPECT_EQ(config.rays_vertical, mapping::MapperConfig{}.rays_vertical);
}

TEST(YamlReader, UnknownKeyNamesFileLineAndKey) {
  EXPECT_TRUE(
      ThrowsInputErrorWith([] { (void)ReadMapping("resolution_m: 0.1\nray_horizontal: 3\n"); },
                           {"scene.yaml:2:1", "'ray_horizontal'", "unknown key"}));
}

TEST(YamlReader, OutOfRangeValueNamesKeyAndExpectation) {
  EXPECT_TRUE(ThrowsInputErrorWith(
      [] { (void)ReadMapping("rays_vertical: 0\n"); },
      {"scene.yaml:1:16", "'rays_vertical'", "an integer in [1, 4096]", "got '0'"}));
}

TEST(YamlReader, WrongTypeAndNestedKeyPath) {
  EXPECT_TRUE(ThrowsInputErrorWith(
      [] { (void)ReadMapping("detection:\n  threshold: high\n"); },
      {"scene.yaml:2:14", "'detection.threshold'", "expected an integer", "got 'high'"}));
}

TEST(YamlReader, DuplicateKeyIsAnError) {
  EXPECT_TRUE(
      ThrowsInputErrorWith([] { (void)ReadMapping("resolution_m: 0.1\nresolution_m: 0.2\n"); },
                           {"scene.yaml:2:1", "'resolution_m'", "duplicate key"}));
  // A mapping of many duplicates (two list items run together) is one message.
  EXPECT_EQ(test::InputErrorOf([] {
              (void)ReadMapping(
                  "resolution_m: 0.1\nrays_vertical: 8\nresolution_m: 0.2\nrays_vertical: 9\n"
                  "rays_horizontal: 4\nrays_horizontal: 4\n");
            }),
            "scene.yaml:3:1: key 'resolution_m': duplicate key (each key may appear once; so are "
            "'rays_vertical', 'rays_horizontal')");
}

TEST(YamlReader, ReportsEveryBadFieldAtOnce) {
  EXPECT_TRUE(ThrowsInputErrorWith(
      [] { (void)ReadMapping("resolution_m: -1\nrays_vertical: 0\nbogus: 1\n"); },
      {"'resolution_m'", "'rays_vertical'", "'bogus'"}));
}

TEST(YamlReader, NonFiniteNumbersAreRejected) {
  EXPECT_TRUE(ThrowsInputErrorWith([] { (void)ReadMapping("resolution_m: .nan\n"); },
                                   {"'resolution_m'", "a finite number"}));
}

// A failure recorded at a key names that key's line and leaves the mapping as it was: the keys
// after it still read (yaml-cpp assigns through a Node that shares another, so pointing at the
// key's value must rebind, not assign).
TEST(YamlReader, FailAtAKeyLeavesTheMappingIntact) {
  YamlReader reader = YamlReader::FromString("a: 1\nb: 2\nc: 3\n", "scene.yaml");
  reader.Fail("b", "something else");
  int a = 0;
  int c = 0;
  reader.Required("a", a);
  reader.Required("c", c);
  EXPECT_EQ(a, 1);
  EXPECT_EQ(c, 3);
  EXPECT_EQ(reader.Keys(), (std::vector<std::string>{"a", "b", "c"}));
  const std::string message = test::InputErrorOf([&] { reader.ThrowIfErrors(); });
  EXPECT_NE(message.find("scene.yaml:2:"), std::string::npos) << message;
  EXPECT_NE(message.find("key 'b': something else"), std::string::npos) << message;
  EXPECT_EQ(message.find("'a'"), std::string::npos) << message;
  EXPECT_EQ(message.find("'c'"), std::string::npos) << message;
}

// A value that should be a mapping and is not, or is missing, is one mistake, reported once:
// the keys then read from it, its checks and its unknown keys add nothing.
TEST(YamlReader, AValueThatIsNotAMappingIsReportedOnce) {
  YamlReader reader = YamlReader::FromString("a: 5\nb: x\n", "scene.yaml");
  int c = 0;
  for (const char* key : {"a", "d"}) {
    YamlReader child = reader.Child(key);
    child.Required("c", c);
    child.Fail("", "a bound");
    child.RejectUnknownKeys();
  }
  int b = 0;
  reader.Required("b", b);  // a mistake of its own: still reported
  reader.RejectUnknownKeys();
  const std::string message = test::InputErrorOf([&] { reader.ThrowIfErrors(); });
  EXPECT_EQ(message,
            "scene.yaml:1:4: key 'a': expected a mapping, got '5'\n"
            "scene.yaml:1:1: key 'd': missing (expected a mapping)\n"
            "scene.yaml:2:4: key 'b': expected an integer, got 'x'");
}

TEST(YamlReader, SyntaxErrorNamesFileAndLine) {
  EXPECT_TRUE(ThrowsInputErrorWith([] { (void)ReadMapping("a: [1, 2\nb: 3\n"); },
                                   {"scene.yaml:", "invalid YAML"}));
}

// A directory opens as a stream and would read as an empty document: it is refused as what it is.
TEST(YamlReader, ADirectoryIsNotAFile) {
  test::TempDir dir;
  EXPECT_TRUE(ThrowsInputErrorWith([&] { (void)YamlReader::FromFile(dir.path().string()); },
                                   {dir.path().string(), "is a directory"}));
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

// The message a small scene (one material, one mesh, the trajectory; `acoustics`, if any, as its
// sonar_acoustics from line 5) is refused with; "" if it is not.
std::string SmallSceneRefusal(const std::string& material, const std::string& mesh,
                              const std::string& trajectory, const std::string& acoustics = "") {
  test::TempDir dir;
  const std::string path = (dir.path() / "bad.yaml").string();
  std::ofstream(path) << "name: x\nsensor_model: "
                      << test::SourcePath("sensor-models/shad-micron.yaml") << "\nsweeps: 1\n"
                      << (acoustics.empty() ? "" : "sonar_acoustics:\n" + acoustics)
                      << "materials:\n  - " << material << "\nmeshes:\n  - " << mesh
                      << "\ntrajectory: " << trajectory << "\n";
  return test::InputErrorOf([&] { (void)sim::LoadScene(path); });
}

// `message` is one error, the one that holds `expected`.
::testing::AssertionResult IsTheOneError(const std::string& message, const std::string& expected) {
  if (message.find(expected) == std::string::npos || message.find('\n') != std::string::npos) {
    return ::testing::AssertionFailure() << "expected only \"" << expected << "\"; message was:\n"
                                         << message;
  }
  return ::testing::AssertionSuccess();
}

constexpr const char* kRock = "{name: rock, reflectivity: 0.5}";
constexpr const char* kPlane = "{name: m, type: plane, size_m: [1, 1, 0], material: rock}";
constexpr const char* kStatic = "{type: static, position_m: [0, 0, 0]}";

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

// A scene's sonar_acoustics replaces only the keys it names; the rest come from the model.
TEST(SceneFile, SonarAcousticsOverrideTheModelsKeysItNames) {
  const sim::SensorModel model =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  const sim::Scene scene = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  EXPECT_EQ(scene.sensor.acoustics.gain_db, 6.0);
  EXPECT_EQ(scene.sensor.acoustics.max_bounces, 8);
  EXPECT_EQ(scene.sensor.acoustics.speckle_correlation_m, 0.05);
  EXPECT_EQ(model.acoustics.speckle_correlation_m, 0.0);
  EXPECT_NE(model.acoustics.gain_db, 5.0);
  EXPECT_EQ(scene.sensor.acoustics.rays_vertical, model.acoustics.rays_vertical);
  // The tank keeps the model's ringing (bins 0-27) and replaces its tail by its vehicle's parts
  // and a weaker tail all round.
  const std::vector<double>& own = scene.sensor.acoustics.self_reflection_db;
  const std::vector<double>& models = model.acoustics.self_reflection_db;
  ASSERT_EQ(own.size(), models.size());
  for (std::size_t k = 0; k < own.size(); ++k) {
    if (k < 28) {
      EXPECT_EQ(own[k], models[k]) << k;
    } else {
      EXPECT_LT(own[k], models[k]) << k;
    }
  }
  EXPECT_FALSE(scene.vehicle.empty());
  // The water surface is traced but not scored.
  bool surface_found = false;
  for (const sim::MeshSpec& mesh : scene.meshes) {
    if (mesh.name != "surface") continue;
    surface_found = true;
    EXPECT_FALSE(mesh.truth);
  }
  EXPECT_TRUE(surface_found);
}

TEST(SceneFile, BadSonarAcousticsAreNamed) {
  test::TempDir dir;
  const std::string path = (dir.path() / "bad.yaml").string();
  std::ofstream(path) << "name: x\nsensor_model: "
                      << test::SourcePath("sensor-models/shad-micron.yaml")
                      << "\nsweeps: 1\nsonar_acoustics: {max_bounces: 40, gain: 3, "
                      << "speckle_correlation_m: -0.1}\n"
                      << "materials:\n  - {name: rock, reflectivity: 0.5}\n"
                      << "meshes:\n  - {name: m, type: plane, size_m: [1, 1, 0], material: rock}\n"
                      << "trajectory: {type: static, position_m: [0, 0, 0]}\n";
  EXPECT_TRUE(ThrowsInputErrorWith(
      [&] { (void)sim::LoadScene(path); },
      {"bad.yaml:4:", "'sonar_acoustics.max_bounces'", "'40'", "'sonar_acoustics.gain'",
       "'sonar_acoustics.speckle_correlation_m'", "'-0.1'"}));
}

// A material's mirror roughness is read in degrees and kept in radians, its glint as a
// fraction of a perfect reflector's echo (the tank's walls glint as one, the vehicle's nose at
// 0.05, nothing else); out of range, a glint without the spread it falls over, or one whose
// lobe would send more sound than the surface meets (over 1/(2σ²): 102.588 at σ = 4°), is named.
TEST(SceneFile, SpecularSpreadIsReadInDegrees) {
  const sim::Scene scene = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  ASSERT_FALSE(scene.materials.empty());
  EXPECT_NEAR(scene.materials.front().specular_spread_rad, 8.0 * mapping::kDegToRad, 1e-15);
  for (const sim::Material& m : scene.materials) {
    if (m.name == "vehicle_nose") {
      EXPECT_EQ(m.glint, 0.05);
      EXPECT_NEAR(m.specular_spread_rad, 3.0 * mapping::kDegToRad, 1e-15);
    } else if (m.name == "tank_wall") {
      EXPECT_EQ(m.glint, 1.0);
    } else {
      EXPECT_EQ(m.glint, 0.0) << m.name;
    }
  }
  const std::pair<std::string, std::vector<std::string>> cases[] = {
      {"reflectivity: 0.5, specular_spread_deg: 45",
       {"'materials[0].specular_spread_deg'", "'45'"}},
      {"reflectivity: 0.5, specular_spread_deg: 4, glint: -0.5",
       {"'materials[0].glint'", "a number >= 0", "'-0.5'"}},
      {"reflectivity: 0.5, specular_spread_deg: 4, glint: 103",
       {"'materials[0].glint'", "at most 1/(2σ²) = 102.588 for specular_spread_deg 4", "got 103"}},
      {"reflectivity: 0.5, glint: 0.1",
       {"'materials[0].glint'", "specular_spread_deg > 0", "got 0"}}};
  test::TempDir dir;
  const auto scene_with = [&](const std::string& material) {
    const std::string path = (dir.path() / "bad.yaml").string();
    std::ofstream(path)
        << "name: x\nsensor_model: " << test::SourcePath("sensor-models/shad-micron.yaml")
        << "\nsweeps: 1\nmaterials:\n"
        << "  - {name: rock, " << material << "}\n"
        << "meshes:\n  - {name: m, type: plane, size_m: [1, 1, 0], material: rock}\n"
        << "trajectory: {type: static, position_m: [0, 0, 0]}\n";
    return path;
  };
  for (const auto& [material_text, expected] : cases) {
    std::vector<std::string> parts = {"bad.yaml:5:"};
    parts.insert(parts.end(), expected.begin(), expected.end());
    const std::string& material = material_text;  // a lambda may not capture a binding (clang 14)
    EXPECT_TRUE(ThrowsInputErrorWith([&] { (void)sim::LoadScene(scene_with(material)); }, parts))
        << material;
  }
  // Under the bound, a glint brighter than a perfect diffuse reflector is a smooth surface's.
  EXPECT_EQ(sim::LoadScene(scene_with("reflectivity: 0.5, specular_spread_deg: 4, glint: 102.5"))
                .materials.front()
                .glint,
            102.5);
}

// The tank's reverberation, second trip, pulse skirts and level jitter are the scene's (the
// sensor model has none), and a level outside its range (-100..20 dB, the jitter 0..20 dB, its
// correlation between neighbouring bins 0..0.5) is refused, naming the key and line.
TEST(SceneFile, ReverberationIsTheScenes) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.reverberation_length_m, 0.0);
  EXPECT_EQ(micron.acoustics.second_trip_db, -100.0);
  EXPECT_EQ(micron.acoustics.pulse_skirt_length_m, 0.0);
  const sim::Scene tank = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  EXPECT_EQ(tank.sensor.acoustics.reverberation_length_m, 0.9);
  EXPECT_EQ(tank.sensor.acoustics.reverberation_db, -3.0);
  EXPECT_EQ(micron.acoustics.back_lobe_width_deg, 0.0);
  EXPECT_EQ(tank.sensor.acoustics.back_lobe_width_deg, 30.0);
  EXPECT_EQ(tank.sensor.acoustics.back_lobe_db, -15.0);
  EXPECT_EQ(tank.sensor.acoustics.second_trip_db, 7.75);
  EXPECT_EQ(tank.sensor.acoustics.pulse_skirt_length_m, 0.05);
  EXPECT_EQ(tank.sensor.acoustics.pulse_skirt_db, 3.0);
  EXPECT_EQ(micron.acoustics.level_jitter_db, 0.0);
  EXPECT_EQ(tank.sensor.acoustics.level_jitter_db, 0.19);
  EXPECT_EQ(micron.acoustics.level_jitter_bin_correlation, 0.0);
  EXPECT_EQ(tank.sensor.acoustics.level_jitter_bin_correlation, 0.36);
  for (const char* key : {"reverberation_db", "second_trip_db", "pulse_skirt_db", "level_jitter_db",
                          "level_jitter_bin_correlation"}) {
    test::TempDir dir;
    const std::string path = (dir.path() / "bad.yaml").string();
    std::ofstream(path) << "name: x\nsensor_model: "
                        << test::SourcePath("sensor-models/shad-micron.yaml")
                        << "\nsweeps: 1\nsonar_acoustics:\n"
                        << "  " << key << ": 30\n"
                        << "meshes:\n  - {name: m, type: plane, size_m: [1, 1, 0]}\n"
                        << "trajectory: {type: static, position_m: [0, 0, 0]}\n";
    EXPECT_TRUE(
        ThrowsInputErrorWith([&] { (void)sim::LoadScene(path); },
                             {"bad.yaml:5:", "'sonar_acoustics." + std::string(key) + "'", "'30'"}))
        << key;
  }
}

// A scene on the Micron whose sonar_acoustics (from line 5) are `acoustics` is refused, the
// message naming line 5 of the file and each of `expected`.
void ExpectSonarAcousticsRefused(const std::string& acoustics,
                                 const std::vector<std::string>& expected) {
  const std::string message = SmallSceneRefusal(kRock, kPlane, kStatic, acoustics);
  std::vector<std::string> parts = {"bad.yaml:5:"};
  parts.insert(parts.end(), expected.begin(), expected.end());
  for (const std::string& part : parts) {
    EXPECT_NE(message.find(part), std::string::npos) << acoustics << "\nmessage: " << message;
  }
}

// The place's angular correlation and the head step's own share of its speckle need the place's
// speckle: set without it (the sensor model has none), the scene is refused, naming the key, its
// line and what it needs; a share of 1 or more (nothing left to share) too.
TEST(SceneFile, AngularCorrelationAndOwnShareNeedThePlacesSpeckle) {
  for (const std::string key : {"speckle_angular_correlation_deg: 7.2", "speckle_own_share: 0.2"}) {
    for (const std::string extra : {"", "  speckle_correlation_m: 0.05\n  speckle: false\n"}) {
      ExpectSonarAcousticsRefused(
          "  " + key + "\n" + extra,
          {"'sonar_acoustics." + key.substr(0, key.find(':')) + "'", "the place's speckle",
           extra.empty() ? "got speckle_correlation_m 0" : "got speckle: false"});
    }
  }
  ExpectSonarAcousticsRefused("  speckle_own_share: 1\n  speckle_correlation_m: 0.05\n",
                              {"'sonar_acoustics.speckle_own_share'", "'1'"});
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.speckle_own_share, 0.0);
  const sim::Scene tank = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  EXPECT_EQ(tank.sensor.acoustics.speckle_angular_correlation_deg, 6.5);
  EXPECT_EQ(tank.sensor.acoustics.speckle_own_share, 0.19);
}

// The speckle's looks and window are the tank's (the sensor model keeps one look over the
// range response); looks without speckle, or out of 1..16, are refused with the key and line.
TEST(SceneFile, SpeckleLooksAndWindowAreTheTanks) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.speckle_looks, 1);
  EXPECT_EQ(micron.acoustics.speckle_window_m, 0.0);
  const sim::Scene tank = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  EXPECT_EQ(tank.sensor.acoustics.speckle_looks, 3);
  EXPECT_EQ(tank.sensor.acoustics.speckle_window_m, 0.063);
  const std::pair<std::string, std::vector<std::string>> cases[] = {
      {"  speckle_looks: 2\n  speckle: false\n",
       {"'sonar_acoustics.speckle_looks'", "speckle: true", "got speckle: false"}},
      {"  speckle_looks: 0\n", {"'sonar_acoustics.speckle_looks'", "'0'"}},
      {"  speckle_looks: 2.5\n", {"'sonar_acoustics.speckle_looks'", "'2.5'"}},
      {"  speckle_window_m: -0.1\n", {"'sonar_acoustics.speckle_window_m'", "'-0.1'"}}};
  for (const auto& [acoustics, expected] : cases) ExpectSonarAcousticsRefused(acoustics, expected);
}

// The self-reflection's spreads are the sensor model's (the sonar's own, fitted to the real
// log); a spread with no profile to vary, a correlation or ringing range with no spread to
// shape, or a spread out of 0..10 dB, is refused with the key and line.
TEST(SceneFile, SelfReflectionSpreadsAreTheSonars) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.self_reflection_ping_spread_db, 0.97);
  EXPECT_EQ(micron.acoustics.self_reflection_ringing_range_m, 0.35);
  EXPECT_EQ(micron.acoustics.self_reflection_angle_spread_db, 1.6);
  EXPECT_EQ(micron.acoustics.self_reflection_angle_correlation_deg, 5.0);
  EXPECT_EQ(micron.acoustics.self_reflection_db.size(), 66u);
  const std::pair<std::string, std::vector<std::string>> cases[] = {
      {"  self_reflection_db: []\n",
       {"'sonar_acoustics.self_reflection_ping_spread_db'", "a self-reflection profile"}},
      {"  self_reflection_angle_spread_db: 0\n",
       {"'sonar_acoustics.self_reflection_angle_correlation_deg'",
        "self_reflection_angle_spread_db > 0", "got 0"}},
      {"  self_reflection_ping_spread_db: 0\n",
       {"'sonar_acoustics.self_reflection_ringing_range_m'", "self_reflection_ping_spread_db > 0"}},
      {"  self_reflection_ping_spread_db: 11\n",
       {"'sonar_acoustics.self_reflection_ping_spread_db'", "'11'"}},
      {"  self_reflection_angle_spread_db: -1\n",
       {"'sonar_acoustics.self_reflection_angle_spread_db'", "'-1'"}}};
  for (const auto& [acoustics, expected] : cases) ExpectSonarAcousticsRefused(acoustics, expected);
}

// The receiver's ceiling is off unless asked for (knee and ceiling at 255); a knee over its
// ceiling, or either out of the 8 bits, is refused with the key and line.
TEST(SceneFile, ReceiverCeilingIsCheckedAgainstItsKnee) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.ad_knee, 255.0);
  EXPECT_EQ(micron.acoustics.ad_ceiling, 255.0);
  const std::pair<std::string, std::vector<std::string>> cases[] = {
      {"  ad_ceiling: 191\n",
       {"'sonar_acoustics.ad_knee'", "at or below ad_ceiling (191)", "got 255"}},
      {"  ad_knee: 200\n  ad_ceiling: 191\n", {"'sonar_acoustics.ad_knee'", "got 200"}},
      {"  ad_ceiling: 256\n", {"'sonar_acoustics.ad_ceiling'", "'256'"}},
      {"  ad_knee: -1\n", {"'sonar_acoustics.ad_knee'", "'-1'"}}};
  for (const auto& [acoustics, expected] : cases) ExpectSonarAcousticsRefused(acoustics, expected);
}

// Sidelobes are off unless asked for; an extent inside the main lobe's rays (±1.5° on the
// Micron), a level over the main lobe's, or no strata, are refused with the key and line.
TEST(SceneFile, SidelobesMustReachPastTheMainLobe) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.sidelobe_extent_deg, 0.0);
  EXPECT_EQ(sim::PrimaryRays(micron.acoustics), 640u);
  const std::pair<std::string, std::vector<std::string>> cases[] = {
      {"  sidelobe_extent_deg: 1.5\n",
       {"'sonar_acoustics.sidelobe_extent_deg'", "past the main lobe's rays (1.5°)", "got 1.5"}},
      {"  sidelobe_db: 3\n  sidelobe_extent_deg: 20\n", {"'sonar_acoustics.sidelobe_db'", "'3'"}},
      {"  sidelobe_rays_vertical: 0\n  sidelobe_extent_deg: 20\n",
       {"'sonar_acoustics.sidelobe_rays_vertical'", "'0'"}}};
  for (const auto& [acoustics, expected] : cases) ExpectSonarAcousticsRefused(acoustics, expected);
}

// The sensor model has no back lobe unless asked for (a scene's acoustics may add one: its
// strata then join the primary rays); a level over the main lobe's, a width past 90°, or no
// strata, are refused with the key and line.
TEST(SceneFile, BackLobeIsOffUnlessAskedForAndChecked) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.back_lobe_width_deg, 0.0);
  sim::Acoustics with_back_lobe = micron.acoustics;
  with_back_lobe.back_lobe_width_deg = 30.0;
  with_back_lobe.back_lobe_rays = 8;
  EXPECT_EQ(sim::PrimaryRays(with_back_lobe), 640u + 64u);
  const std::pair<std::string, std::vector<std::string>> cases[] = {
      {"  back_lobe_db: 1\n  back_lobe_width_deg: 30\n", {"'sonar_acoustics.back_lobe_db'", "'1'"}},
      {"  back_lobe_width_deg: 91\n", {"'sonar_acoustics.back_lobe_width_deg'", "'91'"}},
      {"  back_lobe_rays: 0\n  back_lobe_width_deg: 30\n",
       {"'sonar_acoustics.back_lobe_rays'", "'0'"}}};
  for (const auto& [acoustics, expected] : cases) ExpectSonarAcousticsRefused(acoustics, expected);
}

// The level jitter's correlation between neighbouring bins needs a jitter: alone, it is refused,
// naming the key, its line and what it needs.
TEST(SceneFile, LevelJitterCorrelationNeedsAJitter) {
  ExpectSonarAcousticsRefused("  level_jitter_bin_correlation: 0.3\n",
                              {"'sonar_acoustics.level_jitter_bin_correlation'",
                               "level_jitter_db > 0 (a jitter to correlate), got 0"});
}

// The Micron's converter reads the AD window in 160 steps (the real log's values; the default, 255,
// is every value); a count under 2, over 255 or not a whole number is refused with the key and
// line.
TEST(SceneFile, ConverterStepsAreTheMicronsAndChecked) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.ad_levels, 160);
  EXPECT_EQ(sim::Acoustics{}.ad_levels, 255);
  const std::pair<std::string, std::vector<std::string>> cases[] = {
      {"  ad_levels: 1\n", {"'sonar_acoustics.ad_levels'", "'1'"}},
      {"  ad_levels: 256\n", {"'sonar_acoustics.ad_levels'", "'256'"}},
      {"  ad_levels: 160.5\n", {"'sonar_acoustics.ad_levels'", "'160.5'"}}};
  for (const auto& [acoustics, expected] : cases) ExpectSonarAcousticsRefused(acoustics, expected);
}

// The Micron's receiver is blanked over its first 0.025 m (the real log's bins 0 and 1; the
// default is none); a negative range is refused with the key and line.
TEST(SceneFile, BlankingIsTheMicronsAndChecked) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.blanking_range_m, 0.025);
  EXPECT_EQ(sim::Acoustics{}.blanking_range_m, 0.0);
  ExpectSonarAcousticsRefused("  blanking_range_m: -0.01\n",
                              {"'sonar_acoustics.blanking_range_m'", "'-0.01'"});
}

// The noise under the time-varied gain is the tank's (fitted to its log; the model has none,
// -100 dB, the default), and a level outside -300..100 dB is refused with the key and line.
TEST(SceneFile, NoiseBeforeTheGainIsTheTanksAndChecked) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.noise_before_tvg_db, -100.0);
  EXPECT_EQ(sim::Acoustics{}.noise_before_tvg_db, -100.0);
  const sim::Scene tank = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  EXPECT_EQ(tank.sensor.acoustics.noise_before_tvg_db, -59.5);
  EXPECT_EQ(tank.sensor.acoustics.noise_level_db, -47.0);
  ExpectSonarAcousticsRefused("  noise_before_tvg_db: 200\n",
                              {"'sonar_acoustics.noise_before_tvg_db'", "'200'"});
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
  acoustics.noise_level_db = -50.0;
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
  EXPECT_TRUE(ThrowsInputErrorWith([] { (void)sim::LoadScene("/nonexistent/scene.yaml"); },
                                   {"/nonexistent/scene.yaml", "cannot open"}));
}

}  // namespace
}  // namespace sonarbench
