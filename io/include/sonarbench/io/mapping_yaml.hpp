#pragma once

#include "sonarbench/io/yaml_reader.hpp"
#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::io {

// The mapper's types these files hold.
using mapping::DetectionConfig;
using mapping::Integration;
using mapping::KeySetKind;
using mapping::MapperConfig;
using mapping::Occupancy;
using mapping::SensorGeometry;

/// Reads a `mapping` mapping of a scene file over `base` (absent keys keep its values; by default
/// the struct's defaults).
[[nodiscard]] MapperConfig ReadMapperConfig(YamlReader& node, MapperConfig base = {});

/// The names `integration`, `detection.method`, `detection.later_echoes`,
/// `detection.behind_walls`, `occupancy` and `key_set` take in YAML (and reports).
[[nodiscard]] const char* IntegrationName(Integration integration);
[[nodiscard]] const char* DetectionMethodName(DetectionConfig::Method method);
[[nodiscard]] const char* LaterEchoesName(DetectionConfig::LaterEchoes rule);
[[nodiscard]] const char* BehindWallsName(DetectionConfig::BehindWalls rule);
[[nodiscard]] const char* OccupancyName(Occupancy occupancy);
[[nodiscard]] const char* KeySetName(KeySetKind kind);

/// Reads a sensor model's `geometry` mapping (keys carry their units: `..._deg`, `..._m`).
[[nodiscard]] SensorGeometry ReadSensorGeometry(YamlReader& node);

}  // namespace sonarbench::io
