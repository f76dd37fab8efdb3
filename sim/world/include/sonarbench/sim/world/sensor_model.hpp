#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "sonarbench/io/yaml_reader.hpp"
#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::sim {

/// What only the simulator needs of the sonar: how echoes form and are digitised. Levels in dB
/// relative to a perfect reflector filling the beam at normal incidence and 1 m, after
/// `gain_db`. Each key's unit, default and meaning: docs/scene-format.md; the equations:
/// docs/physics.md. A level of -100 dB or less, or a length or angle of 0, turns a part off.
struct Acoustics {
  /// The beam's rays and pattern (BeamPattern).
  struct Pattern {
    int rays_horizontal = 4;
    int rays_vertical = 160;
    double aperture_scale_horizontal = 1.0;
    double aperture_scale_vertical = 1.0;
    double sidelobe_extent_deg = 0.0;
    double sidelobe_db = -30.0;
    double sidelobe_width_deg = 5.0;
    int sidelobe_rays_horizontal = 4;
    int sidelobe_rays_vertical = 40;
    double back_lobe_width_deg = 0.0;
    double back_lobe_db = -30.0;
    int back_lobe_rays = 8;
    bool operator==(const Pattern&) const = default;
  } pattern;
  /// Propagation and the receiver's gain (Receiver): dB per decade of range, dB per m two-way.
  struct Gain {
    double spreading_db_per_decade = 20.0;
    double absorption_db_per_m = 0.2;
    double tvg_db_per_decade = 20.0;
    double gain_db = 0.0;
    bool operator==(const Gain&) const = default;
  } gain;
  /// The pulse's range extent c·τ/2 [m] and its skirts (range_spread): keys pulse_length_m,
  /// pulse_skirt_length_m, pulse_skirt_db.
  struct Pulse {
    double length_m = 0.0375;
    double skirt_length_m = 0.0;
    double skirt_db = -20.0;
    bool operator==(const Pulse&) const = default;
  } pulse;
  /// Noise at the output and under the time-varied gain, blanking, level jitter (Receiver): keys
  /// noise_level_db, noise_before_tvg_db and the rest as named.
  struct Noise {
    double level_db = -40.0;
    double before_tvg_db = -100.0;
    double blanking_range_m = 0.0;
    double level_jitter_db = 0.0;
    double level_jitter_bin_correlation = 0.0;
    bool operator==(const Noise&) const = default;
  } noise;
  /// Specular reflections followed after the first hit (multipath).
  int max_bounces = 1;
  /// Speckle: per ping, or per place in cells of correlation_m [m] (speckle): keys speckle,
  /// speckle_correlation_m, speckle_looks, ...
  struct Speckle {
    bool on = true;
    double correlation_m = 0.0;
    int looks = 1;
    double window_m = 0.0;
    double angular_correlation_deg = 0.0;
    double own_share = 0.0;
    bool operator==(const Speckle&) const = default;
  } speckle;
  /// A closed place's reverberation tail and the echo's second trip (range_spread).
  struct Tail {
    double reverberation_length_m = 0.0;
    double reverberation_db = -20.0;
    double second_trip_db = -100.0;
    bool operator==(const Tail&) const = default;
  } tail;
  /// The converter: AD window, receiver ceiling [intensity 0-255], readings (Receiver): keys
  /// ad_low_db, ad_span_db, ad_knee, ad_ceiling, ad_levels.
  struct Converter {
    double low_db = -40.0;
    double span_db = 40.0;
    double knee = 255.0;
    double ceiling = 255.0;
    int levels = 255;
    bool operator==(const Converter&) const = default;
  } converter;
  /// The sonar's own ringing per bin from bin 0 [dB] and its spreads (SelfReflection): keys
  /// self_reflection_db, self_reflection_ping_spread_db, ...
  struct SelfReflection {
    std::vector<double> profile_db;
    double ping_spread_db = 0.0;
    double ringing_range_m = 0.0;
    double angle_spread_db = 0.0;
    double angle_correlation_deg = 0.0;
    bool operator==(const SelfReflection&) const = default;
  } self_reflection;

  bool operator==(const Acoustics&) const = default;
};

/// A sensor model file: `geometry` for the mapper, `acoustics` for the simulator, and `mapping`,
/// the mapper's defaults with this sensor (its optional section over MapperConfig's own), which a
/// scene's `mapping` section or `map --mapping` refines.
struct SensorModel {
  std::string name;
  mapping::SensorGeometry geometry;
  Acoustics acoustics;
  mapping::MapperConfig mapping;
};

/// Loads a sensor model YAML file; throws InputError naming the file and key on bad input.
[[nodiscard]] SensorModel LoadSensorModel(const std::string& path);

/// The shipped model of the SHAD's Micron (sensor-models/shad-micron.yaml under the source
/// tree), what `map` uses unless told otherwise.
[[nodiscard]] std::string ShippedSensorModelPath();

/// Primary rays per beam: the main lobe's rays_horizontal × rays_vertical and, with sidelobes,
/// their 2 × sidelobe_rays_horizontal × sidelobe_rays_vertical.
[[nodiscard]] std::size_t MainLobeRays(const Acoustics& a);
[[nodiscard]] std::size_t PrimaryRays(const Acoustics& a);

/// Reads the keys of an `acoustics` mapping that are present into `a` (absent ones keep their
/// value), without rejecting unknown keys: the caller does, once.
void ReadAcoustics(YamlReader& node, Acoustics& a);
/// Reports on `node` (an acoustics mapping) a key that `merged`, the settings in force once that
/// mapping is applied, sets without what it needs (a spread without its profile, a correlation
/// without its spread, a knee over its ceiling, sidelobes inside the main lobe).
void CheckAcoustics(YamlReader& node, const Acoustics& merged,
                    const mapping::SensorGeometry& geometry);
/// Reads a sensor model from an already-open reader (the root of a sensor model file).
[[nodiscard]] SensorModel ReadSensorModel(YamlReader& root);

}  // namespace sonarbench::sim
