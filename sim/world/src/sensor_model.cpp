#include "sonarbench/sim/world/sensor_model.hpp"

#include <filesystem>
#include <sstream>

#include "sonarbench/io/mapping_yaml.hpp"

namespace sonarbench::sim {

std::size_t MainLobeRays(const Acoustics& a) {
  return static_cast<std::size_t>(a.pattern.rays_horizontal) *
         static_cast<std::size_t>(a.pattern.rays_vertical);
}

std::size_t PrimaryRays(const Acoustics& a) {
  std::size_t rays = MainLobeRays(a);
  if (a.pattern.sidelobe_extent_deg > 0.0) {
    rays += 2 * static_cast<std::size_t>(a.pattern.sidelobe_rays_horizontal) *
            static_cast<std::size_t>(a.pattern.sidelobe_rays_vertical);
  }
  if (a.pattern.back_lobe_width_deg > 0.0) {
    rays += static_cast<std::size_t>(a.pattern.back_lobe_rays) *
            static_cast<std::size_t>(a.pattern.back_lobe_rays);
  }
  return rays;
}

void ReadAcoustics(YamlReader& node, Acoustics& a) {
  node.Optional("rays_horizontal", a.pattern.rays_horizontal, IntInRange(1, 1024));
  node.Optional("rays_vertical", a.pattern.rays_vertical, IntInRange(1, 8192));
  node.Optional("aperture_scale_horizontal", a.pattern.aperture_scale_horizontal,
                InRange(0.1, 4.0));
  node.Optional("aperture_scale_vertical", a.pattern.aperture_scale_vertical, InRange(0.1, 4.0));
  node.Optional("sidelobe_extent_deg", a.pattern.sidelobe_extent_deg, InRange(0.0, 89.0));
  node.Optional("sidelobe_db", a.pattern.sidelobe_db, InRange(-100.0, 0.0));
  node.Optional("sidelobe_width_deg", a.pattern.sidelobe_width_deg, InRange(0.01, 89.0));
  node.Optional("sidelobe_rays_horizontal", a.pattern.sidelobe_rays_horizontal,
                IntInRange(1, 1024));
  node.Optional("sidelobe_rays_vertical", a.pattern.sidelobe_rays_vertical, IntInRange(1, 8192));
  node.Optional("back_lobe_width_deg", a.pattern.back_lobe_width_deg, InRange(0.0, 90.0));
  node.Optional("back_lobe_db", a.pattern.back_lobe_db, InRange(-100.0, 0.0));
  node.Optional("back_lobe_rays", a.pattern.back_lobe_rays, IntInRange(1, 1024));
  node.Optional("spreading_db_per_decade", a.gain.spreading_db_per_decade, InRange(0.0, 80.0));
  node.Optional("absorption_db_per_m", a.gain.absorption_db_per_m, InRange(0.0, 100.0));
  node.Optional("tvg_db_per_decade", a.gain.tvg_db_per_decade, InRange(0.0, 80.0));
  node.Optional("gain_db", a.gain.gain_db, InRange(-200.0, 200.0));
  node.Optional("pulse_length_m", a.pulse.length_m, Positive());
  node.Optional("pulse_skirt_length_m", a.pulse.skirt_length_m, InRange(0.0, 10.0));
  node.Optional("pulse_skirt_db", a.pulse.skirt_db, InRange(-100.0, 20.0));
  node.Optional("noise_level_db", a.noise.level_db, InRange(-300.0, 100.0));
  node.Optional("noise_before_tvg_db", a.noise.before_tvg_db, InRange(-300.0, 100.0));
  node.Optional("blanking_range_m", a.noise.blanking_range_m, InRange(0.0, 10.0));
  node.Optional("level_jitter_db", a.noise.level_jitter_db, InRange(0.0, 20.0));
  node.Optional("level_jitter_bin_correlation", a.noise.level_jitter_bin_correlation,
                InRange(0.0, 0.5));
  node.Optional("max_bounces", a.max_bounces, IntInRange(0, 16));
  node.Optional("speckle", a.speckle.on);
  node.Optional("speckle_looks", a.speckle.looks, IntInRange(1, 16));
  node.Optional("speckle_window_m", a.speckle.window_m, InRange(0.0, 10.0));
  node.Optional("speckle_correlation_m", a.speckle.correlation_m, InRange(0.0, 1000.0));
  node.Optional("speckle_angular_correlation_deg", a.speckle.angular_correlation_deg,
                InRange(0.0, 30.0));
  node.Optional("speckle_own_share", a.speckle.own_share, InRange(0.0, 0.99));
  node.Optional("reverberation_length_m", a.tail.reverberation_length_m, InRange(0.0, 1000.0));
  node.Optional("reverberation_db", a.tail.reverberation_db, InRange(-100.0, 20.0));
  node.Optional("second_trip_db", a.tail.second_trip_db, InRange(-100.0, 20.0));
  node.Optional("ad_low_db", a.converter.low_db, InRange(-300.0, 100.0));
  node.Optional("ad_span_db", a.converter.span_db, InRange(1.0, 200.0));
  node.Optional("ad_knee", a.converter.knee, InRange(0.0, 255.0));
  node.Optional("ad_ceiling", a.converter.ceiling, InRange(1.0, 255.0));
  node.Optional("ad_levels", a.converter.levels, IntInRange(2, 255));
  node.Optional("self_reflection_db", a.self_reflection.profile_db);
  node.Optional("self_reflection_ping_spread_db", a.self_reflection.ping_spread_db,
                InRange(0.0, 10.0));
  node.Optional("self_reflection_ringing_range_m", a.self_reflection.ringing_range_m,
                InRange(0.0, 100.0));
  node.Optional("self_reflection_angle_spread_db", a.self_reflection.angle_spread_db,
                InRange(0.0, 10.0));
  node.Optional("self_reflection_angle_correlation_deg", a.self_reflection.angle_correlation_deg,
                InRange(0.0, 90.0));
}

void CheckAcoustics(YamlReader& node, const Acoustics& merged,
                    const mapping::SensorGeometry& geometry) {
  const double main_lobe_edge_deg = 0.5 * merged.pattern.aperture_scale_horizontal *
                                    geometry.beam_width_horizontal_rad / mapping::kDegToRad;
  if (merged.pattern.sidelobe_extent_deg > 0.0 &&
      merged.pattern.sidelobe_extent_deg <= main_lobe_edge_deg) {
    std::ostringstream got;
    got << "an extent past the main lobe's rays (" << main_lobe_edge_deg << "°), got "
        << merged.pattern.sidelobe_extent_deg;
    node.Fail("sidelobe_extent_deg", got.str());
  }
  if (merged.speckle.looks > 1 && !merged.speckle.on) {
    node.Fail("speckle_looks",
              "speckle: true (looks of a speckle that is off), got speckle: false");
  }
  for (const auto& [key, value] :
       {std::pair{"speckle_angular_correlation_deg", merged.speckle.angular_correlation_deg},
        std::pair{"speckle_own_share", merged.speckle.own_share}}) {
    if (value > 0.0 && !(merged.speckle.on && merged.speckle.correlation_m > 0.0)) {
      node.Fail(key, std::string("the place's speckle (speckle: true and "
                                 "speckle_correlation_m > 0), got ") +
                         (merged.speckle.on ? "speckle_correlation_m 0" : "speckle: false"));
    }
  }
  for (const auto& [key, spread] :
       {std::pair{"self_reflection_ping_spread_db", merged.self_reflection.ping_spread_db},
        std::pair{"self_reflection_angle_spread_db", merged.self_reflection.angle_spread_db}}) {
    if (spread > 0.0 && merged.self_reflection.profile_db.empty()) {
      node.Fail(key, "a self-reflection profile to vary (self_reflection_db), got none");
    }
  }
  if (merged.converter.knee > merged.converter.ceiling) {
    std::ostringstream got;
    got << "a knee at or below ad_ceiling (" << merged.converter.ceiling << "), got "
        << merged.converter.knee;
    node.Fail("ad_knee", got.str());
  }
  if (merged.self_reflection.ringing_range_m > 0.0 &&
      merged.self_reflection.ping_spread_db <= 0.0) {
    node.Fail("self_reflection_ringing_range_m",
              "self_reflection_ping_spread_db > 0 (the spread it bounds), got 0");
  }
  if (merged.self_reflection.angle_correlation_deg > 0.0 &&
      merged.self_reflection.angle_spread_db <= 0.0) {
    node.Fail("self_reflection_angle_correlation_deg",
              "self_reflection_angle_spread_db > 0 (a spread to correlate), got 0");
  }
  if (merged.noise.level_jitter_bin_correlation > 0.0 && merged.noise.level_jitter_db <= 0.0) {
    node.Fail("level_jitter_bin_correlation", "level_jitter_db > 0 (a jitter to correlate), got 0");
  }
}

SensorModel ReadSensorModel(YamlReader& root) {
  SensorModel model;
  root.Required("name", model.name, Name());
  YamlReader geometry = root.Child("geometry");
  model.geometry = io::ReadSensorGeometry(geometry);
  YamlReader node = root.Child("acoustics");
  ReadAcoustics(node, model.acoustics);
  CheckAcoustics(node, model.acoustics, model.geometry);
  node.RejectUnknownKeys();
  if (auto mapping = root.OptionalChild("mapping")) model.mapping = io::ReadMapperConfig(*mapping);
  root.RejectUnknownKeys();
  return model;
}

std::string ShippedSensorModelPath() {
  return (std::filesystem::path(SONARBENCH_DATA_DIR) / "sensor-models/shad-micron.yaml").string();
}

SensorModel LoadSensorModel(const std::string& path) {
  YamlReader root = YamlReader::FromFile(path);
  SensorModel model = ReadSensorModel(root);
  root.ThrowIfErrors();
  return model;
}

}  // namespace sonarbench::sim
