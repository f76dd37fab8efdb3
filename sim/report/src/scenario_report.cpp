#include "sonarbench/sim/report/scenario_report.hpp"

#include <openssl/evp.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "sonarbench/io/files.hpp"
#include "sonarbench/io/mapping_yaml.hpp"
#include "sonarbench/io/octomap_file.hpp"
#include "sonarbench/sim/report/images.hpp"
#include "sonarbench/sim/report/map_report.hpp"
#include "sonarbench/sim/report/report.hpp"
#include "sonarbench/sim/report/report_page.hpp"
#include "sonarbench/sim/report/view3d.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"

namespace sonarbench::sim {
namespace {

constexpr double kRadToDeg = 1.0 / mapping::kDegToRad;

nlohmann::json DistanceJson(const DistanceStats& d) {
  return {{"count", d.count}, {"mean_m", d.mean_m}, {"p95_m", d.p95_m}, {"max_m", d.max_m}};
}

}  // namespace

nlohmann::json MapperConfigJson(const mapping::MapperConfig& c) {
  return {{"resolution_m", c.resolution_m},
          {"integration", io::IntegrationName(c.integration)},
          {"rays_horizontal", c.rays_horizontal},
          {"rays_vertical", c.rays_vertical},
          {"detection",
           {{"method", io::DetectionMethodName(c.detection.method)},
            {"threshold", c.detection.threshold},
            {"smoothing_bins", c.detection.smoothing_bins},
            {"min_run_bins", c.detection.min_run_bins},
            {"max_obstacles", c.detection.max_obstacles},
            {"later_echoes", io::LaterEchoesName(c.detection.later_echoes)},
            {"behind_walls", io::BehindWallsName(c.detection.behind_walls)},
            {"support_window_deg", c.detection.support_window_deg},
            {"support_range_m", c.detection.support_range_m},
            {"canny_low", c.detection.canny_low},
            {"canny_high", c.detection.canny_high},
            {"canny_blur_sigma", c.detection.canny_blur_sigma},
            {"auto_canny_sigma", c.detection.auto_canny_sigma},
            {"cfar",
             {{"guard_bins", c.detection.cfar.guard_bins},
              {"training_bins", c.detection.cfar.training_bins},
              {"false_alarm", c.detection.cfar.false_alarm},
              {"order", c.detection.cfar.order},
              {"db_per_count", c.detection.cfar.db_per_count}}}}},
          {"occupancy", io::OccupancyName(c.occupancy)},
          {"water",
           {{"floor_z_m", std::isfinite(c.water.floor_z_m) ? nlohmann::json(c.water.floor_z_m)
                                                           : nlohmann::json()},
            {"surface_z_m", std::isfinite(c.water.surface_z_m) ? nlohmann::json(c.water.surface_z_m)
                                                               : nlohmann::json()}}},
          {"key_set", io::KeySetName(c.key_set)},
          {"prob_hit", c.prob_hit},
          {"prob_miss", c.prob_miss},
          {"clamp_min", c.clamp_min},
          {"clamp_max", c.clamp_max},
          {"clear_without_obstacle", c.clear_without_obstacle},
          {"free_range_m", c.free_range_m}};
}

namespace {

nlohmann::json SensorJson(const SensorModel& s) {
  const auto& g = s.geometry;
  const auto& a = s.acoustics;
  return {{"name", s.name},
          {"geometry",
           {{"beam_width_horizontal_deg", g.beam_width_horizontal_rad * kRadToDeg},
            {"beam_width_vertical_deg", g.beam_width_vertical_rad * kRadToDeg},
            {"num_bins", g.num_bins},
            {"bin_size_m", g.bin_size_m},
            {"step_angle_deg", g.step_angle_rad * kRadToDeg},
            {"beams_per_second", g.beams_per_second},
            {"self_reflection_range_m", g.self_reflection_range_m}}},
          {"acoustics",
           {{"rays_horizontal", a.pattern.rays_horizontal},
            {"rays_vertical", a.pattern.rays_vertical},
            {"aperture_scale_horizontal", a.pattern.aperture_scale_horizontal},
            {"aperture_scale_vertical", a.pattern.aperture_scale_vertical},
            {"sidelobe_extent_deg", a.pattern.sidelobe_extent_deg},
            {"sidelobe_db", a.pattern.sidelobe_db},
            {"sidelobe_width_deg", a.pattern.sidelobe_width_deg},
            {"sidelobe_rays_horizontal", a.pattern.sidelobe_rays_horizontal},
            {"sidelobe_rays_vertical", a.pattern.sidelobe_rays_vertical},
            {"back_lobe_width_deg", a.pattern.back_lobe_width_deg},
            {"back_lobe_db", a.pattern.back_lobe_db},
            {"back_lobe_rays", a.pattern.back_lobe_rays},
            {"spreading_db_per_decade", a.gain.spreading_db_per_decade},
            {"absorption_db_per_m", a.gain.absorption_db_per_m},
            {"tvg_db_per_decade", a.gain.tvg_db_per_decade},
            {"gain_db", a.gain.gain_db},
            {"pulse_length_m", a.pulse.length_m},
            {"pulse_skirt_length_m", a.pulse.skirt_length_m},
            {"pulse_skirt_db", a.pulse.skirt_db},
            {"noise_level_db", a.noise.level_db},
            {"noise_before_tvg_db", a.noise.before_tvg_db},
            {"blanking_range_m", a.noise.blanking_range_m},
            {"level_jitter_db", a.noise.level_jitter_db},
            {"level_jitter_bin_correlation", a.noise.level_jitter_bin_correlation},
            {"max_bounces", a.max_bounces},
            {"speckle", a.speckle.on},
            {"speckle_looks", a.speckle.looks},
            {"speckle_window_m", a.speckle.window_m},
            {"speckle_correlation_m", a.speckle.correlation_m},
            {"speckle_angular_correlation_deg", a.speckle.angular_correlation_deg},
            {"speckle_own_share", a.speckle.own_share},
            {"reverberation_length_m", a.tail.reverberation_length_m},
            {"reverberation_db", a.tail.reverberation_db},
            {"second_trip_db", a.tail.second_trip_db},
            {"ad_low_db", a.converter.low_db},
            {"ad_span_db", a.converter.span_db},
            {"ad_knee", a.converter.knee},
            {"ad_ceiling", a.converter.ceiling},
            {"ad_levels", a.converter.levels},
            {"self_reflection_db", a.self_reflection.profile_db},
            {"self_reflection_ping_spread_db", a.self_reflection.ping_spread_db},
            {"self_reflection_ringing_range_m", a.self_reflection.ringing_range_m},
            {"self_reflection_angle_spread_db", a.self_reflection.angle_spread_db},
            {"self_reflection_angle_correlation_deg", a.self_reflection.angle_correlation_deg}}}};
}

nlohmann::json BoundJson(const std::optional<double>& bound) {
  return bound ? nlohmann::json(*bound) : nlohmann::json(nullptr);
}

nlohmann::json PerMeshJson(const MapMetrics& m) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : m.per_mesh) {
    out.push_back({{"name", r.name},
                   {"recall", r.recall},
                   {"observable_cells", r.observable_cells},
                   {"observed_occupied_cells", r.observed_occupied_cells}});
  }
  return out;
}

