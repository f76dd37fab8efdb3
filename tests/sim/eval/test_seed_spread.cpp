#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "sonarbench/sim/eval/seed_spread.hpp"

namespace sonarbench::sim {
namespace {

TEST(StudentT, QuantilesMatchTheTables) {
  // Two-sided 5% and 1%, one-sided 5%, from the standard tables (six significant digits).
  EXPECT_NEAR(StudentTQuantile(0.975, 1), 12.7062, 1e-4);
  EXPECT_NEAR(StudentTQuantile(0.975, 2), 4.30265, 1e-5);
  EXPECT_NEAR(StudentTQuantile(0.975, 7), 2.36462, 1e-5);
  EXPECT_NEAR(StudentTQuantile(0.995, 10), 3.16927, 1e-5);
  EXPECT_NEAR(StudentTQuantile(0.95, 30), 1.69726, 1e-5);
  EXPECT_NEAR(StudentTQuantile(0.025, 7), -2.36462, 1e-5);
  EXPECT_DOUBLE_EQ(StudentTCdf(0.0, 5), 0.5);
  EXPECT_NEAR(StudentTCdf(2.36462, 7) + StudentTCdf(-2.36462, 7), 1.0, 1e-12);
}

TEST(SeedSpread, LeftOutDifferencesAreEachRunAgainstTheOthers) {
  const std::vector<double> runs = {1.0, 2.0, 3.0, 6.0};
  const SpreadJudgement j = JudgeValue(4.0, runs, 0.05);
  EXPECT_DOUBLE_EQ(j.statistic, 1.0);  // 4 - mean 3
  ASSERT_EQ(j.left_out.size(), 4u);
  EXPECT_DOUBLE_EQ(j.left_out[0], 1.0 - 11.0 / 3.0);
  EXPECT_DOUBLE_EQ(j.left_out[3], 6.0 - 2.0);
  // s = sd(1, 2, 3, 6) = sqrt(14/3); the bound t_3(0.975) · s · sqrt(5/4).
  EXPECT_NEAR(j.bound, 3.18245 * std::sqrt(14.0 / 3.0) * std::sqrt(1.25), 1e-4);
  EXPECT_TRUE(j.within);
  EXPECT_DOUBLE_EQ(j.excess, 0.0);
  const SpreadJudgement far = JudgeValue(30.0, runs, 0.05);
  EXPECT_FALSE(far.within);
  EXPECT_NEAR(far.excess, 27.0 - j.bound, 1e-12);
}

// The log drawn as one more run: JudgeValue rejects it in `level` of trials (exact for normal
// runs), within 5 binomial standard deviations; shifted by 10 sd it rejects nearly always.
TEST(SeedSpread, ValueVerdictHasItsSizeAndPower) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.4, 0.02);
  constexpr int kTrials = 20000;
  constexpr double kLevel = 0.05;
  int rejected = 0;
  int shifted_rejected = 0;
  std::vector<double> runs(8);
  for (int t = 0; t < kTrials; ++t) {
    for (double& r : runs) r = normal(rng);
    const double log = normal(rng);
    rejected += JudgeValue(log, runs, kLevel).within ? 0 : 1;
    shifted_rejected += JudgeValue(log + 0.2, runs, kLevel).within ? 0 : 1;
  }
  const double sigma = std::sqrt(kLevel * (1.0 - kLevel) / kTrials);
  EXPECT_NEAR(static_cast<double>(rejected) / kTrials, kLevel, 5.0 * sigma);
  EXPECT_GT(static_cast<double>(shifted_rejected) / kTrials, 0.99);
}

// Over settings the bound is approximate; what it must not do is flag a true simulator more often
// than asked: the rejection rate at most `level` + 5 binomial sd. Each setting has its own mean
// and spread; a log 3 sd off at every setting is rejected nearly always.
TEST(SeedSpread, SettingsVerdictIsNoStricterThanAskedAndSeesABias) {
  std::mt19937_64 rng(11);
  constexpr int kTrials = 5000;
  constexpr int kSettings = 21;
  constexpr double kLevel = 0.05;
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<double> mean(kSettings), sd(kSettings);
  for (int k = 0; k < kSettings; ++k) {
    mean[k] = 0.2 + 0.03 * k;
    sd[k] = 0.01 + 0.001 * k;
  }
  int rejected = 0;
  int biased_rejected = 0;
  std::vector<std::vector<double>> runs(8, std::vector<double>(kSettings));
  std::vector<double> log(kSettings), biased(kSettings);
  for (int t = 0; t < kTrials; ++t) {
    for (auto& run : runs) {
      for (int k = 0; k < kSettings; ++k) run[k] = mean[k] + sd[k] * unit(rng);
    }
    for (int k = 0; k < kSettings; ++k) {
      log[k] = mean[k] + sd[k] * unit(rng);
      biased[k] = log[k] + 3.0 * sd[k];
    }
    rejected += JudgeSettings(log, runs, kLevel).within ? 0 : 1;
    biased_rejected += JudgeSettings(biased, runs, kLevel).within ? 0 : 1;
  }
  const double sigma = std::sqrt(kLevel * (1.0 - kLevel) / kTrials);
  EXPECT_LE(static_cast<double>(rejected) / kTrials, kLevel + 5.0 * sigma);
  EXPECT_GT(static_cast<double>(biased_rejected) / kTrials, 0.99);
}

TEST(SeedSpread, RefusesTooFewRunsOrRaggedSettings) {
  const std::vector<double> two = {0.1, 0.2};
  EXPECT_THROW((void)JudgeValue(0.1, two, 0.05), std::invalid_argument);
  const std::vector<double> log = {0.1, 0.2};
  EXPECT_THROW((void)JudgeSettings(log, {{0.1, 0.2}, {0.1}, {0.3, 0.2}}, 0.05),
               std::invalid_argument);
  EXPECT_THROW((void)JudgeValue(0.1, std::vector<double>{0.1, 0.2, 0.3}, 1.5),
               std::invalid_argument);
}

}  // namespace
}  // namespace sonarbench::sim
