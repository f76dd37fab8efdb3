#include "sonarbench/sim/report/report_page.hpp"

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <sstream>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/sim/report/images.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"

namespace sonarbench::sim {
namespace {

std::string HtmlEscape(std::string_view text) { return XmlEscape(text); }

// JUnit <testcase>s, one per criterion: a <failure> when a required criterion missed its bound
// (unless the scene expects a failure); `failures` counts them.
std::string CriteriaTestCases(const std::string& classname, const Verdict& v,
                              std::size_t& failures) {
  std::ostringstream cases;
  for (const CriterionResult& r : v.results) {
    cases << "    <testcase classname=\"" << classname << "\" name=\""
          << XmlEscape(r.criterion.metric) << "\" time=\"0\">\n";
    const bool counts = r.status == CriterionStatus::kFail && !r.criterion.optional;
    if (r.status == CriterionStatus::kNotApplicable) {
      cases << "      <skipped message=\"" << XmlEscape(r.criterion.metric)
            << ": not applicable to this map\"/>\n";
    } else if (counts && !v.expect_fail) {
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
  return cases.str();
}

}  // namespace

ReportImage PolarImage(std::span<const mapping::Beam> sweep, const std::string& name) {
  return {"polar.png", "First sweep, polar: one row per beam in time order, range to the right.",
          EncodePng(RenderPolarImage(sweep, name + ": first sweep, polar"))};
}

ReportImage FanImage(std::span<const mapping::Beam> sweep, const std::string& name) {
  return {"fan.png",
          "First sweep, Cartesian fan from above: the sonar at the centre, 1 cm per pixel.",
          EncodePng(RenderFanImage(sweep, 0.01, name + ": first sweep, fan"))};
}

void RunTasks(int threads, std::span<const std::function<void()>> tasks) {
  std::vector<std::exception_ptr> errors(tasks.size());
  const auto count = static_cast<int>(tasks.size());
#pragma omp parallel for num_threads(threads > 0 ? threads : omp_get_max_threads()) \
    schedule(dynamic, 1)
  for (int i = 0; i < count; ++i) {
    try {
      tasks[static_cast<std::size_t>(i)]();
    } catch (...) {
      errors[static_cast<std::size_t>(i)] = std::current_exception();
    }
  }
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

std::string Seconds(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", seconds);
  return text;
}

std::vector<ReportImage> MapTruthImages(const octomap::OcTree& map, const MapCells& cells,
                                        const mapping::KeySet& truth,
                                        const mapping::KeySet& observable,
                                        const mapping::KeySet& detector_ghosts,
                                        const Eigen::Vector3d& side_slice_m,
                                        const std::string& name,
                                        const std::vector<Eigen::Vector3d>& sonar_path_m) {
  MapView top;
  top.resolution_m = map.getResolution();
  top.title = name + ": map against truth, from above";
  for (const Eigen::Vector3d& p : sonar_path_m)
    top.sonar.push_back(map.coordToKey(p.x(), p.y(), p.z()));
  if (top.sonar.empty()) {
    top.sonar.push_back(map.coordToKey(side_slice_m.x(), side_slice_m.y(), side_slice_m.z()));
  }
  MapView side = top;
  side.kind = MapView::Kind::kSide;
  side.slab_key = map.coordToKey(side_slice_m.x(), side_slice_m.y(), side_slice_m.z())[1];
  char slice[96];
  std::snprintf(slice, sizeof slice, ": side slice at y = %.2f m", side_slice_m.y());
  side.title = name + slice;
  return {
      {"map_top.png",
       "Map against truth from above, whole pixels per cell column: green true positive, magenta "
       "the detector's ghosts (where no surface answers directly), red other false positives, "
       "blue observable truth missed, grey free.",
       EncodePng(RenderMapView(cells, truth, observable, top, detector_ghosts))},
      {"map_side.png",
       "Side slice through the sonar (3 cells thick in y), x to the right, z up; same colours.",
       EncodePng(RenderMapView(cells, truth, observable, side, detector_ghosts))},
  };
}

void WriteReportImages(const std::string& dir, const std::vector<ReportImage>& images) {
  for (const ReportImage& image : images) {
    WriteFileAtomically((std::filesystem::path(dir) / image.file).string(), [&](std::ostream& out) {
      out.write(reinterpret_cast<const char*>(image.png.data()),
                static_cast<std::streamsize>(image.png.size()));
    });
  }
}

std::string HtmlPageStart(const std::string& title, const std::string& heading,
                          const Verdict* verdict) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>"
       << HtmlEscape(title) << "</title>\n"
       << "<style>body{font-family:sans-serif;margin:2em;max-width:82em}"
          "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;"
          "padding:.25em .6em;text-align:left}td.n{text-align:right;font-family:monospace}"
          ".pass{background:#d9f2d9}.acceptable{background:#fff3cd}.fail{background:#f8d7da}"
          ".verdict{font-size:1.5em;padding:.4em .8em;display:inline-block}"
          "figure{margin:1.5em 0}figcaption{max-width:60em}"
          "img{max-width:100%;image-rendering:pixelated}"
          ".view3d{position:relative;height:38em;background:#1e1e1e}"
          ".view3d canvas{display:block;width:100%;height:100%}"
          ".view3d-legend{position:absolute;top:.5em;left:.5em;padding:.3em .6em;"
          "background:rgba(255,255,255,.85);font-size:.9em}.view3d-legend label{display:block}"
          ".swatch{display:inline-block;width:.9em;height:.9em;margin:0 .4em;"
          "vertical-align:middle;border:1px solid #555}</style></head><body>\n";
  html << "<h1>" << HtmlEscape(heading) << "</h1>\n";
  if (!verdict) return html.str();
  const Verdict& v = *verdict;
  html << "<p class=\"verdict " << (v.passed ? "pass" : "fail") << "\">"
       << (v.passed ? "PASS" : "FAIL") << (v.expect_fail ? " (expected to fail)" : "") << "</p>\n";
  if (!v.reasons.empty() || !v.warnings.empty()) {
    html << "<ul>\n";
    for (const auto& r : v.reasons) html << "<li class=\"fail\">" << HtmlEscape(r) << "</li>\n";
    for (const auto& w : v.warnings)
      html << "<li class=\"acceptable\">" << HtmlEscape(w) << "</li>\n";
    html << "</ul>\n";
  }
  return html.str();
}

std::string CriteriaHtml(const Verdict& v) {
  std::ostringstream html;
  html << "<h2>Criteria</h2>\n";
  if (v.results.empty()) {
    html << "<p>The scene sets no criteria: the scenario passes when it runs.</p>\n";
    return html.str();
  }
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
  return html.str();
}

std::string MetricsHtml(const MapMetrics& m) {
  std::ostringstream html;
  html << "<h2>Metrics</h2>\n<table><tr><th>metric</th><th>value</th><th>definition</th></tr>\n";
  for (const MetricInfo& info : KnownMetrics()) {
    const double value = MetricValue(m, info.name);
    html << "<tr><td>" << info.name << "</td><td class=\"n\">"
         << (std::isnan(value) ? "not applicable" : FormatMetricValue(value)) << "</td><td>"
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

std::string TableHtml(const std::string& heading,
                      const std::vector<std::pair<std::string, std::string>>& rows, bool numeric) {
  std::ostringstream html;
  html << "<h2>" << HtmlEscape(heading) << "</h2>\n<table>\n";
  for (const auto& [label, value] : rows) {
    html << "<tr><td>" << HtmlEscape(label) << "</td><td" << (numeric ? " class=\"n\"" : "") << ">"
         << HtmlEscape(value) << "</td></tr>\n";
  }
  html << "</table>\n";
  return html.str();
}

std::string MappingHtml(const mapping::MapperConfig& config) {
  std::vector<std::pair<std::string, std::string>> rows;
  const auto add = [&rows](const std::string& key, const nlohmann::json& v) {
    rows.emplace_back(key, v.is_string() ? v.get<std::string>() : v.dump());
  };
  const nlohmann::json mapping = MapperConfigJson(config);
  const nlohmann::json& detection = mapping.at("detection");
  for (auto it = mapping.cbegin(); it != mapping.cend(); ++it) {
    if (it.key() != "detection") add(it.key(), it.value());
  }
  for (auto it = detection.cbegin(); it != detection.cend(); ++it) {
    add("detection." + it.key(), it.value());
  }
  return TableHtml("Mapping", rows, false);
}

std::string ImagesHtmlAndEnd(const std::vector<ReportImage>& images) {
  std::ostringstream html;
  html << "<h2>Images</h2>\n";
  for (const ReportImage& image : images) {
    html << "<figure><img alt=\"" << image.file << "\" src=\"data:image/png;base64,"
         << Base64(image.png) << "\"><figcaption><code>" << image.file
         << "</code>: " << HtmlEscape(image.caption) << "</figcaption></figure>\n";
  }
  html << "</body></html>\n";
  return html.str();
}

std::string ScoredJunitXml(const Scene& scene, const std::string& first_case,
                           const std::string& note,
                           const std::vector<std::pair<std::string, std::string>>& properties,
                           const Verdict& v, double seconds) {
  const std::string suite = XmlEscape(scene.name);
  const std::string classname = "sonarbench." + suite;
  std::size_t failures = 0;
  std::ostringstream cases;
  cases << "    <testcase classname=\"" << classname << "\" name=\"" << XmlEscape(first_case)
        << "\" time=\"" << Seconds(seconds) << "\">\n";
  if (v.expect_fail && !v.passed) {
    ++failures;
    cases << "      <failure type=\"expectation\" message=\"" << XmlEscape(v.reasons.front())
          << "\"/>\n";
  }
  cases << "      <system-out>" << XmlEscape(note) << ", "
        << (v.expect_fail ? "expect: fail" : "expect: pass") << "</system-out>\n"
        << "    </testcase>\n"
        << CriteriaTestCases(classname, v, failures);
  const std::size_t tests = v.results.size() + 1;
  std::size_t skipped = 0;
  for (const CriterionResult& r : v.results) skipped += r.status == CriterionStatus::kNotApplicable;
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<testsuites name=\"sonarbench\" tests=\"" << tests << "\" failures=\"" << failures
      << "\" errors=\"0\" time=\"" << Seconds(seconds) << "\">\n"
      << "  <testsuite name=\"" << suite << "\" tests=\"" << tests << "\" failures=\"" << failures
      << "\" errors=\"0\" skipped=\"" << skipped << "\" time=\"" << Seconds(seconds) << "\">\n"
      << "    <properties>\n";
  for (const auto& [name, value] : properties) {
    xml << "      <property name=\"" << XmlEscape(name) << "\" value=\"" << XmlEscape(value)
        << "\"/>\n";
  }
  xml << "    </properties>\n" << cases.str() << "  </testsuite>\n</testsuites>\n";
  return xml.str();
}

}  // namespace sonarbench::sim