nlohmann::json MeshesJson(const std::vector<ScenarioResult::MeshSummary>& meshes) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& m : meshes) {
    out.push_back({{"name", m.name},
                   {"triangles", m.triangles},
                   {"zero_area_triangles_dropped", m.check.zero_area_triangles},
                   {"boundary_edges", m.check.boundary_edges},
                   {"non_manifold_edges", m.check.non_manifold_edges},
                   {"vehicle_part", m.vehicle_part}});
  }
  return out;
}

double TotalSeconds(const StageTimings& t) {
  return t.build_scene_s + t.simulate_s + t.map_s + t.ground_truth_s + t.score_s;
}

// The images and, beside them on the run's threads, the 3D view's section (`view3d_html`).
std::vector<ReportImage> RenderImages(const Scene& scene, const ScenarioResult& result,
                                      std::string& view3d_html) {
  const std::string name = scene.name + ", seed " + std::to_string(result.seed);
  const std::vector<Eigen::Vector3d> path = SonarPath(scene, result.beams);
  std::vector<ReportImage> images(2);
  std::vector<ReportImage> map_images;
  const octomap::OcTree& tree = result.mapper->tree();  // built once, then only read
  const MapCells cells = CollectMapCells(*result.mapper);
  const std::function<void()> tasks[] = {
      [&] { images[1] = FanImage(result.first_sweep, name); },
      [&] {
        map_images = MapTruthImages(tree, cells, result.score.truth, result.score.observable,
                                    result.score.detector_ghosts, result.sonar_start_m, name, path);
      },
      [&] { view3d_html = View3dHtml(cells, tree.getResolution(), &result.score, path); },
      [&] { images[0] = PolarImage(result.first_sweep, name); }};
  RunTasks(result.threads, tasks);
  for (ReportImage& image : map_images) images.push_back(std::move(image));
  return images;
}

