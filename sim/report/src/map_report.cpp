#include "sonarbench/sim/report/map_report.hpp"

#include <sstream>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/sim/report/report.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"

namespace sonarbench::sim {

namespace {

std::string MapReportHtml(const MapReport& r) {
  const Verdict* verdict = r.score ? &r.score->verdict : nullptr;
  std::ostringstream html;
  html << HtmlPageStart(r.title + (verdict ? (verdict->passed ? " PASS" : " FAIL") : ""), r.heading,
                        verdict)
       << r.intro_html;
  if (r.score) html << CriteriaHtml(*verdict) << MetricsHtml(r.score->metrics);
  html << r.view3d_html << r.after_scores_html << ImagesHtmlAndEnd(r.images);
  return html.str();
}

}  // namespace

void WriteMapReport(const std::string& out_dir, const MapReport& r) {
  WriteReportImages(out_dir, r.images);
  std::vector<std::string> covered = r.files;
  for (const ReportImage& image : r.images) covered.push_back(image.file);
  if (r.score) {
    WriteFileAtomically(out_dir + "/junit.xml", [&](std::ostream& out) {
      out << ScoredJunitXml(*r.scene, r.junit.name, r.junit.note, r.junit.properties,
                            r.score->verdict, r.junit.seconds);
    });
    covered.push_back("junit.xml");
  }
  WriteFileAtomically(out_dir + "/report.html",
                      [&](std::ostream& out) { out << MapReportHtml(r); });
  covered.push_back("report.html");
  nlohmann::json json = r.json;
  if (r.score) {
    json["metrics"] = MetricsJson(r.score->metrics);
    json["verdict"] = VerdictJson(r.score->verdict);
    json["criteria"] = CriteriaJson(r.score->verdict);
  }
  json["files_sha256"] = FilesSha256(out_dir, covered);
  WriteJson(out_dir + "/report.json", json);
}

}  // namespace sonarbench::sim
