#include "sonarbench/sim/app/map_fidelity.hpp"

#include <array>
#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

#include "sonarbench/sim/app/simulated_scene.hpp"
#include "sonarbench/sim/eval/seed_spread.hpp"
#include "sonarbench/sim/eval/verdict.hpp"

namespace sonarbench::sim {
namespace {

using nlohmann::json;

struct Part {
  const char* name;
  std::optional<std::pair<double, double>> heads_deg;
};
const Part kParts[] = {{"all head angles", std::nullopt},
                       {"head angles 0-180 deg", std::pair{0.0, 180.0}},
                       {"head angles 180-360 deg", std::pair{180.0, 360.0}}};
constexpr std::size_t kPartCount = std::size(kParts);
constexpr std::size_t kFigureCount = std::size(kAgreementFigures);

json HeadsJson(const Part& part) {
  return part.heads_deg ? json::array({part.heads_deg->first, part.heads_deg->second}) : json();
}

// The study's rows for each part, from one simulation of the scene; `done(n)` after each setting
// of each part.
std::vector<std::vector<DetectorRow>> RowsByPart(const Scene& scene, DetectorStudyOptions options,
                                                 const std::function<void()>& done) {
  std::optional<SceneWorld> own_world;
  if (!options.world) options.world = &own_world.emplace(scene);
  const SimulatedScene simulated =
      SimulateForScoring(scene, *options.world, options.seed.value_or(scene.seed), options.threads);
  options.simulated = &simulated;
  std::vector<std::vector<DetectorRow>> rows;
  for (const Part& part : kParts) {
    options.heads_deg = part.heads_deg;
    options.progress = [&](std::size_t, std::size_t) {
      if (done) done();
    };
    rows.push_back(RunDetectorStudy(scene, options));
  }
  return rows;
}

// MapFidelity's JSON from its rows (the first `settings` of each part's).
json MapsJson(const std::vector<DetectorItem>& items, std::size_t settings,
              const std::vector<std::vector<DetectorRow>>& rows_by_part, const MapGoals& goals) {
  json parts = json::array();
  bool meets = true;
  for (std::size_t p = 0; p < kPartCount; ++p) {
    const std::vector<DetectorRow> rows(rows_by_part[p].begin(),
                                        rows_by_part[p].begin() + static_cast<long>(settings));
    json table = json::array();
    for (const DetectorRow& row : rows) {
      json scene_values, log_values;
      for (const auto& [figure, metric] : kAgreementFigures) {
        scene_values[figure] = MetricValue(row.scene, metric);
        log_values[figure] = MetricValue(*row.log, metric);
      }
      table.push_back({{"name", row.item.name}, {"scene", scene_values}, {"log", log_values}});
    }
    json agreement = AgreementJson(rows, goals);
    meets = meets && agreement.value("meets", false);
    parts.push_back({{"name", kParts[p].name},
                     {"heads_deg", HeadsJson(kParts[p])},
                     {"agreement", std::move(agreement)},
                     {"rows", std::move(table)}});
  }
  json names = json::array();
  for (std::size_t k = 0; k < settings; ++k) names.push_back(items[k].name);
  return {{"settings", names}, {"parts", parts}, {"meets", meets}};
}

// A run's figures: [part][setting][figure].
using Figures = std::vector<std::vector<std::array<double, kFigureCount>>>;

Figures FiguresOf(const std::vector<std::vector<DetectorRow>>& rows_by_part, bool log) {
  Figures out(kPartCount);
  for (std::size_t p = 0; p < kPartCount; ++p) {
    for (const DetectorRow& row : rows_by_part[p]) {
      std::array<double, kFigureCount> values{};
      for (std::size_t f = 0; f < kFigureCount; ++f) {
        values[f] = MetricValue(log ? *row.log : row.scene, kAgreementFigures[f].second);
      }
      out[p].push_back(values);
    }
  }
  return out;
}

json JudgementJson(const SpreadJudgement& j) {
  return {{"statistic", j.statistic},
          {"left_out", j.left_out},
          {"bound", j.bound},
          {"within", j.within},
          {"excess", j.excess}};
}

struct Judged {
  json parts = json::array();
  bool within = true;
  std::vector<std::string> missed;
};

// One figure f of part p judged, into `out`: at the scene's mapping (the last setting) and, if
// there are others, over them. Null when the log or a run lacks it (NaN).
json JudgeFigure(const Figures& log, const std::vector<Figures>& runs, std::size_t p, std::size_t f,
                 double level_each, Judged& out) {
  const std::size_t settings = log[p].size() - 1;
  std::vector<double> at_scene;
  std::vector<std::vector<double>> by_setting;
  bool finite = true;
  for (std::size_t k = 0; k <= settings; ++k) finite = finite && std::isfinite(log[p][k][f]);
  for (const Figures& run : runs) {
    at_scene.push_back(run[p][settings][f]);
    by_setting.emplace_back();
    for (std::size_t k = 0; k <= settings; ++k) {
      finite = finite && std::isfinite(run[p][k][f]);
      if (k < settings) by_setting.back().push_back(run[p][k][f]);
    }
  }
  if (!finite) return nullptr;
  const std::string where = std::string(kAgreementFigures[f].first) + " (" + kParts[p].name + ")";
  const auto miss = [&](const SpreadJudgement& j, const std::string& what) {
    out.within = out.within && j.within;
    if (j.within) return;
    std::ostringstream text;
    text << std::fixed << std::setprecision(3) << where << what << j.statistic << ", " << j.excess
         << " beyond the bound " << j.bound;
    out.missed.push_back(text.str());
  };
  const double value = log[p][settings][f];
  const SpreadJudgement mapping = JudgeValue(value, at_scene, level_each);
  json entry = {{"scene_mapping", JudgementJson(mapping)}};
  entry["scene_mapping"]["log"] = value;
  entry["scene_mapping"]["runs"] = at_scene;
  std::ostringstream at;
  at << std::fixed << std::setprecision(3) << " at the scene's mapping: " << value
     << ", from the runs' mean ";
  miss(mapping, at.str());
  if (settings > 0) {
    std::vector<double> log_settings;
    for (std::size_t k = 0; k < settings; ++k) log_settings.push_back(log[p][k][f]);
    const SpreadJudgement over = JudgeSettings(log_settings, by_setting, level_each);
    entry["settings"] = JudgementJson(over);
    miss(over, " over " + std::to_string(settings) + " settings: mean |difference| ");
  }
  return entry;
}

// Every judgement of `log` against `runs`; the last setting is the scene's mapping, the ones
// before it the study's settings.
Judged JudgeAll(const Figures& log, const std::vector<Figures>& runs, double level_each) {
  Judged out;
  for (std::size_t p = 0; p < kPartCount; ++p) {
    json figures = json::object();
    for (std::size_t f = 0; f < kFigureCount; ++f) {
      figures[kAgreementFigures[f].first] = JudgeFigure(log, runs, p, f, level_each, out);
    }
    out.parts.push_back(
        {{"name", kParts[p].name}, {"heads_deg", HeadsJson(kParts[p])}, {"figures", figures}});
  }
  return out;
}

}  // namespace

json MapFidelity(const Scene& scene, DetectorStudyOptions options, const MapGoals& goals) {
  const std::vector<DetectorItem> items =
      options.items.empty() ? DetectorStudyItems(scene.mapping.detection) : options.items;
  options.items = items;
  const auto progress = options.progress;
  std::size_t done = 0;
  const auto rows = RowsByPart(scene, options, [&] {
    if (progress) progress(++done, kPartCount * items.size());
  });
  return MapsJson(items, items.size(), rows, goals);
}

MapSpread JudgeMapsAgainstSeeds(const Scene& scene, DetectorStudyOptions options,
                                const MapSpreadOptions& spread, const MapGoals& goals) {
  if (spread.seeds.size() < 4) {
    throw std::invalid_argument("a seed spread needs at least 4 seeds");
  }
  const std::size_t settings = options.items.size();
  std::vector<DetectorItem> items = options.items;
  items.push_back({"the scene's mapping", scene.mapping.detection});
  options.items = items;
  const auto progress = options.progress;
  const std::size_t total = kPartCount * items.size() * spread.seeds.size();
  std::size_t done = 0;
  const auto step = [&] {
    if (progress) progress(++done, total);
  };
  const std::string log = options.log;
  MapSpread out;
  Figures log_figures;
  std::vector<Figures> runs;
  for (std::size_t s = 0; s < spread.seeds.size(); ++s) {
    options.seed = spread.seeds[s];
    options.log = s == 0 ? log : std::string();  // the log is mapped once
    const auto rows = RowsByPart(scene, options, step);
    if (s == 0) {
      log_figures = FiguresOf(rows, true);
      if (settings > 0) out.maps = MapsJson(items, settings, rows, goals);
    }
    runs.push_back(FiguresOf(rows, false));
  }
  const std::size_t judgements = kPartCount * kFigureCount * (settings > 0 ? 2 : 1);
  const double level_each = spread.level / static_cast<double>(judgements);
  Judged judged = JudgeAll(log_figures, runs, level_each);
  std::size_t seeds_within = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    std::vector<Figures> others = runs;
    others.erase(others.begin() + static_cast<long>(i));
    seeds_within += JudgeAll(runs[i], others, level_each).within ? 1 : 0;
  }
  json names = json::array();
  for (std::size_t k = 0; k < settings; ++k) names.push_back(items[k].name);
  out.spread = {{"seeds", spread.seeds},
                {"level", spread.level},
                {"judgements", judgements},
                {"level_each", level_each},
                {"settings", names},
                {"parts", std::move(judged.parts)},
                {"within", judged.within},
                {"missed", judged.missed},
                {"size", {{"seeds_within", seeds_within}, {"seeds", runs.size()}}}};
  return out;
}

}  // namespace sonarbench::sim
