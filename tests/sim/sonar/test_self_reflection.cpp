#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "sim_fixtures.hpp"
#include "sonarbench/mapping/detection.hpp"
#include "sonarbench/sim/sonar/beam_synthesizer.hpp"
#include "sonarbench/sim/sonar/pulse_spreader.hpp"
#include "sonarbench/sim/sonar/range_spread.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/random.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

using mapping::kDegToRad;

// A sensor whose only return is a flat self-reflection profile, `bins` long at -21 dB: 19 dB
// above the AD window's foot, level 121.1 (quantised 121), clear of both ends by over 4σ for
// the spreads tested below (1.5 dB).
SensorModel RingingSensor(std::size_t bins) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.self_reflection.profile_db.assign(bins, -21.0);
  return sensor;
}

// Per bin of the profile, a beam's level less the profile's, in dB (AD steps of span/255).
std::vector<double> RingingDeviations(const SensorModel& sensor, const SynthesizedBeam& beam) {
  const Acoustics& a = sensor.acoustics;
  std::vector<double> out;
  for (std::size_t k = 0; k < a.self_reflection.profile_db.size(); ++k) {
    out.push_back(a.converter.low_db + beam.beam.intensities[k] * a.converter.span_db / 255.0 -
                  a.self_reflection.profile_db[k]);
  }
  return out;
}

// The self-reflection is the sonar's own: the place's speckle, on here and drawn per ping,
// changes a wall's echo from ping to ping but leaves the ringing bins at the profile's level,
// whatever the ping and head angle.
TEST(SelfReflection, SelfReflectionIsTheSonarsOwnNotThePlacesSpeckle) {
  SensorModel sensor = RingingSensor(40);
  sensor.acoustics.speckle.on = true;
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  const auto first = synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 1);
  bool wall_varies = false;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const double head = static_cast<double>(seed) * sensor.geometry.step_angle_rad;
    const auto beam = synthesizer.Synthesize(0.0, head, Eigen::Isometry3d::Identity(), seed);
    for (std::size_t k = 0; k < 40; ++k) ASSERT_EQ(beam.beam.intensities[k], 121) << "bin " << k;
    const auto ping = synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), seed);
    wall_varies |= ping.beam.intensities != first.beam.intensities;
  }
  EXPECT_TRUE(wall_varies);
}

// From ping to ping, the ringing bins' levels move by σ_p (y_k + y_k+1)/√2 dB less the
// divisor's ½ (ln 10/10) σ_p² dB, y standard normal: mean -0.26 dB and variance σ_p² (plus the
// AD step's rounding, step²/12) for σ_p = 1.5, neighbouring bins correlating by ½ and bins two
// apart not at all; the mean power stays the profile's. Past the ringing range (20 bins of 40)
// nothing moves. 2000 pings × 20 bins, fixed seeds; each check within 5 standard errors (a
// false alarm under 1e-5 each), the errors counting the neighbours' correlation (Σρ² = 1.5).
TEST(SelfReflection, SelfReflectionVariesFromPingToPingInItsRingingBins) {
  SensorModel sensor = RingingSensor(40);
  Acoustics& a = sensor.acoustics;
  a.self_reflection.ping_spread_db = 1.5;
  a.self_reflection.ringing_range_m = 20 * sensor.geometry.bin_size_m;
  const std::vector<TriangleMesh> none;
  const RayTracer tracer(none);
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  const double sigma = a.self_reflection.ping_spread_db;
  const double step = a.converter.span_db / 255.0;
  std::vector<double> d;
  std::vector<double> power;
  double lag_one = 0.0;
  double lag_two = 0.0;
  double pairs = 0.0;
  constexpr int kPings = 2000;
  for (std::uint64_t seed = 1; seed <= kPings; ++seed) {
    const auto beam = synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), seed);
    const std::vector<double> dev = RingingDeviations(sensor, beam);
    for (std::size_t k = 20; k < 40; ++k) ASSERT_EQ(beam.beam.intensities[k], 121) << "bin " << k;
    for (std::size_t k = 0; k < 20; ++k) {
      d.push_back(dev[k]);
      power.push_back(std::pow(10.0, dev[k] / 10.0));
    }
    for (std::size_t k = 0; k + 2 < 20; ++k) {
      lag_one += dev[k] * dev[k + 1];
      lag_two += dev[k] * dev[k + 2];
      pairs += 1.0;
    }
  }
  const auto n = static_cast<double>(d.size());
  const double shift = 0.5 * kNepersPerDecibel * sigma * sigma;
  const double mean = std::accumulate(d.begin(), d.end(), 0.0) / n;
  double variance = 0.0;
  for (const double x : d) variance += (x - mean) * (x - mean);
  variance /= n - 1.0;
  const double expected = sigma * sigma + step * step / 12.0;
  constexpr double kRhoSquares = 1.5;                              // 1 + 2 · (½)²
  EXPECT_NEAR(mean, -shift, 5.0 * std::sqrt(expected * 2.0 / n));  // Σρ = 2
  EXPECT_NEAR(variance, expected, 5.0 * expected * std::sqrt(2.0 * kRhoSquares / n));
  // Correlations of the centred deviations: the shift's square taken off each product's mean.
  const double rho_one = (lag_one / pairs - mean * mean) / variance;
  const double rho_two = (lag_two / pairs - mean * mean) / variance;
  EXPECT_NEAR(rho_one, 0.5, 5.0 * std::sqrt(2.0 * kRhoSquares / pairs));
  EXPECT_NEAR(rho_two, 0.0, 5.0 * std::sqrt(2.0 * kRhoSquares / pairs));
  const double mean_power = std::accumulate(power.begin(), power.end(), 0.0) / n;
  const double c = kNepersPerDecibel * sigma;  // the factor's log-sd
  const double power_sd = std::sqrt(std::exp(c * c) - 1.0);
  EXPECT_NEAR(mean_power, 1.0, 5.0 * power_sd * std::sqrt(2.0 / n));
}