// report.html's lines before the criteria, and the timing table after the metrics.
std::string ScenarioIntroHtml(const Scene& scene, const ScenarioResult& result) {
  std::ostringstream html;
  html << "<p>Scene <code>" << XmlEscape(scene.file) << "</code>, sensor model <code>"
       << XmlEscape(scene.sensor_model_file) << "</code>, seed " << result.seed << ", "
       << result.beams << " beams in " << scene.sweeps << " sweeps, " << result.threads
       << (result.threads == 1 ? " thread, " : " threads, ")
       << Seconds(TotalSeconds(result.timings)) << " s.</p>\n";
  return html.str();
}

std::string TimingHtml(const StageTimings& t) {
  std::ostringstream html;
  html << "<h2>Timing</h2>\n<table><tr><th>stage</th><th>seconds</th></tr>\n";
  for (const auto& [stage, seconds] :
       {std::pair{"build scene", t.build_scene_s}, std::pair{"simulate", t.simulate_s},
        std::pair{"map", t.map_s}, std::pair{"ground truth", t.ground_truth_s},
        std::pair{"score", t.score_s}}) {
    html << "<tr><td>" << stage << "</td><td class=\"n\">" << Seconds(seconds) << "</td></tr>\n";
  }
  html << "</table>\n";
  return html.str();
}

}  // namespace

std::vector<Eigen::Vector3d> SonarPath(const Scene& scene, std::size_t beams) {
  std::vector<Eigen::Vector3d> path;
  for (std::size_t b = 0; b < beams; b += 10) {
    path.push_back(ScheduleBeam(scene, b).pose.T_world_sonar.translation());
  }
  return path;
}

nlohmann::json SceneJson(const Scene& scene) {
  return {{"name", scene.name},
          {"file", scene.file},
          {"extends", scene.extends},
          {"sensor_model", scene.sensor_model_file}};
}

nlohmann::json VerdictJson(const Verdict& v) {
  return {{"passed", v.passed}, {"reasons", v.reasons}, {"warnings", v.warnings}};
}

nlohmann::json CriteriaJson(const Verdict& v) {
  nlohmann::json results = nlohmann::json::array();
  for (const CriterionResult& r : v.results) {
    const Criterion& c = r.criterion;
    results.push_back({{"metric", c.metric},
                       {"actual", r.actual},
                       {"expected", r.expected},
                       {"min", BoundJson(c.min)},
                       {"max", BoundJson(c.max)},
                       {"acceptable_min", BoundJson(c.acceptable_min)},
                       {"acceptable_max", BoundJson(c.acceptable_max)},
                       {"margin", r.margin},
                       {"optional", c.optional},
                       {"status", StatusName(r.status)}});
  }
  return {{"expect", v.expect_fail ? "fail" : "pass"}, {"results", results}};
}

nlohmann::json MetricsJson(const MapMetrics& m) {
  nlohmann::json json = {{"occupied_precision", m.occupied_precision},
                         {"occupied_recall", m.occupied_recall},
                         {"occupied_f1", m.occupied_f1},
                         {"within_cells",
                          {{"cells", {0, 1, 2}},
                           {"precision", m.precision_within},
                           {"recall", m.recall_within},
                           {"f1", m.f1_within}}},
                         {"ghost_share", m.ghost_share},
                         {"column_precision", m.column_precision},
                         {"column_recall", m.column_recall},
                         {"coverage", m.coverage},
                         {"coverage_absolute", m.coverage_absolute},
                         {"free_accuracy", m.free_accuracy},
                         {"per_mesh", PerMeshJson(m)},
                         {"surface_distance",
                          {{"map_to_mesh", DistanceJson(m.map_to_mesh)},
                           {"mesh_to_map", DistanceJson(m.mesh_to_map)}}},
                         {"counts",
                          {{"truth_cells", m.truth_cells},
                           {"observable_cells", m.observable_cells},
                           {"occupied_cells", m.occupied_cells},
                           {"free_cells", m.free_cells},
                           {"true_positive_cells", m.true_positive_cells},
                           {"observed_occupied_cells", m.observed_occupied_cells},
                           {"known_observable_cells", m.known_observable_cells},
                           {"free_on_surface_cells", m.free_on_surface_cells}}}};
  if (m.ghost_arc_share) json["ghost_arc_share"] = *m.ghost_arc_share;
  if (m.ghost_echo_share) json["ghost_echo_share"] = *m.ghost_echo_share;
  if (m.labelled_ghost_split) {
    json["ghost_split_from_labels"] = {{"arc_share", m.labelled_ghost_split->first},
                                       {"echo_share", m.labelled_ghost_split->second}};
  }
  return json;
}

