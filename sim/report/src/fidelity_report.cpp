#include "sonarbench/sim/report/fidelity_report.hpp"

#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/sim/report/images.hpp"
#include "sonarbench/sim/report/report.hpp"
#include "sonarbench/sim/world/criteria.hpp"

namespace sonarbench::sim {
namespace {

nlohmann::json HeadAngleJson(const FidelityReport::HeadAngleCells& cells) {
  return {{"mean", cells.mean},
          {"ping_spread", cells.ping_spread},
          {"angle_spread", cells.angle_spread},
          {"angle_correlation_1_and_5_steps", cells.angle_correlation}};
}

void WriteText(const std::string& path, const std::string& text) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

// Two images side by side (the right one scaled to the left one's size).
cv::Mat SideBySide(const cv::Mat& left, const cv::Mat& right) {
  cv::Mat right_sized;
  cv::resize(right, right_sized, left.size(), 0, 0, cv::INTER_NEAREST);
  cv::Mat joined;
  cv::hconcat(left, right_sized, joined);
  return joined;
}

// A value per range band of each run (the mean profiles', the sweep spreads'), for fidelity.json:
// one object per band, null where a run's bins do not reach it.
nlohmann::json RangeBandsJson(const FidelityReport::RangeBands& sim,
                              const FidelityReport::RangeBands& real) {
  nlohmann::json bands = nlohmann::json::array();
  const auto value = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  for (std::size_t b = 0; b < FidelityReport::kRangeBandsM.size(); ++b) {
    bands.push_back({{"from_m", FidelityReport::kRangeBandsM[b][0]},
                     {"to_m", FidelityReport::kRangeBandsM[b][1]},
                     {"sim", value(sim[b])},
                     {"real", value(real[b])}});
  }
  return bands;
}

}  // namespace

nlohmann::json FidelityJson(const FidelityReport& r, const std::string& scene_file,
                            const std::string& log_file) {
  nlohmann::json report = ReportHeader();
  report.update({{"scene", scene_file},
                 {"log", log_file},
                 {"profile_correlation_all_bins", r.profile_correlation_all},
                 {"profile_correlation_usable_bins", r.profile_correlation_usable},
                 {"profile_mean_abs_difference_usable_bins", r.profile_mean_abs_difference},
                 {"mean_by_range_band", RangeBandsJson(r.sim.band_means, r.real.band_means)},
                 {"median_wall_range_difference_bins", r.median_wall_difference_bins},
                 {"wall_angles_compared", r.wall_angles_compared},
                 {"wall_peak_intensity_p10_p50_p90_sim", r.sim.wall_peak},
                 {"wall_tail_mean_abs_difference", r.wall_tail_mean_abs_difference},
                 {"behind_walls_square_corners_sim", r.sim.behind_walls},
                 {"behind_walls_square_by_side_sim", r.sim.behind_walls_by_side},
                 {"behind_walls_square_by_side_real", r.real.behind_walls_by_side},
                 {"behind_walls_square_corners_real", r.real.behind_walls},
                 {"wall_peak_intensity_p10_p50_p90_real", r.real.wall_peak},
                 {"wall_front_mean_abs_difference", r.wall_front_mean_abs_difference},
                 {"direct_wall_beams_sim", r.sim.direct_wall_beams},
                 {"direct_wall_beams_real", r.real.direct_wall_beams},
                 {"second_trip_excess_sim", r.sim.second_trip_excess},
                 {"second_trip_excess_real", r.real.second_trip_excess},
                 {"second_trip_beams_sim", r.sim.second_trip_beams},
                 {"second_trip_beams_real", r.real.second_trip_beams},
                 {"second_trip_mean_abs_difference", r.second_trip_mean_abs_difference},
                 {"histogram_intersection", r.histogram_intersection},
                 {"values_held_sim", r.sim.values},
                 {"values_held_real", r.real.values},
                 {"values_held_sim_not_real", r.sim_values_not_real},
                 {"range_correlation_by_lag_sim", r.sim.range_correlation},
                 {"range_correlation_by_lag_real", r.real.range_correlation},
                 {"beam_correlation_by_step_sim", r.sim.beam_correlation},
                 {"beam_correlation_by_step_real", r.real.beam_correlation},
                 {"local_range_correlation_by_lag_sim", r.sim.local_range_correlation},
                 {"local_range_correlation_by_lag_real", r.real.local_range_correlation},
                 {"local_beam_correlation_by_step_sim", r.sim.local_beam_correlation},
                 {"local_beam_correlation_by_step_real", r.real.local_beam_correlation},
                 {"local_contrast_sim", r.sim.local_contrast},
                 {"local_contrast_real", r.real.local_contrast},
                 {"self_reflection",
                  {{"bins", {r.real.ringing.first_bin, r.real.ringing.last_bin}},
                   {"sim", HeadAngleJson(r.sim.ringing)},
                   {"real", HeadAngleJson(r.real.ringing)}}},
                 {"near_range",
                  {{"bins", {r.real.near_range.first_bin, r.real.near_range.last_bin}},
                   {"sim", HeadAngleJson(r.sim.near_range)},
                   {"real", HeadAngleJson(r.real.near_range)}}},
                 {"sweep_spread_sim", r.sim.sweep_spread},
                 {"sweep_spread_real", r.real.sweep_spread},
                 {"sweep_spread_by_range_band",
                  RangeBandsJson(r.sim.sweep_spread_by_band, r.real.sweep_spread_by_band)},
                 {"outputs",
                  {"profile.csv", "profile.png", "wall_range.csv", "wall_profile.csv",
                   "direct_wall_profile.csv", "second_trip_profile.csv", "histogram.csv",
                   "by_head_angle.csv", "polar.png", "fan.png"}}});
  return report;
}

namespace {

// A value of fidelity.json as the summary prints it: numbers to four significant digits, a
// list as "a / b / c", a missing value as "none".
std::string SummaryValue(const nlohmann::json& value) {
  if (value.is_null()) return "none";
  if (value.is_number()) return FormatMetricValue(value.get<double>());
  if (value.is_array()) {
    std::string text;
    const char* separator = value.size() > 0 && value[0].is_object() ? "; " : " / ";
    for (const auto& item : value) text += (text.empty() ? "" : separator) + SummaryValue(item);
    return text;
  }
  if (value.is_object() && value.contains("from_m") && value.contains("to_m")) {
    return SummaryValue(value["from_m"]) + "-" + SummaryValue(value["to_m"]) + " m: sim " +
           SummaryValue(value.value("sim", nlohmann::json())) + ", real " +
           SummaryValue(value.value("real", nlohmann::json()));
  }
  if (value.is_object()) {
    std::string text;
    for (const auto& [key, item] : value.items()) {
      text += (text.empty() ? "" : ", ") + key + " " + SummaryValue(item);
    }
    return "{" + text + "}";
  }
  return value.dump();
}

}  // namespace

std::string FidelitySummary(const nlohmann::json& report) {
  std::string text;
  for (const auto& [key, value] : report.items()) {
    if (key == "schema_version" || key == "tool" || key == "scene" || key == "log" ||
        key == "outputs" || key == "spread") {
      continue;
    }
    if (value.is_object()) {
      for (const auto& [part, item] : value.items()) {
        text += key + "." + part + ": " + SummaryValue(item) + "\n";
      }
    } else {
      text += key + ": " + SummaryValue(value) + "\n";
    }
  }
  return text;
}

namespace {

// The CSV files of WriteFidelityOutputs into `dir`.
void WriteFidelityCsvs(const std::filesystem::path& dir, const FidelityReport& r,
                       const mapping::SensorGeometry& sensor) {
  std::ostringstream profile;
  profile << "bin,range_m,sim_mean,real_mean\n";
  for (std::size_t k = 0; k < r.sim.mean.size(); ++k) {
    profile << k << "," << (k + 0.5) * sensor.bin_size_m << "," << r.sim.mean[k] << ","
            << r.real.mean[k] << "\n";
  }
  WriteText((dir / "profile.csv").string(), profile.str());
  std::ostringstream walls;
  walls << "head_angle_deg,sim_wall_m,real_wall_m,sim_wall_intensity,real_wall_intensity\n";
  const auto field = [](const std::optional<double>& v) {
    return v ? std::to_string(*v) : std::string();
  };
  for (std::size_t a = 0; a < r.sim.wall_m.size(); ++a) {
    walls << a * sensor.step_angle_rad * 180.0 / std::numbers::pi << "," << field(r.sim.wall_m[a])
          << "," << field(r.real.wall_m[a]) << "," << field(r.sim.wall_peak_by_angle[a]) << ","
          << field(r.real.wall_peak_by_angle[a]) << "\n";
  }
  WriteText((dir / "wall_range.csv").string(), walls.str());
  std::ostringstream angles;
  angles << "head_angle_deg,sim_self_reflection,real_self_reflection,sim_near_range,"
            "real_near_range\n";
  const auto at = [](const FidelityReport::HeadAngleCells& cells, std::size_t a) {
    return a < cells.by_head_angle.size() ? cells.by_head_angle[a] : std::nullopt;
  };
  for (std::size_t a = 0; a < static_cast<std::size_t>(sensor.BeamsPerSweep()); ++a) {
    angles << a * sensor.step_angle_rad * 180.0 / std::numbers::pi << ","
           << field(at(r.sim.ringing, a)) << "," << field(at(r.real.ringing, a)) << ","
           << field(at(r.sim.near_range, a)) << "," << field(at(r.real.near_range, a)) << "\n";
  }
  WriteText((dir / "by_head_angle.csv").string(), angles.str());
  // An aligned profile, entry i at offset i - before.
  const auto write_aligned = [&](const char* name, const std::vector<double>& sim,
                                 const std::vector<double>& real, long before) {
    std::ostringstream csv;
    csv << "offset_bins,sim_mean,real_mean\n";
    for (std::size_t i = 0; i < sim.size(); ++i) {
      csv << static_cast<long>(i) - before << "," << sim[i] << "," << real[i] << "\n";
    }
    WriteText((dir / name).string(), csv.str());
  };
  write_aligned("wall_profile.csv", r.sim.wall_profile, r.real.wall_profile,
                FidelityReport::kWallProfileBefore);
  write_aligned("direct_wall_profile.csv", r.sim.direct_wall_profile, r.real.direct_wall_profile,
                FidelityReport::kWallProfileBefore);
  write_aligned("second_trip_profile.csv", r.sim.second_trip_profile, r.real.second_trip_profile,
                FidelityReport::kSecondTripReach);
  std::ostringstream hist;
  hist << "intensity,sim_fraction,real_fraction\n";
  for (std::size_t v = 0; v < 256; ++v) {
    hist << v << "," << r.sim.histogram[v] << "," << r.real.histogram[v] << "\n";
  }
  WriteText((dir / "histogram.csv").string(), hist.str());
}

}  // namespace

void WriteFidelityOutputs(const std::string& out_dir, const FidelityReport& r,
                          std::span<const mapping::Beam> sim_sweep,
                          std::span<const mapping::Beam> real_sweep,
                          const mapping::SensorGeometry& sensor, const std::string& scene_file,
                          const std::string& log_file, const nlohmann::json& maps,
                          const nlohmann::json& spread) {
  namespace fs = std::filesystem;
  CreateOutputDirectory(out_dir);
  const fs::path dir(out_dir);
  WriteFidelityCsvs(dir, r, sensor);

  // The two mean profiles against range: sim orange, real black.
  PlotSeries real_profile{"real log", cv::Scalar(0, 0, 0), {}, r.real.mean};
  PlotSeries sim_profile{"simulated", cv::Scalar(0, 140, 255), {}, r.sim.mean};
  for (std::size_t k = 0; k < r.sim.mean.size(); ++k) {
    real_profile.x.push_back((static_cast<double>(k) + 0.5) * sensor.bin_size_m);
  }
  sim_profile.x = real_profile.x;
  WritePng((dir / "profile.png").string(),
           RenderLinePlot("Mean intensity against range", "range [m]", "mean intensity",
                          {real_profile, sim_profile}, false, 0.0));

  WritePng((dir / "polar.png").string(),
           SideBySide(RenderPolarImage(sim_sweep, "simulated: " + scene_file + ", first sweep"),
                      RenderPolarImage(real_sweep, "real: " + log_file + ", first sweep")));
  WritePng((dir / "fan.png").string(),
           SideBySide(RenderFanImage(sim_sweep, 0.01, "simulated: " + scene_file + ", first sweep"),
                      RenderFanImage(real_sweep, 0.01, "real: " + log_file + ", first sweep")));

  nlohmann::json report = FidelityJson(r, scene_file, log_file);
  if (!maps.is_null()) {
    report["maps"] = maps;
    report["outputs"].push_back("maps.csv");
    WriteText((dir / "maps.csv").string(), MapsCsv(maps));
  }
  if (!spread.is_null()) {
    report["spread"] = spread;
    report["outputs"].push_back("spread.csv");
    WriteText((dir / "spread.csv").string(), SpreadCsv(spread));
  }
  report["outputs"].push_back("report.html");
  WriteText((dir / "report.html").string(), FidelityHtml(report));
  WriteJson((dir / "fidelity.json").string(), report);
}

}  // namespace sonarbench::sim
