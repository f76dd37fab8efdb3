#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "sonarbench/sim/eval/scenario_result.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// Version of report.json's layout; raised whenever a field changes meaning or goes away.
inline constexpr int kScenarioReportSchema = 2;

/// A map's scores as report.json holds them (its "metrics"): precision, recall, F1, coverage,
/// free accuracy, per mesh, surface distances and the counts behind each.
[[nodiscard]] nlohmann::json MetricsJson(const MapMetrics& m);

/// A mapper's settings as report.json holds them ("mapping"): every MapperConfig field, by its
/// YAML name.
[[nodiscard]] nlohmann::json MapperConfigJson(const mapping::MapperConfig& c);

/// report.json's "scene": its name, file, the file it extends and its sensor model's file.
[[nodiscard]] nlohmann::json SceneJson(const Scene& scene);

/// report.json's "verdict" (passed, reasons, warnings) and "criteria" (each criterion's bounds,
/// actual, expected, margin and status) of a map scored against a scene's criteria.
[[nodiscard]] nlohmann::json VerdictJson(const Verdict& v);
[[nodiscard]] nlohmann::json CriteriaJson(const Verdict& v);

/// report.json of a run: scene, parameters, metrics with their counts, each criterion's actual,
/// expected and margin, the verdict, mapping totals and stage timings.
[[nodiscard]] nlohmann::json ScenarioReportJson(const Scene& scene, const ScenarioResult& result);

/// Where the sonar was on the scene's true path [m], world frame, every tenth of its first
/// `beams` beams: what the map views mark.
[[nodiscard]] std::vector<Eigen::Vector3d> SonarPath(const Scene& scene, std::size_t beams);

/// JUnit XML for a run that broke before it produced a result: one test case with an <error>
/// (type "input_error" for bad input, "internal_error" for a bug or the environment).
[[nodiscard]] std::string ErrorJunitXml(std::string_view scenario, std::string_view error_type,
                                        std::string_view message);

/// The files WriteScenarioOutputs writes (and an error junit.xml), relative to its `out_dir`.
inline const std::vector<std::string> kScenarioOutputFiles = {
    "map.bt",       "polar.png",   "fan.png",   "map_top.png",
    "map_side.png", "report.json", "junit.xml", "report.html"};

/// Writes, each file atomically, into `out_dir` (created if needed): map.bt, polar.png (the first
/// sweep), fan.png, map_top.png and map_side.png (map against truth), junit.xml, report.html
/// (self-contained: the images are embedded) and, last, report.json with the sha256 of the others
/// (files_sha256).
void WriteScenarioOutputs(const std::string& out_dir, const Scene& scene,
                          const ScenarioResult& result);

/// `text` with &, <, >, " and ' escaped and characters XML 1.0 forbids replaced by '?'.
[[nodiscard]] std::string XmlEscape(std::string_view text);
/// Standard base64 (RFC 4648) with padding.
[[nodiscard]] std::string Base64(const std::vector<unsigned char>& bytes);

}  // namespace sonarbench::sim
