#include "sonarbench/sim/report/scenario_report.hpp"

#include <openssl/evp.h>

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "sonarbench/mapping/atomic_file.hpp"
#include "sonarbench/sim/report/images.hpp"
#include "sonarbench/sim/report/report.hpp"

namespace sonarbench::sim {
namespace {

constexpr double kRadToDeg = 1.0 / mapping::kDegToRad;

nlohmann::json DistanceJson(const DistanceStats& d) {
  return {{"count", d.count}, {"mean_m", d.mean_m}, {"p95_m", d.p95_m}, {"max_m", d.max_m}};
}

const char* DetectionMethodName(mapping::DetectionConfig::Method method) {
  switch (method) {
    case mapping::DetectionConfig::Method::kThreshold:
      return "threshold";
    case mapping::DetectionConfig::Method::kCanny:
      return "canny";
    case mapping::DetectionConfig::Method::kAutoCanny:
      return "auto_canny";
  }
  return "?";
}

nlohmann::json MappingJson(const mapping::MapperConfig& c) {
  return {{"resolution_m", c.resolution_m},
          {"rays_horizontal", c.rays_horizontal},
          {"rays_vertical", c.rays_vertical},
          {"detection",
           {{"method", DetectionMethodName(c.detection.method)},
            {"threshold", c.detection.threshold},
            {"smoothing_bins", c.detection.smoothing_bins},
            {"min_run_bins", c.detection.min_run_bins},
            {"max_obstacles", c.detection.max_obstacles},
            {"canny_low", c.detection.canny_low},
            {"canny_high", c.detection.canny_high},
            {"canny_blur_sigma", c.detection.canny_blur_sigma},
            {"auto_canny_sigma", c.detection.auto_canny_sigma}}},
          {"key_set", c.key_set == mapping::KeySetKind::kStd ? "std" : "open_addressing"},
          {"prob_hit", c.prob_hit},
          {"prob_miss", c.prob_miss},
          {"clamp_min", c.clamp_min},
          {"clamp_max", c.clamp_max},
          {"clear_without_obstacle", c.clear_without_obstacle},
          {"free_range_m", c.free_range_m}};
}

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
           {{"rays_horizontal", a.rays_horizontal},
            {"rays_vertical", a.rays_vertical},
            {"aperture_scale_horizontal", a.aperture_scale_horizontal},
            {"aperture_scale_vertical", a.aperture_scale_vertical},
            {"sidelobe_extent_deg", a.sidelobe_extent_deg},
            {"sidelobe_db", a.sidelobe_db},
            {"sidelobe_width_deg", a.sidelobe_width_deg},
            {"sidelobe_rays_horizontal", a.sidelobe_rays_horizontal},
            {"sidelobe_rays_vertical", a.sidelobe_rays_vertical},
            {"back_lobe_width_deg", a.back_lobe_width_deg},
            {"back_lobe_db", a.back_lobe_db},
            {"back_lobe_rays", a.back_lobe_rays},
            {"spreading_db_per_decade", a.spreading_db_per_decade},
            {"absorption_db_per_m", a.absorption_db_per_m},
            {"tvg_db_per_decade", a.tvg_db_per_decade},
            {"gain_db", a.gain_db},
            {"pulse_length_m", a.pulse_length_m},
            {"pulse_skirt_length_m", a.pulse_skirt_length_m},
            {"pulse_skirt_db", a.pulse_skirt_db},
            {"noise_level_db", a.noise_level_db},
            {"noise_before_tvg_db", a.noise_before_tvg_db},
            {"blanking_range_m", a.blanking_range_m},
            {"level_jitter_db", a.level_jitter_db},
            {"level_jitter_bin_correlation", a.level_jitter_bin_correlation},
            {"max_bounces", a.max_bounces},
            {"speckle", a.speckle},
            {"speckle_looks", a.speckle_looks},
            {"speckle_window_m", a.speckle_window_m},
            {"speckle_correlation_m", a.speckle_correlation_m},
            {"speckle_angular_correlation_deg", a.speckle_angular_correlation_deg},
            {"speckle_own_share", a.speckle_own_share},
            {"reverberation_length_m", a.reverberation_length_m},
            {"reverberation_db", a.reverberation_db},
            {"second_trip_db", a.second_trip_db},
            {"ad_low_db", a.ad_low_db},
            {"ad_span_db", a.ad_span_db},
            {"ad_knee", a.ad_knee},
            {"ad_ceiling", a.ad_ceiling},
            {"ad_levels", a.ad_levels},
            {"self_reflection_db", a.self_reflection_db},
            {"self_reflection_ping_spread_db", a.self_reflection_ping_spread_db},
            {"self_reflection_ringing_range_m", a.self_reflection_ringing_range_m},
            {"self_reflection_angle_spread_db", a.self_reflection_angle_spread_db},
            {"self_reflection_angle_correlation_deg", a.self_reflection_angle_correlation_deg}}}};
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

