#pragma once

#include <octomap/OcTree.h>

#include <Eigen/Core>
#include <functional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/beam_cells.hpp"
#include "sonarbench/mapping/mapper_config.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/eval/verdict.hpp"
#include "sonarbench/sim/world/scene.hpp"

// The parts of report.html and junit.xml that run, map and score share.
namespace sonarbench::sim {

/// An image of a report, encoded once: written as a file and embedded in report.html.
struct ReportImage {
  std::string file;
  std::string caption;
  std::vector<unsigned char> png;
};

/// map_top.png and map_side.png: the map's `cells` (CollectMapCells of `map`) against the truth
/// (its `detector_ghosts` apart) from above, and in a slice 3 cells thick in y through
/// `side_slice_m` [m, world frame]; `name` (the scene and seed, or the map) starts their titles.
/// Both mark the sonar along `sonar_path_m` [m, world frame] (none given: at `side_slice_m`).
[[nodiscard]] std::vector<ReportImage> MapTruthImages(
    const octomap::OcTree& map, const MapCells& cells, const mapping::KeySet& truth,
    const mapping::KeySet& observable, const mapping::KeySet& detector_ghosts,
    const Eigen::Vector3d& side_slice_m, const std::string& name,
    const std::vector<Eigen::Vector3d>& sonar_path_m = {});

/// polar.png and fan.png of a sweep (report.html's "first sweep" images); `name` starts their
/// titles.
[[nodiscard]] ReportImage PolarImage(std::span<const mapping::Beam> sweep, const std::string& name);
[[nodiscard]] ReportImage FanImage(std::span<const mapping::Beam> sweep, const std::string& name);

/// Runs each of `tasks` once, on up to `threads` threads (0 = all cores), taking them in order:
/// put the longest first. Then rethrows the exception of the first task (in order) that threw.
/// The tasks must not share what they write.
void RunTasks(int threads, std::span<const std::function<void()>> tasks);

/// Writes each image into `dir` as its file, atomically.
void WriteReportImages(const std::string& dir, const std::vector<ReportImage>& images);

/// report.html's head and title, "<h1>`heading`</h1>", and, when `verdict` is set, PASS or FAIL
/// with its reasons and warnings.
[[nodiscard]] std::string HtmlPageStart(const std::string& title, const std::string& heading,
                                        const Verdict* verdict);
/// Each criterion's actual, expected, margin and status.
[[nodiscard]] std::string CriteriaHtml(const Verdict& v);
/// Every known metric with its definition, each mesh's recall, the counts.
[[nodiscard]] std::string MetricsHtml(const MapMetrics& m);
/// A table of `rows` (label, value) under `heading`; values right-aligned when `numeric`.
[[nodiscard]] std::string TableHtml(const std::string& heading,
                                    const std::vector<std::pair<std::string, std::string>>& rows,
                                    bool numeric);
/// "Mapping": every parameter of `config` (the detection's as "detection.KEY"), as report.json's
/// "mapping" names them.
[[nodiscard]] std::string MappingHtml(const mapping::MapperConfig& config);
/// The images, embedded, each with its caption; then the end of the page.
[[nodiscard]] std::string ImagesHtmlAndEnd(const std::vector<ReportImage>& images);

/// JUnit XML of a map scored against `scene`: one suite named after the scene, a first test case
/// `first_case` for the scoring itself (it fails when an `expect: fail` scene passes; `note` and
/// the expectation in its system-out), then a test case per criterion (a <failure> when a
/// required one missed its bound; optional and "acceptable" ones pass with the reason in
/// <system-out>); `properties` (name, value) in the suite's <properties>.
[[nodiscard]] std::string ScoredJunitXml(
    const Scene& scene, const std::string& first_case, const std::string& note,
    const std::vector<std::pair<std::string, std::string>>& properties, const Verdict& v,
    double seconds);

/// `seconds` with three decimals.
[[nodiscard]] std::string Seconds(double seconds);

}  // namespace sonarbench::sim
