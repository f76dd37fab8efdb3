#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <tuple>
#include <vector>

#include "cli_util.hpp"
#include "sim_fixtures.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/mapping_yaml.hpp"
#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/world/scene.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

using test::ThrowsInputErrorWith;

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

// A scene's sonar_acoustics replaces only the keys it names; the rest come from the model.
TEST(SensorModelFile, SonarAcousticsOverrideTheModelsKeysItNames) {
  const sim::SensorModel model =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  const sim::Scene scene = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  EXPECT_EQ(scene.sensor.acoustics.gain.gain_db, 6.0);
  EXPECT_EQ(scene.sensor.acoustics.max_bounces, 8);
  EXPECT_EQ(scene.sensor.acoustics.speckle.correlation_m, 0.05);
  EXPECT_EQ(model.acoustics.speckle.correlation_m, 0.0);
  EXPECT_NE(model.acoustics.gain.gain_db, 5.0);
  EXPECT_EQ(scene.sensor.acoustics.pattern.rays_vertical, model.acoustics.pattern.rays_vertical);
  // The tank keeps the model's ringing (bins 0-27) and replaces its tail by its vehicle's parts
  // and a weaker tail all round.
  const std::vector<double>& own = scene.sensor.acoustics.self_reflection.profile_db;
  const std::vector<double>& models = model.acoustics.self_reflection.profile_db;
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

TEST(SensorModelFile, BadSonarAcousticsAreNamed) {
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
TEST(SensorModelFile, SpecularSpreadIsReadInDegrees) {
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
TEST(SensorModelFile, ReverberationIsTheScenes) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.tail.reverberation_length_m, 0.0);
  EXPECT_EQ(micron.acoustics.tail.second_trip_db, -100.0);
  EXPECT_EQ(micron.acoustics.pulse.skirt_length_m, 0.0);
  const sim::Scene tank = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  EXPECT_EQ(tank.sensor.acoustics.tail.reverberation_length_m, 0.9);
  EXPECT_EQ(tank.sensor.acoustics.tail.reverberation_db, -4.0);
  EXPECT_EQ(micron.acoustics.pattern.back_lobe_width_deg, 0.0);
  EXPECT_EQ(tank.sensor.acoustics.pattern.back_lobe_width_deg, 30.0);
  EXPECT_EQ(tank.sensor.acoustics.pattern.back_lobe_db, -15.0);
  EXPECT_EQ(tank.sensor.acoustics.tail.second_trip_db, 7.75);
  EXPECT_EQ(tank.sensor.acoustics.pulse.skirt_length_m, 0.05);
  EXPECT_EQ(tank.sensor.acoustics.pulse.skirt_db, 3.0);
  EXPECT_EQ(micron.acoustics.noise.level_jitter_db, 0.0);
  EXPECT_EQ(tank.sensor.acoustics.noise.level_jitter_db, 0.19);
  EXPECT_EQ(micron.acoustics.noise.level_jitter_bin_correlation, 0.0);
  EXPECT_EQ(tank.sensor.acoustics.noise.level_jitter_bin_correlation, 0.36);
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

// The place's angular correlation and the head step's own share of its speckle need the place's
// speckle: set without it (the sensor model has none), the scene is refused, naming the key, its
// line and what it needs; a share of 1 or more (nothing left to share) too.
TEST(SensorModelFile, AngularCorrelationAndOwnShareNeedThePlacesSpeckle) {
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
  EXPECT_EQ(micron.acoustics.speckle.own_share, 0.0);
  const sim::Scene tank = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  EXPECT_EQ(tank.sensor.acoustics.speckle.angular_correlation_deg, 6.5);
  EXPECT_EQ(tank.sensor.acoustics.speckle.own_share, 0.19);
}

// The speckle's looks and window are the tank's (the sensor model keeps one look over the
// range response); looks without speckle, or out of 1..16, are refused with the key and line.
TEST(SensorModelFile, SpeckleLooksAndWindowAreTheTanks) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.speckle.looks, 1);
  EXPECT_EQ(micron.acoustics.speckle.window_m, 0.0);
  const sim::Scene tank = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  EXPECT_EQ(tank.sensor.acoustics.speckle.looks, 3);
  EXPECT_EQ(tank.sensor.acoustics.speckle.window_m, 0.063);
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
TEST(SensorModelFile, SelfReflectionSpreadsAreTheSonars) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.self_reflection.ping_spread_db, 0.97);
  EXPECT_EQ(micron.acoustics.self_reflection.ringing_range_m, 0.35);
  EXPECT_EQ(micron.acoustics.self_reflection.angle_spread_db, 1.6);
  EXPECT_EQ(micron.acoustics.self_reflection.angle_correlation_deg, 5.0);
  EXPECT_EQ(micron.acoustics.self_reflection.profile_db.size(), 66u);
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
TEST(SensorModelFile, ReceiverCeilingIsCheckedAgainstItsKnee) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.converter.knee, 255.0);
  EXPECT_EQ(micron.acoustics.converter.ceiling, 255.0);
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
TEST(SensorModelFile, SidelobesMustReachPastTheMainLobe) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.pattern.sidelobe_extent_deg, 0.0);
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
TEST(SensorModelFile, BackLobeIsOffUnlessAskedForAndChecked) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.pattern.back_lobe_width_deg, 0.0);
  sim::Acoustics with_back_lobe = micron.acoustics;
  with_back_lobe.pattern.back_lobe_width_deg = 30.0;
  with_back_lobe.pattern.back_lobe_rays = 8;
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
TEST(SensorModelFile, LevelJitterCorrelationNeedsAJitter) {
  ExpectSonarAcousticsRefused("  level_jitter_bin_correlation: 0.3\n",
                              {"'sonar_acoustics.level_jitter_bin_correlation'",
                               "level_jitter_db > 0 (a jitter to correlate), got 0"});
}

