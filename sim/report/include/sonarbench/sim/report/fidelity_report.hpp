#pragma once

#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"
#include "sonarbench/sim/eval/fidelity.hpp"

namespace sonarbench::sim {

/// Writes fidelity.json, profile.csv, wall_range.csv, wall_profile.csv,
/// direct_wall_profile.csv, second_trip_profile.csv, histogram.csv, by_head_angle.csv (the
/// self-reflection's and the near range's mean per head angle: where a vehicle's parts echo),
/// profile.png (the two mean profiles), and polar and fan images of each run's first sweep side
/// by side (sim left, real right) into `out_dir`.
/// The files WriteFidelityOutputs writes, relative to its `out_dir`.
inline const std::vector<std::string> kFidelityOutputFiles = {"fidelity.json",
                                                              "profile.csv",
                                                              "profile.png",
                                                              "wall_range.csv",
                                                              "wall_profile.csv",
                                                              "direct_wall_profile.csv",
                                                              "second_trip_profile.csv",
                                                              "histogram.csv",
                                                              "by_head_angle.csv",
                                                              "polar.png",
                                                              "fan.png",
                                                              "maps.csv",
                                                              "spread.csv",
                                                              "report.html"};

/// fidelity.json's content: the report's header, the scene and log, and every statistic.
[[nodiscard]] nlohmann::json FidelityJson(const FidelityReport& report,
                                          const std::string& scene_file,
                                          const std::string& log_file);

/// That content as text, a line per statistic ("key: value"), for the terminal.
[[nodiscard]] std::string FidelitySummary(const nlohmann::json& report);

/// report.html from fidelity.json's content: the maps' verdict first (when it holds "maps"),
/// then the beams' key statistics, the maps' agreement per part, the images.
[[nodiscard]] std::string FidelityHtml(const nlohmann::json& report);
/// The terminal's summary of fidelity.json's content: the beams' key statistics, the maps'
/// agreement per part and the verdict, a dozen lines.
[[nodiscard]] std::string FidelityBrief(const nlohmann::json& report);
/// maps.csv from fidelity.json's "maps": a row per part and setting, scene and log columns.
[[nodiscard]] std::string MapsCsv(const nlohmann::json& maps);
/// spread.csv from fidelity.json's "spread": a row per part, figure and judgement.
[[nodiscard]] std::string SpreadCsv(const nlohmann::json& spread);

/// With `maps` (fidelity.json's "maps", null for none), also "maps" in fidelity.json and
/// maps.csv; with `spread` (the verdict against the seeds' spread), "spread" and spread.csv;
/// report.html always.
void WriteFidelityOutputs(const std::string& out_dir, const FidelityReport& report,
                          std::span<const mapping::Beam> sim_sweep,
                          std::span<const mapping::Beam> real_sweep,
                          const mapping::SensorGeometry& sensor, const std::string& scene_file,
                          const std::string& log_file, const nlohmann::json& maps = nullptr,
                          const nlohmann::json& spread = nullptr);

}  // namespace sonarbench::sim