std::string Seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", s);
  return text;
}

/// The images of a run, encoded once: written as files and embedded in the HTML report.
struct Image {
  const char* file;
  const char* caption;
  std::vector<unsigned char> png;
};

std::vector<Image> RenderImages(const ScenarioResult& result) {
  const MapCells cells = CollectMapCells(result.mapper->tree());
  MapView side;
  side.kind = MapView::Kind::kSide;
  side.slab_key = result.mapper->tree().coordToKey(
      result.sonar_start_m.x(), result.sonar_start_m.y(), result.sonar_start_m.z())[1];
  return {
      {"polar.png", "First sweep, polar: one row per beam in time order, range to the right.",
       EncodePng(RenderPolarImage(result.first_sweep))},
      {"fan.png", "First sweep, Cartesian fan from above: the sonar at the centre, 1 cm per pixel.",
       EncodePng(RenderFanImage(result.first_sweep, 0.01))},
      {"map_top.png",
       "Map against truth from above, one pixel per cell column: green true positive, red only "
       "false positives, blue observable truth missed, grey free.",
       EncodePng(RenderMapView(cells, result.truth, result.observable, MapView{}))},
      {"map_side.png",
       "Side slice through the sonar (3 cells thick in y), x to the right, z up; same colours.",
       EncodePng(RenderMapView(cells, result.truth, result.observable, side))},
  };
}

std::string HtmlEscape(std::string_view text) { return XmlEscape(text); }

// report.html's criteria section: each criterion's actual, expected, margin and status.
std::string CriteriaHtml(const Verdict& v) {
  std::ostringstream html;
  html << "<h2>Criteria</h2>\n";
  if (v.results.empty()) {
    html << "<p>The scene sets no criteria: the scenario passes when it runs.</p>\n";
  } else {
    html << "<table><tr><th>metric</th><th>actual</th><th>expected</th><th>margin</th>"
            "<th>status</th><th>optional</th></tr>\n";
    for (const CriterionResult& r : v.results) {
      html << "<tr class=\"" << StatusName(r.status) << "\"><td>" << HtmlEscape(r.criterion.metric)
           << "</td><td class=\"n\">" << FormatMetricValue(r.actual) << "</td><td>"
           << HtmlEscape(r.expected) << "</td><td class=\"n\">" << FormatMetricValue(r.margin)
           << "</td><td>" << StatusName(r.status) << "</td><td>"
           << (r.criterion.optional ? "yes" : "no") << "</td></tr>\n";
    }
    html << "</table>\n";
  }
  return html.str();
}

// report.html's metrics section: every known metric with its definition, each mesh's recall, the
// counts.
std::string MetricsHtml(const MapMetrics& m) {
  std::ostringstream html;
  html << "<h2>Metrics</h2>\n<table><tr><th>metric</th><th>value</th><th>definition</th></tr>\n";
  for (const MetricInfo& info : KnownMetrics()) {
    html << "<tr><td>" << info.name << "</td><td class=\"n\">"
         << FormatMetricValue(MetricValue(m, info.name)) << "</td><td>"
         << HtmlEscape(info.definition) << "</td></tr>\n";
  }
  for (const auto& r : m.per_mesh) {
    html << "<tr><td>" << kMeshRecallPrefix << HtmlEscape(r.name) << "</td><td class=\"n\">"
         << FormatMetricValue(r.recall) << "</td><td>" << r.observed_occupied_cells << " of "
         << r.observable_cells << " observable cells of this mesh mapped occupied</td></tr>\n";
  }
  html << "</table>\n<p>Counts: " << m.truth_cells << " surface cells, " << m.observable_cells
       << " observable, " << m.occupied_cells << " occupied (" << m.true_positive_cells
       << " on a surface), " << m.free_cells
       << " free. Unknown cells are neither occupied nor "
          "free: they lower coverage and recall, never precision.</p>\n";
  return html.str();
}

