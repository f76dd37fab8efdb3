#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "sonarbench/sim/report/fidelity_report.hpp"
#include "sonarbench/sim/report/report.hpp"
#include "sonarbench/sim/report/report_page.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"

namespace sonarbench::sim {
namespace {

const char* const kFigures[] = {"precision_1", "recall_1", "f1_1", "ghost_arc_share",
                                "ghost_echo_share"};

// A number of fidelity.json to `decimals` places, or "none".
std::string Fixed(const nlohmann::json& value, int decimals) {
  if (!value.is_number()) return "none";
  const double v = value.get<double>();
  if (!std::isfinite(v)) return "none";
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", decimals, v);
  return text;
}

// The maps' verdict in a sentence: whether every part meets the goals, and what misses where.
std::string MapsVerdict(const nlohmann::json& maps) {
  std::string missed;
  for (const auto& part : maps.at("parts")) {
    const auto& agreement = part.at("agreement");
    std::string here;
    for (const auto& [figure, values] : agreement.at("figures").items()) {
      if (!values.at("meets").get<bool>()) here += (here.empty() ? "" : ", ") + figure;
    }
    if (!agreement.at("best_f1_1").at("same").get<bool>()) {
      here += std::string(here.empty() ? "" : ", ") + "the best setting";
    }
    if (!here.empty()) {
      missed +=
          (missed.empty() ? "" : "; ") + here + " (" + part.at("name").get<std::string>() + ")";
    }
  }
  const auto& goals = maps.at("parts").at(0).at("agreement").at("goals");
  std::string text = maps.at("meets").get<bool>()
                         ? "The simulated scene predicts the log's maps"
                         : "The simulated scene does not predict the log's maps";
  text +=
      " (goals over the " + std::to_string(maps.at("settings").size()) +
      " settings, per part: mean |difference| <= " + Fixed(goals.at("max_mean_abs_difference"), 2) +
      ", max <= " + Fixed(goals.at("max_abs_difference"), 2) +
      ", Spearman >= " + Fixed(goals.at("min_spearman"), 2) + ", the same best setting by F1@1)";
  if (!missed.empty()) text += "; missed: " + missed;
  return text + ".";
}

// The beams' key statistics as (label, value) rows.
std::vector<std::pair<std::string, std::string>> BeamRows(const nlohmann::json& r) {
  return {
      {"mean intensity against range: correlation, all bins / past the self-reflection",
       Fixed(r.at("profile_correlation_all_bins"), 3) + " / " +
           Fixed(r.at("profile_correlation_usable_bins"), 3)},
      {"the strongest echo's range per head angle: median difference [bins]",
       Fixed(r.at("median_wall_range_difference_bins"), 1)},
      {"intensity histograms: intersection (1 = identical)",
       Fixed(r.at("histogram_intersection"), 3)},
      {"sweep-to-sweep spread per head angle and bin [intensity]: sim / real",
       Fixed(r.at("sweep_spread_sim"), 2) + " / " + Fixed(r.at("sweep_spread_real"), 2)},
  };
}

// One part's agreement as an HTML table: a row per figure.
std::string AgreementHtml(const nlohmann::json& part) {
  std::ostringstream html;
  const auto& a = part.at("agreement");
  html << "<h3>" << XmlEscape(part.at("name").get<std::string>()) << "</h3>\n<table>\n"
       << "<tr><th>figure</th><th>Spearman</th><th>mean |difference|</th>"
       << "<th>max |difference|</th><th>meets</th></tr>\n";
  for (const char* figure : kFigures) {
    const auto& f = a.at("figures").at(figure);
    html << "<tr><td>" << figure << "</td><td class=\"n\">" << Fixed(f.at("spearman"), 2)
         << "</td><td class=\"n\">" << Fixed(f.at("mean_abs_difference"), 3)
         << "</td><td class=\"n\">" << Fixed(f.at("max_abs_difference"), 3) << "</td><td>"
         << (f.at("meets").get<bool>() ? "yes" : "no") << "</td></tr>\n";
  }
  const auto& best = a.at("best_f1_1");
  html << "</table>\n<p>Best F1 at 1 cell: " << XmlEscape(best.at("scene").get<std::string>())
       << " (simulated), " << XmlEscape(best.at("log").get<std::string>()) << " (log).</p>\n";
  return html.str();
}

}  // namespace

std::string FidelityHtml(const nlohmann::json& r) {
  std::ostringstream html;
  html << HtmlPageStart("sonarbench fidelity", "Fidelity: the simulated scene against the log",
                        nullptr);
  const nlohmann::json maps = r.value("maps", nlohmann::json());
  if (!maps.is_null()) {
    html << "<p class=\"verdict " << (maps.at("meets").get<bool>() ? "pass" : "fail") << "\">"
         << XmlEscape(MapsVerdict(maps)) << "</p>\n";
  }
  html << "<p>Scene " << XmlEscape(r.at("scene").dump()) << ", log "
       << XmlEscape(r.at("log").dump())
       << ". Maps are scored against the scene's surfaces at 1 cell of tolerance (shares, 0-1); "
          "intensities are the sonar's 0-255 scale; every statistic is in fidelity.json.</p>\n";
  html << TableHtml("The beams", BeamRows(r), true);
  if (!maps.is_null()) {
    html << "<h2>The maps, setting by setting (maps.csv)</h2>\n";
    for (const auto& part : maps.at("parts")) html << AgreementHtml(part);
  }
  html << "<h2>Images</h2>\n";
  for (const char* file : {"profile.png", "polar.png", "fan.png"}) {
    html << "<figure><img src=\"" << file << "\" alt=\"" << file << "\"><figcaption>" << file
         << "</figcaption></figure>\n";
  }
  html << "</body>\n</html>\n";
  return html.str();
}

std::string FidelityBrief(const nlohmann::json& r) {
  std::ostringstream text;
  for (const auto& [label, value] : BeamRows(r)) text << label << ": " << value << "\n";
  const nlohmann::json maps = r.value("maps", nlohmann::json());
  if (maps.is_null()) return text.str();
  text << "maps, simulated against the log over " << maps.at("settings").size()
       << " settings: Spearman, mean / max |difference|\n";
  char line[200];
  std::snprintf(line, sizeof line, "  %-17s", "");
  text << line;
  for (const auto& part : maps.at("parts")) {
    std::snprintf(line, sizeof line, " %-24s", part.at("name").get<std::string>().c_str());
    text << line;
  }
  text << "\n";
  for (const char* figure : kFigures) {
    std::snprintf(line, sizeof line, "  %-17s", figure);
    text << line;
    for (const auto& part : maps.at("parts")) {
      const auto& f = part.at("agreement").at("figures").at(figure);
      const std::string cell = Fixed(f.at("spearman"), 2) + ", " +
                               Fixed(f.at("mean_abs_difference"), 3) + " / " +
                               Fixed(f.at("max_abs_difference"), 3);
      std::snprintf(line, sizeof line, " %-24s", cell.c_str());
      text << line;
    }
    text << "\n";
  }
  text << MapsVerdict(maps) << "\n";
  return text.str();
}

std::string MapsCsv(const nlohmann::json& maps) {
  std::ostringstream csv;
  csv << "part,setting";
  for (const char* source : {"scene", "log"}) {
    for (const char* figure : kFigures) csv << "," << source << "_" << figure;
  }
  csv << "\n";
  for (const auto& part : maps.at("parts")) {
    for (const auto& row : part.at("rows")) {
      csv << '"' << part.at("name").get<std::string>() << "\",\""
          << row.at("name").get<std::string>() << '"';
      for (const char* source : {"scene", "log"}) {
        for (const char* figure : kFigures) csv << "," << row.at(source).at(figure).dump();
      }
      csv << "\n";
    }
  }
  return csv.str();
}

}  // namespace sonarbench::sim
