#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "cfar.hpp"
#include "sonarbench/mapping/detection.hpp"

namespace sonarbench::mapping {
namespace {

// Independent trials, so that the passes counted are binomial: each trial's power vector holds
// two homogeneous stretches of exponential noise, the second `step` times the first's mean, each
// as long as a bin's whole window; one bin under test in the middle of each.
constexpr int kTrials = 100000;

DetectionConfig CfarConfig(DetectionConfig::Method method, double false_alarm) {
  DetectionConfig config;
  config.method = method;
  config.cfar.guard_bins = 2;
  config.cfar.training_bins = 12;
  config.cfar.false_alarm = false_alarm;
  return config;
}

// Five standard deviations of a binomial share of `n` trials at probability `p`: a correct
// detector fails the comparison once in 1.7 million runs.
double BinomialBound(double p, int n) { return 5.0 * std::sqrt(p * (1.0 - p) / n); }

struct Passes {
  double low = 0.0;   // the share of the first stretch's bin under test that passed
  double high = 0.0;  // the same in the second, `step` times stronger, stretch
};

// The pass rate of each stretch's middle bin; that bin's power is drawn with mean `cut_mean`
// times its stretch's (1 for noise alone, 1 + SNR for a fluctuating echo).
Passes MeasurePasses(const DetectionConfig& config, double step, double cut_mean) {
  const int half = config.cfar.guard_bins + config.cfar.training_bins;
  const int stretch = 2 * half + 1;
  const CfarFactors factors(config);
  std::mt19937_64 rng(20261201);
  std::exponential_distribution<double> noise(1.0);
  std::vector<double> power(2 * static_cast<std::size_t>(stretch));
  int low = 0;
  int high = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    for (std::size_t k = 0; k < power.size(); ++k) {
      power[k] = noise(rng) * (k < static_cast<std::size_t>(stretch) ? 1.0 : step);
    }
    power[static_cast<std::size_t>(half)] *= cut_mean;
    power[static_cast<std::size_t>(stretch + half)] *= cut_mean;
    const std::vector<bool> passes = CfarPasses(power, 0, config, factors);
    low += passes[static_cast<std::size_t>(half)];
    high += passes[static_cast<std::size_t>(stretch + half)];
  }
  return {static_cast<double>(low) / kTrials, static_cast<double>(high) / kTrials};
}

TEST(Cfar, FactorsGiveTheRequestedFalseAlarmProbability) {
  for (const double pfa : {1e-2, 1e-3, 1e-6}) {
    for (const int n : {2, 8, 24}) {
      EXPECT_NEAR(std::pow(1.0 + CaCfarFactor(n, pfa) / n, -n), pfa, 1e-9 * pfa);
      for (const int k : {1, n / 2, (3 * n + 3) / 4, n}) {
        const double alpha = OsCfarFactor(n, k, pfa);
        double product = 1.0;
        for (int i = 0; i < k; ++i) product *= (n - i) / (n - i + alpha);
        EXPECT_NEAR(product, pfa, 1e-9 * pfa) << "n " << n << ", k " << k;
      }
    }
  }
}

// A fixed threshold passes a stretch ten times stronger far more often; CFAR, cell averaging and
// ordered statistic alike, holds its rate in both, within the binomial bound.
TEST(Cfar, TheFalseAlarmRateHoldsAcrossAStep) {
  for (const auto method : {DetectionConfig::Method::kCaCfar, DetectionConfig::Method::kOsCfar}) {
    for (const double pfa : {1e-2, 1e-3}) {
      const Passes measured = MeasurePasses(CfarConfig(method, pfa), 10.0, 1.0);
      EXPECT_NEAR(measured.low, pfa, BinomialBound(pfa, kTrials));
      EXPECT_NEAR(measured.high, pfa, BinomialBound(pfa, kTrials));
    }
  }
}

// A fluctuating (Swerling I) echo of signal-to-noise ratio S: its bin's power is exponential with
// mean 1 + S, and it passes with probability (1 + α / (n (1 + S)))^-n (CA) or
// Π_{i<k} (n - i) / (n - i + α / (1 + S)) (OS).
TEST(Cfar, AnEchoIsDetectedWithTheTheoreticalProbability) {
  const int n = 24;
  for (const double snr_db : {5.0, 10.0, 15.0}) {
    const double s = std::pow(10.0, snr_db / 10.0);
    const DetectionConfig ca = CfarConfig(DetectionConfig::Method::kCaCfar, 1e-3);
    const double pd_ca = std::pow(1.0 + CaCfarFactor(n, 1e-3) / (n * (1.0 + s)), -n);
    const Passes ca_measured = MeasurePasses(ca, 1.0, 1.0 + s);
    EXPECT_NEAR(ca_measured.low, pd_ca, BinomialBound(pd_ca, kTrials)) << snr_db << " dB";

    const DetectionConfig os = CfarConfig(DetectionConfig::Method::kOsCfar, 1e-3);
    const int k = CfarFactors(os).order(n);
    const double alpha = OsCfarFactor(n, k, 1e-3);
    double pd_os = 1.0;
    for (int i = 0; i < k; ++i) pd_os *= (n - i) / (n - i + alpha / (1.0 + s));
    const Passes os_measured = MeasurePasses(os, 1.0, 1.0 + s);
    EXPECT_NEAR(os_measured.low, pd_os, BinomialBound(pd_os, kTrials)) << snr_db << " dB";
  }
}

// On the Micron's 8-bit intensities: a wall's echo of five bins 160 counts (25.1 dB, 324 times the
// power) over a flat background is found at its first bin by either detector. There CA-CFAR's
// right training bins hold two of the echo's (past the guard): a background of (22 + 2 · 324) / 24
// = 27.9, times α = 8.0 (24 bins, 10^-3) = 223, under 324. The background's bins pass none.
TEST(Cfar, AWallOverAFlatBackgroundIsFoundAtItsFirstBin) {
  SensorGeometry sensor;
  Beam beam;
  beam.bin_size_m = sensor.bin_size_m;
  beam.intensities.assign(static_cast<std::size_t>(sensor.num_bins), 40);
  for (int k = 200; k < 205; ++k) beam.intensities[static_cast<std::size_t>(k)] = 200;
  for (const auto method : {DetectionConfig::Method::kCaCfar, DetectionConfig::Method::kOsCfar}) {
    DetectionConfig config = CfarConfig(method, 1e-3);
    config.max_obstacles = 3;
    const std::vector<std::vector<double>> echoes =
        DetectObstacles(std::span<const Beam>(&beam, 1), sensor, config);
    ASSERT_EQ(echoes.size(), 1U);
    ASSERT_EQ(echoes[0].size(), 1U);
    EXPECT_DOUBLE_EQ(echoes[0][0], beam.BinCentreRange(200));
  }
}

}  // namespace
}  // namespace sonarbench::mapping