// Across head angles, a turn of 200 head steps: each step's levels are the same ping after
// ping (two seeds), and move by σ_a A_jk dB less the divisor's shift, A a standard normal
// correlating by ½ between neighbouring bins and, between head steps m apart, as the kernel
// exp(-|e| Δ / θ) convolved with itself: q^m (1 + m (1 - q²)/(1 + q²)), q = exp(-Δ/θ)
// (θ = 5°, Δ = 1.8°: 0.94 at one step, 0.45 at five). 200 steps × 200 bins; the variance and the
// correlations within 5 standard errors counting the field's own correlation (Σρ² over bins and
// steps, from the same formula).
TEST(SelfReflection, SelfReflectionVariesWithHeadAngleAlikeSweepAfterSweep) {
  constexpr std::size_t kBins = 200;
  SensorModel sensor = RingingSensor(kBins);
  Acoustics& a = sensor.acoustics;
  a.self_reflection.angle_spread_db = 1.5;
  a.self_reflection.angle_correlation_deg = 5.0;
  const std::vector<TriangleMesh> none;
  const RayTracer tracer(none);
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}}, 3);
  const int turn = sensor.geometry.BeamsPerSweep();
  ASSERT_EQ(turn, 200);
  std::vector<std::vector<double>> dev;
  for (int j = 0; j < turn; ++j) {
    const double head = j * sensor.geometry.step_angle_rad;
    const auto beam = synthesizer.Synthesize(0.0, head, Eigen::Isometry3d::Identity(), 1);
    const auto again = synthesizer.Synthesize(1.0, head, Eigen::Isometry3d::Identity(), 2);
    ASSERT_EQ(beam.beam.intensities, again.beam.intensities) << "head step " << j;
    dev.push_back(RingingDeviations(sensor, beam));
  }
  const double sigma = a.self_reflection.angle_spread_db;
  const double step = a.converter.span_db / 255.0;
  const double q = std::exp(-sensor.geometry.step_angle_rad /
                            (a.self_reflection.angle_correlation_deg * kDegToRad));
  const auto r_c = [&](int m) {
    return std::pow(q, std::abs(m)) * (1.0 + std::abs(m) * (1.0 - q * q) / (1.0 + q * q));
  };
  double rho_squares = 0.0;  // over steps and the bins' lags 0 and ±1
  for (int m = -turn / 2; m < turn / 2; ++m) rho_squares += 1.5 * r_c(m) * r_c(m);
  const double n = static_cast<double>(turn) * kBins;
  double sum = 0.0;
  for (const auto& row : dev) sum += std::accumulate(row.begin(), row.end(), 0.0);
  const double mean = sum / n;
  EXPECT_NEAR(mean, -0.5 * kNepersPerDecibel * sigma * sigma,
              5.0 * sigma * std::sqrt(rho_squares / n) * 2.0);
  const auto covariance = [&](int m, std::size_t lag) {
    double total = 0.0;
    double count = 0.0;
    for (int j = 0; j < turn; ++j) {
      const auto& row = dev[static_cast<std::size_t>(j)];
      const auto& other = dev[static_cast<std::size_t>((j + m) % turn)];
      for (std::size_t k = 0; k + lag < kBins; ++k) {
        total += (row[k] - mean) * (other[k + lag] - mean);
        count += 1.0;
      }
    }
    return total / count;
  };
  const double variance = covariance(0, 0);
  const double expected = sigma * sigma + step * step / 12.0;
  const double error = std::sqrt(2.0 * rho_squares / n);
  EXPECT_NEAR(variance, expected, 5.0 * expected * error);
  EXPECT_NEAR(covariance(0, 1) / variance, 0.5, 5.0 * error);
  for (const int m : {1, 2, 5, 10}) {
    EXPECT_NEAR(covariance(m, 0) / variance, r_c(m), 5.0 * error) << "m " << m;
  }
}

}  // namespace
}  // namespace sonarbench::sim
