#include "sonarbench/io/mapping_yaml.hpp"

#include <array>
#include <string>

#include "sonarbench/io/files.hpp"
#include "sonarbench/io/text.hpp"

namespace sonarbench::io {

const char* IntegrationName(Integration integration) {
  return integration == Integration::kExact ? "exact" : "rays";
}

const char* DetectionMethodName(DetectionConfig::Method method) {
  switch (method) {
    case DetectionConfig::Method::kThreshold:
      return "threshold";
    case DetectionConfig::Method::kCanny:
      return "canny";
    case DetectionConfig::Method::kAutoCanny:
      return "auto_canny";
    case DetectionConfig::Method::kCaCfar:
      return "ca_cfar";
    case DetectionConfig::Method::kOsCfar:
      return "os_cfar";
  }
  return "?";
}

const char* LaterEchoesName(DetectionConfig::LaterEchoes rule) {
  return rule == DetectionConfig::LaterEchoes::kSupported ? "supported" : "strongest";
}

const char* BehindWallsName(DetectionConfig::BehindWalls rule) {
  return rule == DetectionConfig::BehindWalls::kRefuse ? "refuse" : "keep";
}

const char* OccupancyName(Occupancy occupancy) {
  return occupancy == Occupancy::kArcEvidence ? "arc_evidence" : "arc_marking";
}

const char* KeySetName(KeySetKind kind) {
  switch (kind) {
    case KeySetKind::kStd:
      return "std";
    case KeySetKind::kOpenAddressing:
      return "open_addressing";
    case KeySetKind::kBlocks:
      break;
  }
  return "blocks";
}

MapperConfig ReadMapperConfig(YamlReader& node, MapperConfig base) {
  MapperConfig c = std::move(base);
  node.Optional("resolution_m", c.resolution_m, InRange(0.001, 10.0));
  std::string integration = IntegrationName(c.integration);
  node.Optional("integration", integration, OneOf({"rays", "exact"}));
  c.integration = integration == "exact" ? Integration::kExact : Integration::kRays;
  node.Optional("rays_horizontal", c.rays_horizontal, IntInRange(1, 4096));
  node.Optional("rays_vertical", c.rays_vertical, IntInRange(1, 4096));
  if (auto detection = node.OptionalChild("detection")) {
    DetectionConfig& d = c.detection;
    std::string method = DetectionMethodName(d.method);
    detection->Optional("method", method,
                        OneOf({"threshold", "canny", "auto_canny", "ca_cfar", "os_cfar"}));
    d.method = method == "threshold"    ? DetectionConfig::Method::kThreshold
               : method == "canny"      ? DetectionConfig::Method::kCanny
               : method == "auto_canny" ? DetectionConfig::Method::kAutoCanny
               : method == "ca_cfar"    ? DetectionConfig::Method::kCaCfar
                                        : DetectionConfig::Method::kOsCfar;
    detection->Optional("threshold", d.threshold, IntInRange(1, 255));
    detection->Optional("smoothing_bins", d.smoothing_bins, IntInRange(1, 99));
    detection->Optional("min_run_bins", d.min_run_bins, IntInRange(1, 1000));
    detection->Optional("max_obstacles", d.max_obstacles, IntInRange(1, 100));
    std::string later = LaterEchoesName(d.later_echoes);
    detection->Optional("later_echoes", later, OneOf({"strongest", "supported"}));
    d.later_echoes = later == "supported" ? DetectionConfig::LaterEchoes::kSupported
                                          : DetectionConfig::LaterEchoes::kStrongest;
    std::string walls = BehindWallsName(d.behind_walls);
    detection->Optional("behind_walls", walls, OneOf({"keep", "refuse"}));
    d.behind_walls = walls == "refuse" ? DetectionConfig::BehindWalls::kRefuse
                                       : DetectionConfig::BehindWalls::kKeep;
    detection->Optional("support_window_deg", d.support_window_deg, InRange(0.0, 180.0));
    detection->Optional("support_range_m", d.support_range_m, InRange(0.0, 100.0));
    detection->Optional("canny_low", d.canny_low, InRange(0.0, 2000.0));
    detection->Optional("canny_high", d.canny_high, InRange(0.0, 2000.0));
    detection->Optional("canny_blur_sigma", d.canny_blur_sigma, InRange(0.1, 10.0));
    detection->Optional("auto_canny_sigma", d.auto_canny_sigma, InRange(0.0, 1.0));
    if (auto cfar = detection->OptionalChild("cfar")) {
      cfar->Optional("guard_bins", d.cfar.guard_bins, IntInRange(0, 1000));
      cfar->Optional("training_bins", d.cfar.training_bins, IntInRange(1, 1000));
      cfar->Optional("false_alarm", d.cfar.false_alarm, InRange(1e-12, 0.5));
      cfar->Optional("order", d.cfar.order, InRange(0.01, 1.0));
      cfar->Optional("db_per_count", d.cfar.db_per_count, InRange(0.001, 1.0));
      cfar->RejectUnknownKeys();
    }
    detection->RejectUnknownKeys();
    if (d.smoothing_bins % 2 == 0) {
      detection->Fail("smoothing_bins", "an odd number of bins (the window is centred)");
    }
    if (d.canny_low > d.canny_high) {
      detection->Fail("canny_low", "a value no greater than canny_high");
    }
  }
  std::string occupancy = OccupancyName(c.occupancy);
  node.Optional("occupancy", occupancy, OneOf({"arc_marking", "arc_evidence"}));
  c.occupancy = occupancy == "arc_evidence" ? Occupancy::kArcEvidence : Occupancy::kArcMarking;
  std::string key_set = KeySetName(c.key_set);
  node.Optional("key_set", key_set, OneOf({"blocks", "open_addressing", "std"}));
  c.key_set = key_set == "std"               ? KeySetKind::kStd
              : key_set == "open_addressing" ? KeySetKind::kOpenAddressing
                                             : KeySetKind::kBlocks;
  node.Optional("prob_hit", c.prob_hit, InRange(0.5, 1.0));
  node.Optional("prob_miss", c.prob_miss, InRange(0.0, 0.5));
  node.Optional("clamp_min", c.clamp_min, InRange(0.0, 0.5));
  node.Optional("clamp_max", c.clamp_max, InRange(0.5, 1.0));
  if (auto water = node.OptionalChild("water")) {
    water->Optional("floor_z_m", c.water.floor_z_m, InRange(-1e4, 1e4));
    water->Optional("surface_z_m", c.water.surface_z_m, InRange(-1e4, 1e4));
    water->RejectUnknownKeys();
    if (c.water.floor_z_m >= c.water.surface_z_m) {
      water->Fail("floor_z_m", "a height below surface_z_m (" + Number(c.water.surface_z_m) + ")");
    }
  }
  node.Optional("clear_without_obstacle", c.clear_without_obstacle);
  node.Optional("free_range_m", c.free_range_m, NonNegative());
  node.Optional("threads", c.threads, IntInRange(0, 1024));
  node.RejectUnknownKeys();
  return c;
}

SensorGeometry ReadSensorGeometry(YamlReader& node) {
  SensorGeometry g;
  double width_h_deg = g.beam_width_horizontal_rad / mapping::kDegToRad;
  double width_v_deg = g.beam_width_vertical_rad / mapping::kDegToRad;
  double step_deg = g.step_angle_rad / mapping::kDegToRad;
  node.Required("beam_width_horizontal_deg", width_h_deg, InRange(0.1, 90.0));
  node.Required("beam_width_vertical_deg", width_v_deg, InRange(0.1, 90.0));
  node.Required("num_bins", g.num_bins, IntInRange(1, static_cast<int>(kMaxBinsPerBeam)));
  node.Required("bin_size_m", g.bin_size_m, Positive());
  node.Required("step_angle_deg", step_deg, InRange(0.01, 180.0));
  node.Required("beams_per_second", g.beams_per_second, Positive());
  node.Required("self_reflection_range_m", g.self_reflection_range_m, NonNegative());
  if (auto mounting = node.OptionalChild("mounting")) {
    std::array<double, 3> position{0, 0, 0};
    std::array<double, 3> rpy_deg{0, 0, 0};
    mounting->Optional("position_m", position);
    mounting->Optional("rpy_deg", rpy_deg);
    mounting->RejectUnknownKeys();
    g.T_vehicle_sonar = mapping::PoseFromXyzRpy(
        {position[0], position[1], position[2]},
        Eigen::Vector3d(rpy_deg[0], rpy_deg[1], rpy_deg[2]) * mapping::kDegToRad);
  }
  node.RejectUnknownKeys();
  g.beam_width_horizontal_rad = width_h_deg * mapping::kDegToRad;
  g.beam_width_vertical_rad = width_v_deg * mapping::kDegToRad;
  g.step_angle_rad = step_deg * mapping::kDegToRad;
  if (g.self_reflection_range_m >= g.MaxRangeM()) {
    node.Fail("self_reflection_range_m", "a range below num_bins * bin_size_m");
  }
  return g;
}

}  // namespace sonarbench::io
