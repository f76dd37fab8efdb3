#include "sonarbench/sim/world/criteria.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sonarbench::sim {

std::string FormatMetricValue(double value) {
  char text[32];
  const bool whole = std::isfinite(value) && value == std::floor(value) && std::abs(value) < 1e15;
  std::snprintf(text, sizeof text, whole ? "%.0f" : "%.4g", value);
  return text;
}

const std::vector<MetricInfo>& KnownMetrics() {
  static const std::vector<MetricInfo> metrics = {
      {"occupied_precision", "occupied cells on a mesh surface / occupied cells"},
      {"occupied_recall", "observable surface cells mapped occupied / observable surface cells"},
      {"occupied_f1", "harmonic mean of occupied precision and recall"},
      {"occupied_precision_within_1", "occupied cells within 1 cell of a surface / occupied cells"},
      {"occupied_precision_within_2",
       "occupied cells within 2 cells of a surface / occupied cells"},
      {"occupied_recall_within_1",
       "observable surface cells with an occupied cell within 1 cell / observable surface cells"},
      {"occupied_recall_within_2",
       "observable surface cells with an occupied cell within 2 cells / observable surface cells"},
      {"occupied_f1_within_1", "harmonic mean of precision and recall within 1 cell"},
      {"occupied_f1_within_2", "harmonic mean of precision and recall within 2 cells"},
      {"ghost_share", "occupied cells more than 2 cells from every surface / occupied cells"},
      {"ghost_arc_share", "ghosts on the arc of an echo a surface returns directly / occupied"},
      {"ghost_echo_share", "ghosts where no surface answers directly in their beams / occupied"},
      {"column_precision",
       "(x, y) columns with an occupied cell that hold a surface / columns with an occupied cell"},
      {"column_recall",
       "columns of observable surface cells that hold an occupied cell / those columns"},
      {"coverage", "observable surface cells the map knows (occupied or free) / observable"},
      {"coverage_absolute", "surface cells the map knows / all surface cells"},
      {"free_accuracy", "1 - free cells on a surface / free cells"},
      {"map_to_mesh_mean_m", "mean distance from occupied cell centres to the mesh [m]"},
      {"map_to_mesh_p95_m", "95th percentile of that distance [m]"},
      {"map_to_mesh_max_m", "largest such distance (one-sided Hausdorff) [m]"},
      {"mesh_to_map_mean_m", "mean distance from observable surface cells to the map [m]"},
      {"mesh_to_map_p95_m", "95th percentile of that distance [m]"},
      {"mesh_to_map_max_m", "largest such distance [m]"},
      {"occupied_cells", "cells the map holds occupied"},
      {"true_positive_cells", "occupied cells on a mesh surface"},
      {"free_on_surface_cells", "free cells on a mesh surface"},
  };
  return metrics;
}

Criteria ReadCriteria(YamlReader& node, const std::vector<std::string>& mesh_names,
                      const Criteria* base) {
  Criteria criteria = base ? *base : Criteria{};
  std::string expect = criteria.expect_fail ? "fail" : "pass";
  node.Optional("expect", expect, OneOf({"pass", "fail"}));
  criteria.expect_fail = expect == "fail";
  if (base && !node.Has("metrics")) {
    node.RejectUnknownKeys();
    return criteria;
  }
  criteria.metrics.clear();
  YamlReader metrics = node.Child("metrics");
  for (const std::string& name : metrics.Keys()) {
    YamlReader entry = metrics.Child(name);
    Criterion c;
    c.metric = name;
    const auto& known = KnownMetrics();
    const bool is_known = std::any_of(known.begin(), known.end(),
                                      [&](const MetricInfo& m) { return name == m.name; });
    const bool is_mesh_recall =
        name.starts_with(kMeshRecallPrefix) &&
        std::find(mesh_names.begin(), mesh_names.end(),
                  name.substr(std::string(kMeshRecallPrefix).size())) != mesh_names.end();
    if (!is_known && !is_mesh_recall) {
      std::string names;
      for (const MetricInfo& m : known) names += (names.empty() ? "" : ", ") + std::string(m.name);
      std::string meshes;
      for (const auto& m : mesh_names) meshes += (meshes.empty() ? "" : ", ") + m;
      metrics.Fail(name, "a known metric (" + names +
                             ") or mesh_recall.MESH for a mesh of the "
                             "scene (" +
                             meshes + ")");
      continue;
    }
    auto read_bound = [&](const char* key, std::optional<double>& out) {
      if (!entry.Has(key)) return;
      double value = 0.0;
      entry.Required(key, value);
      out = value;
    };
    read_bound("min", c.min);
    read_bound("max", c.max);
    read_bound("acceptable_min", c.acceptable_min);
    read_bound("acceptable_max", c.acceptable_max);
    entry.Optional("optional", c.optional);
    entry.RejectUnknownKeys();
    if (!c.min && !c.max) entry.Fail("", "a bound: 'min', 'max' or both");
    if (c.min && c.max && *c.min > *c.max) entry.Fail("max", "max >= min");
    if (c.acceptable_min && !c.min) entry.Fail("acceptable_min", "'min' beside it");
    if (c.acceptable_max && !c.max) entry.Fail("acceptable_max", "'max' beside it");
    if (c.acceptable_min && c.min && *c.acceptable_min > *c.min)
      entry.Fail("acceptable_min",
                 "a value <= min (" + FormatMetricValue(*c.min) + "), a wider band");
    if (c.acceptable_max && c.max && *c.acceptable_max < *c.max)
      entry.Fail("acceptable_max",
                 "a value >= max (" + FormatMetricValue(*c.max) + "), a wider band");
    criteria.metrics.push_back(c);
  }
  metrics.RejectUnknownKeys();
  node.RejectUnknownKeys();
  return criteria;
}

}  // namespace sonarbench::sim