nlohmann::json ScenarioReportJson(const Scene& scene, const ScenarioResult& result) {
  const MapMetrics& m = result.score.metrics;
  const StageTimings& t = result.timings;
  nlohmann::json report = ReportHeader();
  report["schema_version"] = kScenarioReportSchema;
  report.update({{"scene", SceneJson(scene)},
                 {"verdict", VerdictJson(result.score.verdict)},
                 {"criteria", CriteriaJson(result.score.verdict)},
                 {"seed", result.seed},
                 {"threads", result.threads},
                 {"meshes", MeshesJson(result.meshes)},
                 {"parameters",
                  {{"sweeps", scene.sweeps},
                   {"beams", result.beams},
                   {"start_head_angle_deg", scene.start_head_angle_rad * kRadToDeg},
                   {"sensor", SensorJson(scene.sensor)},
                   {"mapping", MapperConfigJson(result.mapper->config())}}},
                 {"metrics", MetricsJson(m)},
                 {"mapping_totals",
                  {{"beams", result.mapping_totals.beams},
                   {"beams_with_obstacle", result.mapping_totals.beams_with_obstacle},
                   {"ray_casts", result.mapping_totals.ray_casts},
                   {"cell_visits", result.mapping_totals.cell_visits},
                   {"free_cell_updates", result.mapping_totals.free_cells},
                   {"occupied_cell_updates", result.mapping_totals.occupied_cells}}},
                 {"timing",
                  {{"build_scene_s", t.build_scene_s},
                   {"simulate_s", t.simulate_s},
                   {"map_s", t.map_s},
                   {"ground_truth_s", t.ground_truth_s},
                   {"score_s", t.score_s},
                   {"total_s", TotalSeconds(t)}}},
                 {"outputs",
                  {{"map", "map.bt"},
                   {"polar", "polar.png"},
                   {"fan", "fan.png"},
                   {"map_top", "map_top.png"},
                   {"map_side", "map_side.png"},
                   {"junit", "junit.xml"},
                   {"html", "report.html"}}}});
  return report;
}

std::string ErrorJunitXml(std::string_view scenario, std::string_view error_type,
                          std::string_view message) {
  const std::string suite = XmlEscape(scenario);
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<testsuites name=\"sonarbench\" tests=\"1\" failures=\"0\" errors=\"1\">\n"
      << "  <testsuite name=\"" << suite << "\" tests=\"1\" failures=\"0\" errors=\"1\">\n"
      << "    <testcase classname=\"sonarbench." << suite << "\" name=\"scenario\">\n"
      << "      <error type=\"" << XmlEscape(error_type) << "\" message=\"" << XmlEscape(message)
      << "\"/>\n"
      << "    </testcase>\n  </testsuite>\n</testsuites>\n";
  return xml.str();
}

void WriteScenarioOutputs(const std::string& out_dir, const Scene& scene,
                          const ScenarioResult& result) {
  CreateOutputDirectory(out_dir);
  io::WriteMapFile(*result.mapper, out_dir + "/map.bt", io::MapFormat::kBinary);
  MapReport report;
  report.title = "sonarbench: " + scene.name;
  report.heading = "sonarbench scenario: " + scene.name;
  report.intro_html = ScenarioIntroHtml(scene, result);
  report.after_scores_html = TimingHtml(result.timings);
  report.images = RenderImages(scene, result, report.view3d_html);
  report.json = ScenarioReportJson(scene, result);
  report.files = {"map.bt"};
  report.scene = &scene;
  report.score = &result.score;
  report.junit = {
      "scenario",
      "seed " + std::to_string(result.seed) + ", " + std::to_string(result.beams) + " beams",
      {{"scene_file", scene.file}, {"seed", std::to_string(result.seed)}},
      TotalSeconds(result.timings)};
  WriteMapReport(out_dir, report);
}

std::string XmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      case '\n':
        out += "&#10;";
        break;
      default:
        // XML 1.0 allows no control character but tab, newline and carriage return.
        out += (c < 0x20 && ch != '\t' && ch != '\r') ? '?' : ch;
    }
  }
  return out;
}

std::string Base64(const std::vector<unsigned char>& bytes) {
  // EVP_EncodeBlock writes 4 characters per 3 bytes (padded with '=') and a terminating NUL.
  std::string out((bytes.size() + 2) / 3 * 4 + 1, '\0');
  const int written = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(out.data()), bytes.data(),
                                      static_cast<int>(bytes.size()));
  out.resize(static_cast<std::size_t>(written));
  return out;
}

}  // namespace sonarbench::sim