std::string ScenarioHtml(const Scene& scene, const ScenarioResult& result,
                         const std::vector<Image>& images) {
  const Verdict& v = result.verdict;
  const MapMetrics& m = result.metrics;
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>sonarbench: "
       << HtmlEscape(scene.name) << " " << (v.passed ? "PASS" : "FAIL") << "</title>\n"
       << "<style>body{font-family:sans-serif;margin:2em;max-width:70em}"
          "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;"
          "padding:.25em .6em;text-align:left}td.n{text-align:right;font-family:monospace}"
          ".pass{background:#d9f2d9}.acceptable{background:#fff3cd}.fail{background:#f8d7da}"
          ".verdict{font-size:1.5em;padding:.4em .8em;display:inline-block}"
          "figure{display:inline-block;vertical-align:top;margin:.5em;max-width:32em}"
          "img{max-width:100%;image-rendering:pixelated}</style></head><body>\n";
  html << "<h1>sonarbench scenario: " << HtmlEscape(scene.name) << "</h1>\n"
       << "<p class=\"verdict " << (v.passed ? "pass" : "fail") << "\">"
       << (v.passed ? "PASS" : "FAIL") << (v.expect_fail ? " (expected to fail)" : "") << "</p>\n";
  if (!v.reasons.empty() || !v.warnings.empty()) {
    html << "<ul>\n";
    for (const auto& r : v.reasons) html << "<li class=\"fail\">" << HtmlEscape(r) << "</li>\n";
    for (const auto& w : v.warnings)
      html << "<li class=\"acceptable\">" << HtmlEscape(w) << "</li>\n";
    html << "</ul>\n";
  }
  html << "<p>Scene <code>" << HtmlEscape(scene.file) << "</code>, sensor model <code>"
       << HtmlEscape(scene.sensor_model_file) << "</code>, seed " << result.seed << ", "
       << result.beams << " beams in " << scene.sweeps << " sweeps, " << result.threads
       << " threads, " << Seconds(TotalSeconds(result.timings)) << " s.</p>\n";

  html << CriteriaHtml(v);
  html << MetricsHtml(m);

  const StageTimings& t = result.timings;
  html << "<h2>Timing</h2>\n<table><tr><th>stage</th><th>seconds</th></tr>\n";
  for (const auto& [stage, seconds] :
       {std::pair{"build scene", t.build_scene_s}, std::pair{"simulate", t.simulate_s},
        std::pair{"map", t.map_s}, std::pair{"ground truth", t.ground_truth_s},
        std::pair{"score", t.score_s}}) {
    html << "<tr><td>" << stage << "</td><td class=\"n\">" << Seconds(seconds) << "</td></tr>\n";
  }
  html << "</table>\n<h2>Images</h2>\n";
  for (const Image& image : images) {
    html << "<figure><img alt=\"" << image.file << "\" src=\"data:image/png;base64,"
         << Base64(image.png) << "\"><figcaption><code>" << image.file
         << "</code>: " << HtmlEscape(image.caption) << "</figcaption></figure>\n";
  }
  html << "</body></html>\n";
  return html.str();
}

void WriteText(const std::string& path, const std::string& text) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace

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
  return {{"occupied_precision", m.occupied_precision},
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
}

