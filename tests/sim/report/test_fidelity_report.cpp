#include <gtest/gtest.h>

#include <string>

#include "sonarbench/sim/report/fidelity_report.hpp"

namespace sonarbench::sim {
namespace {

// The terminal's summary is fidelity.json's content, a line per statistic: what the file says,
// the terminal says, and nothing of the header or the file list.
TEST(FidelityReport, SummaryIsTheJsonALinePerStatistic) {
  FidelityReport report;
  report.profile_correlation_all = 0.95462;
  report.sim.band_means[0] = 5.5;
  report.real.ringing.mean = 97.07;
  const nlohmann::json json = FidelityJson(report, "scene.yaml", "log.mat");
  const std::string summary = FidelitySummary(json);
  EXPECT_NE(summary.find("profile_correlation_all_bins: 0.9546\n"), std::string::npos) << summary;
  EXPECT_NE(summary.find("mean_by_range_band: 0.4-1.5 m: sim 5.5, real none; 1.5-2 m: sim none"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("self_reflection.real: {"), std::string::npos) << summary;
  EXPECT_NE(summary.find("mean 97.07"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("tool"), std::string::npos);
  EXPECT_EQ(summary.find("outputs"), std::string::npos);
  std::size_t lines = 0;
  for (const char c : summary) lines += c == '\n' ? 1 : 0;
  std::size_t statistics = 0;
  for (const auto& [key, value] : json.items()) {
    if (key == "schema_version" || key == "tool" || key == "scene" || key == "log" ||
        key == "outputs") {
      continue;
    }
    statistics += value.is_object() ? value.size() : 1;
  }
  EXPECT_EQ(lines, statistics);
}

}  // namespace
}  // namespace sonarbench::sim
