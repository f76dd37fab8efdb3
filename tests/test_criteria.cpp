#include <gtest/gtest.h>

#include <cmath>

#include "sonarbench/mapping/error.hpp"
#include "sonarbench/sim/criteria.hpp"
#include "sonarbench/sim/scenario_report.hpp"
#include "sonarbench/sim/score.hpp"

namespace sonarbench::sim {
namespace {

Criteria Parse(const std::string& yaml) {
  YamlReader reader = YamlReader::FromString(yaml, "scene.yaml");
  Criteria criteria = ReadCriteria(reader, {"tank", "crate"});
  reader.ThrowIfErrors();
  return criteria;
}

std::string ParseError(const std::string& yaml) {
  try {
    (void)Parse(yaml);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

MapMetrics Metrics(double recall, double precision) {
  MapMetrics m;
  m.occupied_recall = recall;
  m.occupied_precision = precision;
  return m;
}

TEST(Criteria, ReadsBoundsBandsAndFlags) {
  const Criteria c = Parse(
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

TEST(Criteria, StatusAndMarginFollowTheBounds) {
  const Criteria c = Parse(
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

TEST(Criteria, OptionalFailuresWarnAndExpectFailInverts) {
  const Criteria optional = Parse("metrics: {occupied_recall: {min: 0.5, optional: true}}");
  const Verdict v = Evaluate(optional, Metrics(0.1, 0));
  EXPECT_TRUE(v.passed);
  EXPECT_EQ(v.warnings.size(), 1u);

  const Criteria must_fail = Parse("expect: fail\nmetrics: {occupied_recall: {min: 0.5}}");
  EXPECT_TRUE(Evaluate(must_fail, Metrics(0.1, 0)).passed);
  const Verdict unexpected = Evaluate(must_fail, Metrics(0.9, 0));
  EXPECT_FALSE(unexpected.passed);
  ASSERT_EQ(unexpected.reasons.size(), 1u);
  EXPECT_NE(unexpected.reasons[0].find("expect: fail"), std::string::npos);
  // An optional criterion alone cannot satisfy an expected failure.
  const Criteria only_optional =
      Parse("expect: fail\nmetrics: {occupied_recall: {min: 0.5, optional: true}}");
  EXPECT_FALSE(Evaluate(only_optional, Metrics(0.1, 0)).passed);
}

TEST(Criteria, MeshRecallNamesAMeshOfTheScene) {
  const Criteria c = Parse("metrics: {mesh_recall.crate: {min: 0.5}}");
  MapMetrics m;
  m.per_mesh.push_back({"tank", 10, 10, 1.0});
  m.per_mesh.push_back({"crate", 10, 4, 0.4});
  const Verdict v = Evaluate(c, m);
  EXPECT_FALSE(v.passed);
  EXPECT_DOUBLE_EQ(v.results[0].actual, 0.4);
  EXPECT_NE(ParseError("metrics: {mesh_recall.boat: {min: 0.5}}").find("(tank, crate)"),
            std::string::npos);
}

TEST(Criteria, EveryKnownMetricReadsItsField) {
  MapMetrics m;
  m.map_to_mesh.p95_m = 0.25;
  m.occupied_cells = 42;
  double p95 = -1, cells = -1;
  for (const MetricInfo& info : KnownMetrics()) {
    if (std::string(info.name) == "map_to_mesh_p95_m") p95 = info.value(m);
    if (std::string(info.name) == "occupied_cells") cells = info.value(m);
  }
  EXPECT_EQ(p95, 0.25);
  EXPECT_EQ(cells, 42.0);
}

TEST(Reports, XmlEscapeLeavesNoMarkupOrForbiddenCharacter) {
  EXPECT_EQ(XmlEscape("a<b & \"c\" 'd'>"), "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;");
  EXPECT_EQ(XmlEscape(std::string("bell\x07|line\n")), "bell?|line&#10;");
}

TEST(Reports, Base64MatchesRfc4648) {
  auto encode = [](const std::string& s) {
    return Base64(std::vector<unsigned char>(s.begin(), s.end()));
  };
  EXPECT_EQ(encode(""), "");
  EXPECT_EQ(encode("f"), "Zg==");
  EXPECT_EQ(encode("fo"), "Zm8=");
  EXPECT_EQ(encode("foo"), "Zm9v");
  EXPECT_EQ(encode("foob"), "Zm9vYg==");
  EXPECT_EQ(encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64({0xff, 0xfe, 0x00}), "//4A");
}

TEST(Reports, ErrorJunitEscapesTheMessage) {
  const std::string xml = ErrorJunitXml("tank<1>", "input_error", "key 'a' & \"b\"");
  EXPECT_NE(xml.find("name=\"tank&lt;1&gt;\""), std::string::npos) << xml;
  EXPECT_NE(
      xml.find("<error type=\"input_error\" message=\"key &apos;a&apos; &amp; &quot;b&quot;\""),
      std::string::npos)
      << xml;
  EXPECT_NE(xml.find("errors=\"1\""), std::string::npos);
}

}  // namespace
}  // namespace sonarbench::sim