// The Micron's converter reads the AD window in 160 steps (the real log's values; the default, 255,
// is every value); a count under 2, over 255 or not a whole number is refused with the key and
// line.
TEST(SensorModelFile, ConverterStepsAreTheMicronsAndChecked) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.converter.levels, 160);
  EXPECT_EQ(sim::Acoustics{}.converter.levels, 255);
  const std::pair<std::string, std::vector<std::string>> cases[] = {
      {"  ad_levels: 1\n", {"'sonar_acoustics.ad_levels'", "'1'"}},
      {"  ad_levels: 256\n", {"'sonar_acoustics.ad_levels'", "'256'"}},
      {"  ad_levels: 160.5\n", {"'sonar_acoustics.ad_levels'", "'160.5'"}}};
  for (const auto& [acoustics, expected] : cases) ExpectSonarAcousticsRefused(acoustics, expected);
}

// The Micron's receiver is blanked over its first 0.025 m (the real log's bins 0 and 1; the
// default is none); a negative range is refused with the key and line.
TEST(SensorModelFile, BlankingIsTheMicronsAndChecked) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.noise.blanking_range_m, 0.025);
  EXPECT_EQ(sim::Acoustics{}.noise.blanking_range_m, 0.0);
  ExpectSonarAcousticsRefused("  blanking_range_m: -0.01\n",
                              {"'sonar_acoustics.blanking_range_m'", "'-0.01'"});
}

// The noise under the time-varied gain is the tank's (fitted to its log; the model has none,
// -100 dB, the default), and a level outside -300..100 dB is refused with the key and line.
TEST(SensorModelFile, NoiseBeforeTheGainIsTheTanksAndChecked) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.acoustics.noise.before_tvg_db, -100.0);
  EXPECT_EQ(sim::Acoustics{}.noise.before_tvg_db, -100.0);
  const sim::Scene tank = sim::LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  EXPECT_EQ(tank.sensor.acoustics.noise.before_tvg_db, -59.5);
  EXPECT_EQ(tank.sensor.acoustics.noise.level_db, -47.0);
  ExpectSonarAcousticsRefused("  noise_before_tvg_db: 200\n",
                              {"'sonar_acoustics.noise_before_tvg_db'", "'200'"});
}

// The model's `mapping` section gives the mapper's defaults with that sonar: the shipped Micron's
// detector is the threshold at 110 on first echoes; a model without one keeps MapperConfig's.
// A scene's `mapping` refines them key by key; a bad key in the model's is named with its file.
TEST(SensorModelFile, MappingDefaultsAreTheModelsAndTheSceneRefinesThem) {
  const sim::SensorModel micron =
      sim::LoadSensorModel(test::SourcePath("sensor-models/shad-micron.yaml"));
  EXPECT_EQ(micron.mapping.detection.threshold, 110);
  EXPECT_EQ(micron.mapping.detection.max_obstacles, 2);
  EXPECT_EQ(micron.mapping.detection.behind_walls, mapping::DetectionConfig::BehindWalls::kRefuse);
  EXPECT_EQ(micron.mapping.detection.smoothing_bins, 5);
  EXPECT_EQ(micron.mapping.detection.min_run_bins, 3);
  EXPECT_EQ(micron.mapping.resolution_m, mapping::MapperConfig{}.resolution_m);

  test::TempDir dir;
  const std::string text = test::ReadFile(test::SourcePath("sensor-models/shad-micron.yaml"));
  const std::string bare = text.substr(0, text.find("\nmapping:"));
  const std::string bare_path = (dir.path() / "bare.yaml").string();
  std::ofstream(bare_path) << bare;
  EXPECT_EQ(sim::LoadSensorModel(bare_path).mapping.detection, mapping::DetectionConfig{});
  const std::string bad_path = (dir.path() / "bad_model.yaml").string();
  std::ofstream(bad_path) << bare << "\nmapping: {detection: {threshold: 300}}\n";
  EXPECT_TRUE(ThrowsInputErrorWith([&] { (void)sim::LoadSensorModel(bad_path); },
                                   {"bad_model.yaml:", "'mapping.detection.threshold'", "'300'"}));

  const auto scene_with = [&](const std::string& mapping_section) {
    const std::string path = (dir.path() / "scene.yaml").string();
    std::ofstream(path)
        << "name: x\nsensor_model: " << test::SourcePath("sensor-models/shad-micron.yaml")
        << "\nsweeps: 1\nmaterials:\n  - {name: rock, reflectivity: 0.5}\n"
        << "meshes:\n  - {name: m, type: plane, size_m: [1, 1, 0], material: rock}\n"
        << "trajectory: {type: static, position_m: [0, 0, 0]}\n"
        << mapping_section;
    return sim::LoadScene(path);
  };
  EXPECT_EQ(scene_with("").mapping.detection, micron.mapping.detection);
  const sim::Scene refined = scene_with("mapping: {detection: {max_obstacles: 1}}\n");
  EXPECT_EQ(refined.mapping.detection.max_obstacles, 1);
  EXPECT_EQ(refined.mapping.detection.threshold, 110);
  EXPECT_EQ(refined.mapping.detection.behind_walls, mapping::DetectionConfig::BehindWalls::kRefuse);
  EXPECT_TRUE(
      ThrowsInputErrorWith([&] { (void)scene_with("mapping: {detection: {threshold: 0}}\n"); },
                           {"scene.yaml:9:", "'mapping.detection.threshold'", "'0'"}));
}

}  // namespace
}  // namespace sonarbench
