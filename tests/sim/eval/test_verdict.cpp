#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "sim_fixtures.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/eval/verdict.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"
#include "sonarbench/sim/world/criteria.hpp"

namespace sonarbench::sim {
namespace {

MapMetrics Metrics(double recall, double precision) {
  MapMetrics m;
  m.occupied_recall = recall;
  m.occupied_precision = precision;
  return m;
}

TEST(Verdict, StatusAndMarginFollowTheBounds) {
  const Criteria c = ParseCriteria(
      "metrics:\n"
      "  occupied_recall: {min: 0.5, acceptable_min: 0.4}\n"
      "  occupied_precision: {min: 0.2, max: 0.6}\n");
  const Verdict pass = Evaluate(c, Metrics(0.55, 0.5));
  EXPECT_TRUE(pass.passed);
  EXPECT_EQ(pass.results[0].status, CriterionStatus::kPass);
  EXPECT_NEAR(pass.results[0].margin, 0.05, 1e-12);
  EXPECT_NEAR(pass.results[1].margin, 0.1, 1e-12);  // the nearer of the two bounds

  const Verdict band = Evaluate(c, Metrics(0.45, 0.5));
  EXPECT_TRUE(band.passed);
  EXPECT_EQ(band.results[0].status, CriterionStatus::kAcceptable);
  EXPECT_NEAR(band.results[0].margin, -0.05, 1e-12);
  EXPECT_EQ(band.warnings.size(), 1u);

  const Verdict fail = Evaluate(c, Metrics(0.35, 0.7));
  EXPECT_FALSE(fail.passed);
  EXPECT_EQ(fail.results[0].status, CriterionStatus::kFail);
  EXPECT_EQ(fail.results[1].status, CriterionStatus::kFail);
  ASSERT_EQ(fail.reasons.size(), 2u);
  EXPECT_NE(fail.reasons[0].find("occupied_recall = 0.35, expected >= 0.5"), std::string::npos)
      << fail.reasons[0];

  MapMetrics undefined = Metrics(NAN, 0.5);
  EXPECT_FALSE(Evaluate(c, undefined).passed);  // a NaN never passes
}

// A map without free cells (a mapper that exports occupied cells only) cannot be judged on
// free_accuracy: not applicable, said so, never deciding; with free cells it decides as before.
TEST(Verdict, FreeAccuracyOfAMapWithoutFreeCellsIsNotApplicable) {
  const Criteria c = ParseCriteria(
      "metrics:\n"
      "  occupied_recall: {min: 0.5}\n"
      "  free_accuracy: {min: 0.9}\n");
  MapMetrics occupied_only = Metrics(0.6, 0.9);
  occupied_only.free_accuracy = NAN;
  occupied_only.free_cells = 0;
  const Verdict v = Evaluate(c, occupied_only);
  EXPECT_TRUE(v.passed);
  EXPECT_EQ(v.results[1].status, CriterionStatus::kNotApplicable);
  ASSERT_EQ(v.warnings.size(), 1u);
  EXPECT_NE(v.warnings[0].find("free_accuracy: not applicable (the map holds no free cells)"),
            std::string::npos);
  MapMetrics with_free = occupied_only;
  with_free.free_cells = 10;
  with_free.free_accuracy = 0.5;
  const Verdict judged = Evaluate(c, with_free);
  EXPECT_FALSE(judged.passed);
  EXPECT_EQ(judged.results[1].status, CriterionStatus::kFail);
}

TEST(Verdict, OptionalFailuresWarnAndExpectFailInverts) {
  const Criteria optional = ParseCriteria("metrics: {occupied_recall: {min: 0.5, optional: true}}");
  const Verdict v = Evaluate(optional, Metrics(0.1, 0));
  EXPECT_TRUE(v.passed);
  EXPECT_EQ(v.warnings.size(), 1u);

  const Criteria must_fail = ParseCriteria("expect: fail\nmetrics: {occupied_recall: {min: 0.5}}");
  EXPECT_TRUE(Evaluate(must_fail, Metrics(0.1, 0)).passed);
  const Verdict unexpected = Evaluate(must_fail, Metrics(0.9, 0));
  EXPECT_FALSE(unexpected.passed);
  ASSERT_EQ(unexpected.reasons.size(), 1u);
  EXPECT_NE(unexpected.reasons[0].find("expect: fail"), std::string::npos);
  // An optional criterion alone cannot satisfy an expected failure.
  const Criteria only_optional =
      ParseCriteria("expect: fail\nmetrics: {occupied_recall: {min: 0.5, optional: true}}");
  EXPECT_FALSE(Evaluate(only_optional, Metrics(0.1, 0)).passed);
}

TEST(Verdict, EveryKnownMetricReadsItsOwnField) {
  MapMetrics m;
  double* fields[] = {
      &m.occupied_precision,  &m.occupied_recall,     &m.occupied_f1,        &m.coverage,
      &m.coverage_absolute,   &m.free_accuracy,       &m.map_to_mesh.mean_m, &m.map_to_mesh.p95_m,
      &m.map_to_mesh.max_m,   &m.mesh_to_map.mean_m,  &m.mesh_to_map.p95_m,  &m.mesh_to_map.max_m,
      &m.precision_within[1], &m.precision_within[2], &m.recall_within[1],   &m.recall_within[2],
      &m.f1_within[1],        &m.f1_within[2],        &m.ghost_share,        &m.column_precision,
      &m.column_recall};
  double next = 1.0;
  for (double* field : fields) *field = next++;
  m.occupied_cells = 100;
  m.true_positive_cells = 101;
  m.free_on_surface_cells = 102;
  m.ghost_arc_share = 103.0;
  m.ghost_echo_share = 104.0;
  std::set<double> values;
  for (const MetricInfo& info : KnownMetrics()) {
    const double value = MetricValue(m, info.name);
    EXPECT_FALSE(std::isnan(value)) << info.name;
    values.insert(value);
  }
  EXPECT_EQ(values.size(), KnownMetrics().size());  // no two metrics read one field
  EXPECT_EQ(MetricValue(m, "map_to_mesh_p95_m"), 8.0);
  EXPECT_EQ(MetricValue(m, "occupied_cells"), 100.0);
  EXPECT_EQ(MetricValue(m, "ghost_share"), 19.0);
  EXPECT_TRUE(std::isnan(MetricValue(m, "no_such_metric")));
  // Without the beams' direct echoes the ghosts are not split: a criterion on the split fails.
  m.ghost_arc_share.reset();
  EXPECT_TRUE(std::isnan(MetricValue(m, "ghost_arc_share")));
}

}  // namespace
}  // namespace sonarbench::sim
