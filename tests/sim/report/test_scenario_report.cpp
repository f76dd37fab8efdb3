#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "sonarbench/base/error.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/eval/verdict.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"
#include "sonarbench/sim/world/criteria.hpp"

namespace sonarbench::sim {
namespace {

TEST(ScenarioReport, XmlEscapeLeavesNoMarkupOrForbiddenCharacter) {
  EXPECT_EQ(XmlEscape("a<b & \"c\" 'd'>"), "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;");
  EXPECT_EQ(XmlEscape(std::string("bell\x07|line\n")), "bell?|line&#10;");
}

TEST(ScenarioReport, Base64MatchesRfc4648) {
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

TEST(ScenarioReport, ErrorJunitEscapesTheMessage) {
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
