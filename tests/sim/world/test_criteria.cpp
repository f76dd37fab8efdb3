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

std::string ParseError(const std::string& yaml) {
  try {
    (void)ParseCriteria(yaml);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Criteria, ReadsBoundsBandsAndFlags) {
  const Criteria c = ParseCriteria(
      "expect: fail\n"
      "metrics:\n"
      "  occupied_recall: {min: 0.5, acceptable_min: 0.4}\n"
      "  map_to_mesh_p95_m: {max: 0.3, optional: true}\n");
  EXPECT_TRUE(c.expect_fail);
  ASSERT_EQ(c.metrics.size(), 2u);
  EXPECT_EQ(c.metrics[0].metric, "occupied_recall");
  EXPECT_EQ(c.metrics[0].min, 0.5);
  EXPECT_EQ(c.metrics[0].acceptable_min, 0.4);
  EXPECT_FALSE(c.metrics[0].max.has_value());
  EXPECT_TRUE(c.metrics[1].optional);
  EXPECT_EQ(c.metrics[1].max, 0.3);
}

TEST(Criteria, RejectsWhatWouldMakeACriterionMeaningless) {
  EXPECT_NE(ParseError("metrics: {recal: {min: 1}}").find("key 'metrics.recal': a known metric"),
            std::string::npos);
  EXPECT_NE(ParseError("metrics: {coverage: {}}").find("a bound"), std::string::npos);
  EXPECT_NE(ParseError("metrics: {coverage: {min: 0.5, max: 0.4}}").find("max >= min"),
            std::string::npos);
  EXPECT_NE(ParseError("metrics: {coverage: {min: 0.5, acceptable_min: 0.6}}").find("wider band"),
            std::string::npos);
  EXPECT_NE(ParseError("metrics: {coverage: {max: 0.5, acceptable_min: 0.4}}")
                .find("'metrics.coverage.acceptable_min': 'min' beside it"),
            std::string::npos);
  EXPECT_NE(ParseError("metrics: {coverage: {min: 0.5, minimum: 1}}").find("unknown key"),
            std::string::npos);
  EXPECT_NE(ParseError("expect: maybe\nmetrics: {coverage: {min: 0.5}}").find("one of"),
            std::string::npos);
  EXPECT_NE(ParseError("metrics: {coverage: {min: high}}").find("got 'high'"), std::string::npos);
  // yaml-cpp would keep the last of two equal keys; the reader refuses them.
  EXPECT_NE(
      ParseError("metrics:\n  coverage: {min: 0.5}\n  coverage: {min: 0.9}\n").find("duplicate"),
      std::string::npos);
}

TEST(Criteria, MeshRecallNamesAMeshOfTheScene) {
  const Criteria c = ParseCriteria("metrics: {mesh_recall.crate: {min: 0.5}}");
  MapMetrics m;
  m.per_mesh.push_back({"tank", 10, 10, 1.0});
  m.per_mesh.push_back({"crate", 10, 4, 0.4});
  const Verdict v = Evaluate(c, m);
  EXPECT_FALSE(v.passed);
  EXPECT_DOUBLE_EQ(v.results[0].actual, 0.4);
  EXPECT_NE(ParseError("metrics: {mesh_recall.boat: {min: 0.5}}").find("(tank, crate)"),
            std::string::npos);
}

// Counts print whole (42030, not 4.203e+04); fractions and the rest to four significant digits.
TEST(Criteria, MetricValuesPrintCountsWholeAndTheRestToFourDigits) {
  EXPECT_EQ(FormatMetricValue(42030.0), "42030");
  EXPECT_EQ(FormatMetricValue(0.0), "0");
  EXPECT_EQ(FormatMetricValue(-3.0), "-3");
  EXPECT_EQ(FormatMetricValue(0.11573), "0.1157");
  EXPECT_EQ(FormatMetricValue(2.5), "2.5");
  EXPECT_EQ(FormatMetricValue(1e20), "1e+20");
  EXPECT_EQ(FormatMetricValue(std::nan("")), "nan");
}

}  // namespace
}  // namespace sonarbench::sim
