#include <algorithm>
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

// The spread's verdict in a sentence, and the runs standing in for the log.
std::string SpreadVerdict(const nlohmann::json& spread) {
  std::string text = spread.at("within").get<bool>()
                         ? "The log lies within the simulator's own spread"
                         : "The log lies outside the simulator's own spread";
  text += " (" + std::to_string(spread.at("seeds").size()) + " seeds, " +
          std::to_string(spread.at("judgements").get<std::size_t>()) + " judgements, size " +
          Fixed(spread.at("level"), 2) + " over all); ";
  const auto& size = spread.at("size");
  text += std::to_string(size.at("seeds_within").get<std::size_t>()) + " of " +
          std::to_string(size.at("seeds").get<std::size_t>()) +
          " runs, each standing in for the log against the others, are within.";
  return text;
}

// One part's spread as an SVG strip per figure at the scene's mapping: the runs (grey dots), the
// interval the verdict allows around their mean (the bar) and the log (red), each strip scaled
// to what it shows, its ends labelled.
std::string SpreadSvg(const nlohmann::json& part) {
  constexpr int kRow = 30, kLeft = 150, kWidth = 420, kRight = 70;
  std::ostringstream svg;
  const auto& figures = part.at("figures");
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kLeft + kWidth + kRight
      << "\" height=\"" << kRow * static_cast<int>(std::size(kFigures)) + 10
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  int y = 20;
  for (const char* figure : kFigures) {
    const auto& entry = figures.at(figure);
    svg << "<text x=\"0\" y=\"" << y + 4 << "\">" << figure << "</text>\n";
    if (entry.is_null()) {
      svg << "<text x=\"" << kLeft << "\" y=\"" << y + 4 << "\">not judged</text>\n";
      y += kRow;
      continue;
    }
    const auto& j = entry.at("scene_mapping");
    const double log = j.at("log").get<double>();
    const double centre = log - j.at("statistic").get<double>();
    const double bound = j.at("bound").get<double>();
    double lo = std::min(log, centre - bound), hi = std::max(log, centre + bound);
    for (const auto& run : j.at("runs")) {
      lo = std::min(lo, run.get<double>());
      hi = std::max(hi, run.get<double>());
    }
    const double pad = 0.05 * std::max(hi - lo, 1e-6);
    lo -= pad;
    hi += pad;
    const auto x = [&](double v) { return kLeft + (v - lo) / (hi - lo) * kWidth; };
    svg << "<line x1=\"" << x(centre - bound) << "\" x2=\"" << x(centre + bound) << "\" y1=\"" << y
        << "\" y2=\"" << y << "\" stroke=\"#9ab\" stroke-width=\"8\"/>\n";
    for (const auto& run : j.at("runs")) {
      svg << "<circle cx=\"" << x(run.get<double>()) << "\" cy=\"" << y
          << "\" r=\"3\" fill=\"#555\"/>\n";
    }
    svg << "<rect x=\"" << x(log) - 4 << "\" y=\"" << y - 8
        << "\" width=\"8\" height=\"16\" fill=\"" << (j.at("within").get<bool>() ? "#2a2" : "#d22")
        << "\"/>\n"
        << "<text x=\"" << kLeft << "\" y=\"" << y + 14 << "\" fill=\"#777\">" << Fixed(lo, 3)
        << "</text><text x=\"" << kLeft + kWidth << "\" y=\"" << y + 14
        << "\" fill=\"#777\" text-anchor=\"end\">" << Fixed(hi, 3) << "</text>\n"
        << "<text x=\"" << kLeft + kWidth + 8 << "\" y=\"" << y + 4 << "\">log " << Fixed(log, 3)
        << "</text>\n";
    y += kRow;
  }
  svg << "</svg>\n";
  return svg.str();
}

// One part's judgements as a table: a row per figure, at the scene's mapping and over settings.
std::string SpreadTableHtml(const nlohmann::json& part) {
  std::ostringstream html;
  html << "<table>\n<tr><th>figure</th><th>log - runs' mean</th><th>bound</th><th>within</th>"
       << "<th>mean |difference| over settings</th><th>bound</th><th>within</th></tr>\n";
  for (const char* figure : kFigures) {
    const auto& entry = part.at("figures").at(figure);
    html << "<tr><td>" << figure << "</td>";
    for (const char* kind : {"scene_mapping", "settings"}) {
      if (entry.is_null() || !entry.contains(kind)) {
        html << "<td></td><td></td><td></td>";
        continue;
      }
      const auto& j = entry.at(kind);
      html << "<td class=\"n\">" << Fixed(j.at("statistic"), 3) << "</td><td class=\"n\">"
           << Fixed(j.at("bound"), 3) << "</td><td>"
           << (j.at("within").get<bool>() ? "yes" : "no, by " + Fixed(j.at("excess"), 3))
           << "</td>";
    }
    html << "</tr>\n";
  }
  return html.str() + "</table>\n";
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
  const nlohmann::json spread = r.value("spread", nlohmann::json());
  if (!spread.is_null()) {
    html << "<p class=\"verdict " << (spread.at("within").get<bool>() ? "pass" : "fail") << "\">"
         << XmlEscape(SpreadVerdict(spread)) << "</p>\n";
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
  if (!spread.is_null()) {
    html << "<h2>The log against the simulator's own spread</h2>\n<p>Per figure at the scene's "
            "mapping: the runs (grey), the interval the verdict allows (bar) and the log (green "
            "within, red outside); docs/fidelity.md, \"The verdict\".</p>\n";
    for (const auto& part : spread.at("parts")) {
      html << "<h3>" << XmlEscape(part.at("name").get<std::string>()) << "</h3>\n"
           << SpreadSvg(part) << SpreadTableHtml(part);
    }
    if (!spread.at("missed").empty()) {
      html << "<p>Outside:</p>\n<ul>\n";
      for (const auto& line : spread.at("missed")) {
        html << "<li>" << XmlEscape(line.get<std::string>()) << "</li>\n";
      }
      html << "</ul>\n";
    }
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
  const nlohmann::json spread = r.value("spread", nlohmann::json());
  if (!spread.is_null()) {
    text << SpreadVerdict(spread) << "\n";
    for (const auto& line : spread.at("missed")) {
      text << "  outside: " << line.get<std::string>() << "\n";
    }
  }
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

std::string SpreadCsv(const nlohmann::json& spread) {
  std::ostringstream csv;
  csv << "part,figure,judgement,statistic,bound,excess,within\n";
  for (const auto& part : spread.at("parts")) {
    for (const char* figure : kFigures) {
      const auto& entry = part.at("figures").at(figure);
      if (entry.is_null()) continue;
      for (const auto& [kind, j] : entry.items()) {
        csv << part.at("name").get<std::string>() << "," << figure << "," << kind << ","
            << j.at("statistic").get<double>() << "," << j.at("bound").get<double>() << ","
            << j.at("excess").get<double>() << "," << (j.at("within").get<bool>() ? 1 : 0) << "\n";
      }
    }
  }
  return csv.str();
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
