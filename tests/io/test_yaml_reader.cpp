#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>
#include <tuple>
#include <vector>

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

mapping::MapperConfig ReadMapping(const std::string& text) {
  YamlReader reader = YamlReader::FromString(text, "scene.yaml");
  mapping::MapperConfig config = io::ReadMapperConfig(reader);
  reader.ThrowIfErrors();
  return config;
}

TEST(YamlReader, DefaultsComeFromTheStruct) {
  const mapping::MapperConfig config = ReadMapping("resolution_m: 0.1\n");
  EXPECT_DOUBLE_EQ(config.resolution_m, 0.1);
  EXPECT_EQ(config.rays_horizontal, mapping::MapperConfig{}.rays_horizontal);
  EXPECT_EQ(config.rays_vertical, mapping::MapperConfig{}.rays_vertical);
}

TEST(YamlReader, IntegrationIsExactUnlessRaysAreAskedFor) {
  EXPECT_EQ(ReadMapping("resolution_m: 0.1\n").integration, mapping::Integration::kExact);
  EXPECT_EQ(ReadMapping("integration: rays\n").integration, mapping::Integration::kRays);
  EXPECT_EQ(ReadMapping("integration: exact\n").integration, mapping::Integration::kExact);
  EXPECT_TRUE(
      ThrowsInputErrorWith([] { (void)ReadMapping("integration: dense\n"); },
                           {"scene.yaml:1:14", "'integration'", "rays", "exact", "got 'dense'"}));
}

TEST(YamlReader, EchoesBehindWallsAreKeptUnlessRefused) {
  using BehindWalls = mapping::DetectionConfig::BehindWalls;
  EXPECT_EQ(ReadMapping("resolution_m: 0.1\n").detection.behind_walls, BehindWalls::kKeep);
  EXPECT_EQ(ReadMapping("detection:\n  behind_walls: refuse\n").detection.behind_walls,
            BehindWalls::kRefuse);
  EXPECT_TRUE(ThrowsInputErrorWith(
      [] { (void)ReadMapping("detection:\n  behind_walls: drop\n"); },
      {"scene.yaml:2:17", "'detection.behind_walls'", "keep", "refuse", "got 'drop'"}));
}

TEST(YamlReader, TheWaterColumnIsUnboundedUnlessGivenAndItsFloorUnderItsSurface) {
  EXPECT_EQ(ReadMapping("resolution_m: 0.1\n").water, mapping::WaterColumn{});
  const mapping::WaterColumn water =
      ReadMapping("water: {floor_z_m: -1.5, surface_z_m: 0.25}\n").water;
  EXPECT_DOUBLE_EQ(water.floor_z_m, -1.5);
  EXPECT_DOUBLE_EQ(water.surface_z_m, 0.25);
  EXPECT_TRUE(std::isinf(ReadMapping("water: {floor_z_m: 0}\n").water.surface_z_m));
  EXPECT_TRUE(
      ThrowsInputErrorWith([] { (void)ReadMapping("water: {floor_z_m: 1.0, surface_z_m: 0.5}\n"); },
                           {"scene.yaml:1:20", "'water.floor_z_m'", "below surface_z_m (0.5)"}));
  EXPECT_TRUE(ThrowsInputErrorWith([] { (void)ReadMapping("water: {depth_m: 3}\n"); },
                                   {"'water.depth_m'"}));
}

TEST(YamlReader, LaterEchoesAreTheStrongestUnlessSupportIsAskedFor) {
  using LaterEchoes = mapping::DetectionConfig::LaterEchoes;
  EXPECT_EQ(ReadMapping("resolution_m: 0.1\n").detection.later_echoes, LaterEchoes::kStrongest);
  const mapping::DetectionConfig d = ReadMapping(
                                         "detection:\n  later_echoes: supported\n  "
                                         "support_window_deg: 5\n  support_range_m: 0.2\n")
                                         .detection;
  EXPECT_EQ(d.later_echoes, LaterEchoes::kSupported);
  EXPECT_DOUBLE_EQ(d.support_window_deg, 5.0);
  EXPECT_DOUBLE_EQ(d.support_range_m, 0.2);
  EXPECT_TRUE(ThrowsInputErrorWith(
      [] { (void)ReadMapping("detection:\n  later_echoes: all\n"); },
      {"scene.yaml:2:17", "'detection.later_echoes'", "strongest", "supported", "got 'all'"}));
  EXPECT_TRUE(
      ThrowsInputErrorWith([] { (void)ReadMapping("detection:\n  support_window_deg: -1\n"); },
                           {"'detection.support_window_deg'", "got '-1'"}));
}

TEST(YamlReader, OccupancyIsArcMarkingUnlessArcEvidenceIsAskedFor) {
  using mapping::Occupancy;
  EXPECT_EQ(ReadMapping("resolution_m: 0.1\n").occupancy, Occupancy::kArcMarking);
  EXPECT_EQ(ReadMapping("occupancy: arc_evidence\n").occupancy, Occupancy::kArcEvidence);
  EXPECT_EQ(ReadMapping("occupancy: arc_marking\n").occupancy, Occupancy::kArcMarking);
  EXPECT_TRUE(ThrowsInputErrorWith(
      [] { (void)ReadMapping("occupancy: shares\n"); },
      {"scene.yaml:1:12", "'occupancy'", "arc_marking", "arc_evidence", "got 'shares'"}));
}

TEST(YamlReader, KeySetIsBlocksUnlessAnotherIsAskedFor) {
  using mapping::KeySetKind;
  EXPECT_EQ(ReadMapping("resolution_m: 0.1\n").key_set, KeySetKind::kBlocks);
  EXPECT_EQ(ReadMapping("key_set: blocks\n").key_set, KeySetKind::kBlocks);
  EXPECT_EQ(ReadMapping("key_set: open_addressing\n").key_set, KeySetKind::kOpenAddressing);
  EXPECT_EQ(ReadMapping("key_set: std\n").key_set, KeySetKind::kStd);
  EXPECT_STREQ(io::KeySetName(KeySetKind::kBlocks), "blocks");
  EXPECT_TRUE(ThrowsInputErrorWith(
      [] { (void)ReadMapping("key_set: bonxai\n"); },
      {"scene.yaml:1:10", "'key_set'", "blocks", "open_addressing", "std", "got 'bonxai'"}));
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

}  // namespace
}  // namespace sonarbench
