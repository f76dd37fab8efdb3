#include "sonarbench/sim/criteria.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sonarbench/sim/score.hpp"

namespace sonarbench::sim {
namespace {

double Count(std::size_t n) { return static_cast<double>(n); }

std::string ExpectedText(const Criterion& c) {
  std::string text;
  if (c.min && c.max) {
    text = "in [" + FormatMetricValue(*c.min) + ", " + FormatMetricValue(*c.max) + "]";
  } else if (c.min) {
    text = ">= " + FormatMetricValue(*c.min);
  } else {
    text = "<= " + FormatMetricValue(*c.max);
  }
  if (c.acceptable_min || c.acceptable_max) {
    text += " (acceptable " +
            (c.acceptable_min && c.acceptable_max
                 ? "in [" + FormatMetricValue(*c.acceptable_min) + ", " +
                       FormatMetricValue(*c.acceptable_max) + "]"
             : c.acceptable_min ? ">= " + FormatMetricValue(*c.acceptable_min)
                                : "<= " + FormatMetricValue(*c.acceptable_max)) +
            ")";
  }
  return text;
}

bool Within(double value, const std::optional<double>& lo, const std::optional<double>& hi) {
  return (!lo || value >= *lo) && (!hi || value <= *hi);
}

}  // namespace

std::string FormatMetricValue(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", value);
  return text;
}

const std::vector<MetricInfo>& KnownMetrics() {
  static const std::vector<MetricInfo> metrics = {
      {"occupied_precision", "occupied cells on a mesh surface / occupied cells",
       [](const MapMetrics& m) { return m.occupied_precision; }},
      {"occupied_recall", "observable surface cells mapped occupied / observable surface cells",
       [](const MapMetrics& m) { return m.occupied_recall; }},
      {"occupied_f1", "harmonic mean of occupied precision and recall",
       [](const MapMetrics& m) { return m.occupied_f1; }},
      {"coverage", "observable surface cells the map knows (occupied or free) / observable",
       [](const MapMetrics& m) { return m.coverage; }},
      {"coverage_absolute", "surface cells the map knows / all surface cells",
       [](const MapMetrics& m) { return m.coverage_absolute; }},
      {"free_accuracy", "1 - free cells on a surface / free cells",
       [](const MapMetrics& m) { return m.free_accuracy; }},
      {"map_to_mesh_mean_m", "mean distance from occupied cell centres to the mesh [m]",
       [](const MapMetrics& m) { return m.map_to_mesh.mean_m; }},
      {"map_to_mesh_p95_m", "95th percentile of that distance [m]",
       [](const MapMetrics& m) { return m.map_to_mesh.p95_m; }},
      {"map_to_mesh_max_m", "largest such distance (one-sided Hausdorff) [m]",
       [](const MapMetrics& m) { return m.map_to_mesh.max_m; }},
      {"mesh_to_map_mean_m", "mean distance from observable surface cells to the map [m]",
       [](const MapMetrics& m) { return m.mesh_to_map.mean_m; }},
      {"mesh_to_map_p95_m", "95th percentile of that distance [m]",
       [](const MapMetrics& m) { return m.mesh_to_map.p95_m; }},
      {"mesh_to_map_max_m", "largest such distance [m]",
       [](const MapMetrics& m) { return m.mesh_to_map.max_m; }},
      {"occupied_cells", "cells the map holds occupied",
       [](const MapMetrics& m) { return Count(m.occupied_cells); }},
      {"true_positive_cells", "occupied cells on a mesh surface",
       [](const MapMetrics& m) { return Count(m.true_positive_cells); }},
      {"free_on_surface_cells", "free cells on a mesh surface",
       [](const MapMetrics& m) { return Count(m.free_on_surface_cells); }},
  };
  return metrics;
}

const char* StatusName(CriterionStatus status) {
  switch (status) {
    case CriterionStatus::kPass:
      return "pass";
    case CriterionStatus::kAcceptable:
      return "acceptable";
    case CriterionStatus::kFail:
      return "fail";
  }
  return "?";
}

double MetricValue(const MapMetrics& metrics, const std::string& name) {
  for (const MetricInfo& m : KnownMetrics()) {
    if (name == m.name) return m.value(metrics);
  }
  if (name.starts_with(kMeshRecallPrefix)) {
    const std::string mesh = name.substr(std::string(kMeshRecallPrefix).size());
    for (const auto& r : metrics.per_mesh) {
      if (r.name == mesh) return r.recall;
    }
  }
  return NAN;
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

Verdict Evaluate(const Criteria& criteria, const MapMetrics& metrics) {
  Verdict verdict;
  verdict.expect_fail = criteria.expect_fail;
  bool any_required_failed = false;
  for (const Criterion& c : criteria.metrics) {
    CriterionResult r;
    r.criterion = c;
    r.expected = ExpectedText(c);
    r.actual = MetricValue(metrics, c.metric);
    double margin = INFINITY;
    if (c.min) margin = std::min(margin, r.actual - *c.min);
    if (c.max) margin = std::min(margin, *c.max - r.actual);
    r.margin = margin;
    if (std::isnan(r.actual)) {
      r.status = CriterionStatus::kFail;
    } else if (Within(r.actual, c.min, c.max)) {
      r.status = CriterionStatus::kPass;
    } else if ((c.acceptable_min || c.acceptable_max) &&
               Within(r.actual, c.acceptable_min ? c.acceptable_min : c.min,
                      c.acceptable_max ? c.acceptable_max : c.max)) {
      r.status = CriterionStatus::kAcceptable;
    } else {
      r.status = CriterionStatus::kFail;
    }
    if (r.status == CriterionStatus::kFail && !c.optional) {
      any_required_failed = true;
      if (!criteria.expect_fail) verdict.reasons.push_back(Describe(r));
    } else if (r.status != CriterionStatus::kPass) {
      verdict.warnings.push_back(Describe(r) + (c.optional ? " (optional)" : ""));
    }
    verdict.results.push_back(r);
  }
  if (criteria.expect_fail) {
    verdict.passed = any_required_failed;
    if (!verdict.passed) {
      verdict.reasons.push_back(
          "expected at least one required criterion to fail (expect: fail), but all passed");
    }
  } else {
    verdict.passed = !any_required_failed;
  }
  return verdict;
}

std::string Describe(const CriterionResult& r) {
  return r.criterion.metric + " = " + FormatMetricValue(r.actual) + ", expected " + r.expected +
         ", margin " + FormatMetricValue(r.margin) + " (" + StatusName(r.status) + ")";
}

}  // namespace sonarbench::sim
