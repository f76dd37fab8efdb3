#pragma once

#include <optional>
#include <string>
#include <vector>

#include "sonarbench/io/yaml_reader.hpp"

namespace sonarbench::sim {

/// One pass/fail bound on a map metric, from a scene's `criteria.metrics.<name>` entry.
///
/// The metric passes when it lies within [min, max] (either may be absent). Outside that, it is
/// still *acceptable* when it lies within [acceptable_min, acceptable_max]: reported as a warning,
/// not a failure, so a criterion can carry a target and a tolerated band. An optional criterion
/// is evaluated and reported but never decides the verdict.
struct Criterion {
  std::string metric;
  std::optional<double> min;
  std::optional<double> max;
  std::optional<double> acceptable_min;
  std::optional<double> acceptable_max;
  bool optional = false;

  bool operator==(const Criterion&) const = default;
};

/// A scene's criteria. With `expect_fail`, the scenario passes only when at least one required
/// criterion fails: a suite can hold scenarios that check the criteria themselves.
struct Criteria {
  bool expect_fail = false;
  std::vector<Criterion> metrics;
};

/// The metric names a criterion may name, each with a one-line definition.
struct MetricInfo {
  const char* name;
  const char* definition;
};
[[nodiscard]] const std::vector<MetricInfo>& KnownMetrics();

/// Besides the known metrics, a criterion may name `mesh_recall.NAME`: the recall of one mesh's
/// own observable cells (MapMetrics::per_mesh), NAME one of the scene's meshes.
inline constexpr const char* kMeshRecallPrefix = "mesh_recall.";

/// Reads the `criteria` mapping of a scene (`expect: pass|fail`, `metrics: {name: bounds}`);
/// `mesh_names` are the scene's meshes. Errors are collected in `node` like every other key.
/// Over a `base` (the criteria of the scene this one extends), `metrics` is optional: given, it
/// replaces the base's metrics whole; absent, they stay, as does `expect` when absent.
[[nodiscard]] Criteria ReadCriteria(YamlReader& node, const std::vector<std::string>& mesh_names,
                                    const Criteria* base = nullptr);

/// A metric value as reports print it: a whole number whole (a count), any other to four
/// significant digits ("%.4g").
[[nodiscard]] std::string FormatMetricValue(double value);

}  // namespace sonarbench::sim