nlohmann::json ScenarioReportJson(const Scene& scene, const ScenarioResult& result) {
  const MapMetrics& m = result.metrics;
  const StageTimings& t = result.timings;
  nlohmann::json report = ReportHeader();
  report["schema_version"] = kScenarioReportSchema;
  report.update({{"scene",
                  {{"name", scene.name},
                   {"file", scene.file},
                   {"extends", scene.extends},
                   {"sensor_model", scene.sensor_model_file}}},
                 {"verdict", VerdictJson(result.verdict)},
                 {"criteria", CriteriaJson(result.verdict)},
                 {"seed", result.seed},
                 {"threads", result.threads},
                 {"meshes", MeshesJson(result.meshes)},
                 {"parameters",
                  {{"sweeps", scene.sweeps},
                   {"beams", result.beams},
                   {"start_head_angle_deg", scene.start_head_angle_rad * kRadToDeg},
                   {"sensor", SensorJson(scene.sensor)},
                   {"mapping", MappingJson(result.mapper->config())}}},
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

std::string ScenarioJunitXml(const Scene& scene, const ScenarioResult& result) {
  const Verdict& v = result.verdict;
  const std::string suite = XmlEscape(scene.name);
  const std::string classname = "sonarbench." + suite;
  std::size_t failures = 0;
  std::ostringstream cases;
  // The run itself: fails only when an expect-fail scenario met all its criteria.
  cases << "    <testcase classname=\"" << classname << "\" name=\"scenario\" time=\""
        << Seconds(TotalSeconds(result.timings)) << "\">\n";
  if (v.expect_fail && !v.passed) {
    ++failures;
    cases << "      <failure type=\"expectation\" message=\"" << XmlEscape(v.reasons.front())
          << "\"/>\n";
  }
  cases << "      <system-out>seed " << result.seed << ", " << result.beams << " beams, "
        << (v.expect_fail ? "expect: fail" : "expect: pass") << "</system-out>\n"
        << "    </testcase>\n";
  for (const CriterionResult& r : v.results) {
    cases << "    <testcase classname=\"" << classname << "\" name=\""
          << XmlEscape(r.criterion.metric) << "\" time=\"0\">\n";
    const bool counts = r.status == CriterionStatus::kFail && !r.criterion.optional;
    if (counts && !v.expect_fail) {
      ++failures;
      cases << "      <failure type=\"criterion\" message=\"" << XmlEscape(Describe(r)) << "\"/>\n";
    } else {
      std::string note = Describe(r);
      if (r.criterion.optional && r.status != CriterionStatus::kPass) note += " (optional)";
      if (counts && v.expect_fail) note += " (failure expected: expect: fail)";
      cases << "      <system-out>" << XmlEscape(note) << "</system-out>\n";
    }
    cases << "    </testcase>\n";
  }
  const std::size_t tests = v.results.size() + 1;
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<testsuites name=\"sonarbench\" tests=\"" << tests << "\" failures=\"" << failures
      << "\" errors=\"0\" time=\"" << Seconds(TotalSeconds(result.timings)) << "\">\n"
      << "  <testsuite name=\"" << suite << "\" tests=\"" << tests << "\" failures=\"" << failures
      << "\" errors=\"0\" skipped=\"0\" time=\"" << Seconds(TotalSeconds(result.timings)) << "\">\n"
      << "    <properties>\n"
      << "      <property name=\"scene_file\" value=\"" << XmlEscape(scene.file) << "\"/>\n"
      << "      <property name=\"seed\" value=\"" << result.seed << "\"/>\n"
      << "    </properties>\n"
      << cases.str() << "  </testsuite>\n</testsuites>\n";
  return xml.str();
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
  namespace fs = std::filesystem;
  CreateOutputDirectory(out_dir);
  const fs::path dir(out_dir);
  result.mapper->WriteBinary((dir / "map.bt").string());
  const std::vector<Image> images = RenderImages(result);
  for (const Image& image : images) {
    WriteFileAtomically((dir / image.file).string(), [&](std::ostream& out) {
      out.write(reinterpret_cast<const char*>(image.png.data()),
                static_cast<std::streamsize>(image.png.size()));
    });
  }
  WriteText((dir / "junit.xml").string(), ScenarioJunitXml(scene, result));
  WriteText((dir / "report.html").string(), ScenarioHtml(scene, result, images));
  // The report last, naming what it covers.
  nlohmann::json report = ScenarioReportJson(scene, result);
  std::vector<std::string> covered = kScenarioOutputFiles;
  std::erase(covered, "report.json");
  report["files_sha256"] = FilesSha256(out_dir, covered);
  WriteJson((dir / "report.json").string(), report);
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
