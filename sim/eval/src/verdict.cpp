#include "sonarbench/sim/eval/verdict.hpp"

#include <algorithm>
#include <cmath>

namespace sonarbench::sim {
namespace {

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

const char* StatusName(CriterionStatus status) {
  switch (status) {
    case CriterionStatus::kPass:
      return "pass";
    case CriterionStatus::kAcceptable:
      return "acceptable";
    case CriterionStatus::kFail:
      return "fail";
    case CriterionStatus::kNotApplicable:
      return "not_applicable";
  }
  return "?";
}

double MetricValue(const MapMetrics& metrics, const std::string& name) {
  if (name == "occupied_precision") return metrics.occupied_precision;
  if (name == "occupied_recall") return metrics.occupied_recall;
  if (name == "occupied_f1") return metrics.occupied_f1;
  if (name == "occupied_precision_within_1") return metrics.precision_within[1];
  if (name == "occupied_precision_within_2") return metrics.precision_within[2];
  if (name == "occupied_recall_within_1") return metrics.recall_within[1];
  if (name == "occupied_recall_within_2") return metrics.recall_within[2];
  if (name == "occupied_f1_within_1") return metrics.f1_within[1];
  if (name == "occupied_f1_within_2") return metrics.f1_within[2];
  if (name == "ghost_share") return metrics.ghost_share;
  if (name == "ghost_arc_share") return metrics.ghost_arc_share.value_or(NAN);
  if (name == "ghost_echo_share") return metrics.ghost_echo_share.value_or(NAN);
  if (name == "column_precision") return metrics.column_precision;
  if (name == "column_recall") return metrics.column_recall;
  if (name == "coverage") return metrics.coverage;
  if (name == "coverage_absolute") return metrics.coverage_absolute;
  if (name == "free_accuracy") return metrics.free_accuracy;
  if (name == "map_to_mesh_mean_m") return metrics.map_to_mesh.mean_m;
  if (name == "map_to_mesh_p95_m") return metrics.map_to_mesh.p95_m;
  if (name == "map_to_mesh_max_m") return metrics.map_to_mesh.max_m;
  if (name == "mesh_to_map_mean_m") return metrics.mesh_to_map.mean_m;
  if (name == "mesh_to_map_p95_m") return metrics.mesh_to_map.p95_m;
  if (name == "mesh_to_map_max_m") return metrics.mesh_to_map.max_m;
  if (name == "occupied_cells") return static_cast<double>(metrics.occupied_cells);
  if (name == "true_positive_cells") return static_cast<double>(metrics.true_positive_cells);
  if (name == "free_on_surface_cells") return static_cast<double>(metrics.free_on_surface_cells);
  if (name.starts_with(kMeshRecallPrefix)) {
    const std::string mesh = name.substr(std::string(kMeshRecallPrefix).size());
    for (const auto& r : metrics.per_mesh) {
      if (r.name == mesh) return r.recall;
    }
  }
  return NAN;
}

namespace {

// Whether the map can be judged on `metric`: free_accuracy needs free cells.
bool Applies(const MapMetrics& metrics, const std::string& metric) {
  return metric != "free_accuracy" || metrics.free_cells > 0;
}

std::string NotApplicableWhy(const std::string& metric) {
  return metric == "free_accuracy" ? "the map holds no free cells" : "";
}

}  // namespace

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
    if (!Applies(metrics, c.metric)) {
      r.status = CriterionStatus::kNotApplicable;
      r.margin = NAN;
      verdict.warnings.push_back(c.metric + ": not applicable (" + NotApplicableWhy(c.metric) +
                                 "); it does not decide the verdict");
      verdict.results.push_back(r);
      continue;
    }
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
