#pragma once

#include <string>
#include <vector>

#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/world/criteria.hpp"

namespace sonarbench::sim {

/// The value of a criterion's metric, NaN when the metrics do not hold it.
[[nodiscard]] double MetricValue(const MapMetrics& metrics, const std::string& name);

/// kNotApplicable: the map cannot be judged on the metric (free_accuracy of a map without free
/// cells, as mappers that export occupied cells only write): reported, never deciding.
enum class CriterionStatus { kPass, kAcceptable, kFail, kNotApplicable };
[[nodiscard]] const char* StatusName(CriterionStatus status);

struct CriterionResult {
  Criterion criterion;
  double actual = 0.0;
  /// Distance from the success bound, positive inside: actual - min or max - actual (the smaller
  /// when both are set). Negative means the metric missed its bound by that much.
  double margin = 0.0;
  CriterionStatus status = CriterionStatus::kPass;
  /// "0.42 >= 0.45"-style text of the bound, for reports.
  std::string expected;
};

/// The outcome of a scenario against its criteria.
struct Verdict {
  bool passed = true;
  bool expect_fail = false;
  std::vector<CriterionResult> results;
  /// Why the scenario failed (empty when it passed), one line per reason.
  std::vector<std::string> reasons;
  /// Optional criteria that failed and criteria that were only acceptable, one line each.
  std::vector<std::string> warnings;
};

[[nodiscard]] Verdict Evaluate(const Criteria& criteria, const MapMetrics& metrics);

/// "metric = actual, expected ..., margin ..." for terminal output and reports.
[[nodiscard]] std::string Describe(const CriterionResult& result);

}  // namespace sonarbench::sim
