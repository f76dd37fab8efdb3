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

// The receiver's level jitter alone (level_jitter_db σ = 2 dB, 12.75 AD steps, so that the
// levels' rounding is small beside it): with the echoes frozen by the place (speckle off, the
// rays' jitter the place's) and no noise, pings differ by the jitter alone. Per ping, each
// bright bin's level less the exact level of its noise-free echo, 10 log10 P [dB], and the
// products of the deviations of bright bins 1 and 2 apart.
struct LevelJitterDeviations {
  std::vector<double> deviations;
  std::array<double, 3> lag_products{};  // by lag in bins; [0] unused
  std::array<double, 3> lag_pairs{};
  /// σ² v + s²/12: v the tabled quantiles' variance, s the AD step (the rounding's share).
  double expected_variance = 0.0;
  /// σ² v: the jitter's own share.
  double jitter_variance = 0.0;
};

LevelJitterDeviations MeasureLevelJitter(double bin_correlation) {
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  Material wall;
  wall.reflectivity = 0.5;
  SensorModel sensor = QuietSensor();
  sensor.acoustics.speckle.correlation_m = 0.05;
  sensor.acoustics.noise.level_jitter_db = 2.0;
  sensor.acoustics.noise.level_jitter_bin_correlation = bin_correlation;
  const Acoustics& a = sensor.acoustics;
  const double sigma = a.noise.level_jitter_db;
  const double step = a.converter.span_db / 255.0;
  const BeamSynthesizer synthesizer(sensor, tracer, {wall}, 7);
  const auto reference = synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 0);
  // Bins whose exact level lies 4σ inside the AD window: no clipping at 0 or 255.
  std::vector<std::size_t> bright;
  std::vector<double> exact_db;
  for (std::size_t k = 0; k < reference.echo_power.size(); ++k) {
    const double p = reference.echo_power[k];
    if (p <= 0.0) continue;
    const double db = 10.0 * std::log10(p);
    if (db < a.converter.low_db + 4.0 * sigma ||
        db > a.converter.low_db + a.converter.span_db - 4.0 * sigma)
      continue;
    bright.push_back(k);
    exact_db.push_back(db);
  }
  EXPECT_GE(bright.size(), 4u);
  LevelJitterDeviations out;
  constexpr std::uint64_t kPings = 4000;
  for (std::uint64_t seed = 1; seed <= kPings; ++seed) {
    const auto beam = synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), seed);
    EXPECT_EQ(beam.echo_power, reference.echo_power);  // the echoes are the place's
    const std::size_t first = out.deviations.size();
    for (std::size_t i = 0; i < bright.size(); ++i) {
      const double level = a.converter.low_db + beam.beam.intensities[bright[i]] * step;
      out.deviations.push_back(level - exact_db[i]);
      for (std::size_t lag = 1; lag <= 2 && lag <= i; ++lag) {
        if (bright[i] != bright[i - lag] + lag) continue;
        out.lag_products[lag] += out.deviations.back() * out.deviations[first + i - lag];
        out.lag_pairs[lag] += 1.0;
      }
    }
  }
  double table_variance = 0.0;
  for (int i = 0; i < Receiver::kLevelJitters; ++i) {
    const double z = NormalQuantile((i + 0.5) / Receiver::kLevelJitters);
    table_variance += z * z / Receiver::kLevelJitters;
  }
  out.jitter_variance = sigma * sigma * table_variance;
  out.expected_variance = out.jitter_variance + step * step / 12.0;
  EXPECT_EQ(synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 3).beam.intensities,
            synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 3).beam.intensities);
  return out;
}

// The synthesis quantises powers without a logarithm and takes range losses from a table:
// the same AD step as the dB formula for powers across and beyond the AD window (away from
// the steps' edges, where the two roundings may differ by one ulp), and the loss within its
// stated 1e-4 of the exact one, for the default sensor and for one whose spreading exceeds its
// TVG by 20 dB per decade (the table's steepest case).
TEST(Receiver, QuantisedPowersAndTabledLossesMatchTheirFormulas) {
  std::vector<TriangleMesh> meshes = Wall(1.0, 0.0);
  const RayTracer tracer(meshes);
  SensorModel sensor;
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  const Acoustics& a = sensor.acoustics;
  int compared = 0;
  for (double db = a.converter.low_db - 20.0; db <= a.converter.low_db + a.converter.span_db + 20.0;
       db += 0.0137) {
    const double steps = (db - a.converter.low_db) / a.converter.span_db * 255.0;
    if (std::abs(steps - std::round(steps - 0.5) - 0.5) < 1e-9) continue;  // on an edge
    ASSERT_EQ(synthesizer.receiver().QuantisePower(std::pow(10.0, db / 10.0)),
              synthesizer.receiver().Quantise(db))
        << db << " dB";
    ++compared;
  }
  EXPECT_GT(compared, 5000);
  EXPECT_EQ(synthesizer.receiver().QuantisePower(0.0), 0);
  // AD windows of other spans: the table's buckets narrow with the step, the result stays exact.
  for (const double span : {3.0, 120.0}) {
    SensorModel other = sensor;
    other.acoustics.converter.span_db = span;
    const BeamSynthesizer s(other, tracer, {Material{}});
    for (double db = a.converter.low_db - 5.0; db <= a.converter.low_db + span + 5.0;
         db += span / 2917.0) {
      const double steps = (db - a.converter.low_db) / span * 255.0;
      if (std::abs(steps - std::round(steps - 0.5) - 0.5) < 1e-9) continue;
      ASSERT_EQ(s.receiver().QuantisePower(std::pow(10.0, db / 10.0)), s.receiver().Quantise(db))
          << db << " dB, span " << span;
    }
  }
  for (const double spreading : {a.gain.spreading_db_per_decade, a.gain.tvg_db_per_decade + 20.0}) {
    SensorModel steep = sensor;
    steep.acoustics.gain.spreading_db_per_decade = spreading;
    const BeamSynthesizer s(steep, tracer, {Material{}});
    const double bin = steep.geometry.bin_size_m;
    for (double r = 0.5 * bin; r <= steep.geometry.MaxRangeM() + 2 * bin; r += 0.0173 * bin) {
      const double exact = s.receiver().RangeLoss(r);
      ASSERT_NEAR(s.receiver().RangeLossFromTable(r), exact, 1e-4 * exact)
          << r << " m, S " << spreading;
    }
  }
}

// Independent bin by bin (level_jitter_bin_correlation 0), the deviations:
//  - are normal with mean 0 and the expected variance: mean within 5 standard errors, variance
//    within 5 of its own (σ² √(2/n)), a false alarm under 1e-5 each;
//  - KS against the normal at a 0.1% false-alarm rate (1.949/√n), plus the rounding's most
//    (half a step moves the distribution by at most φ(0) s / 2σ) and the table's 1/4096;
//  - neighbouring bins' deviations are uncorrelated (within 5/√n);
// and the same seed gives the same beam.
TEST(Receiver, LevelJitterIsTheReceiversPerBinAndPerPing) {
  const LevelJitterDeviations m = MeasureLevelJitter(0.0);
  const double expected = m.expected_variance;
  const auto n = static_cast<double>(m.deviations.size());
  const double mean = std::accumulate(m.deviations.begin(), m.deviations.end(), 0.0) / n;
  double variance = 0.0;
  for (double d : m.deviations) variance += (d - mean) * (d - mean);
  variance /= n - 1.0;
  EXPECT_NEAR(mean, 0.0, 5.0 * std::sqrt(expected / n));
  EXPECT_NEAR(variance, expected, 5.0 * expected * std::sqrt(2.0 / n));
  const double sigma = std::sqrt(m.jitter_variance);
  const double step = QuietSensor().acoustics.converter.span_db / 255.0;
  const double rounding = 0.5 * step / sigma / std::sqrt(2.0 * std::numbers::pi);
  std::vector<double> z;
  for (double d : m.deviations) z.push_back(d / sigma);
  EXPECT_LT(KsDistance(z, [](double x) { return 0.5 * std::erfc(-x / std::numbers::sqrt2); }),
            1.949 / std::sqrt(n) + rounding + 1.0 / Receiver::kLevelJitters);
  ASSERT_GT(m.lag_pairs[1], 1000.0);
  EXPECT_NEAR(m.lag_products[1] / m.lag_pairs[1] / expected, 0.0, 5.0 / std::sqrt(m.lag_pairs[1]));
}

// With level_jitter_bin_correlation ρ (0.4 here) each bin's draw is a z_k + b z_k+1 with
// a² + b² = 1 and a b = ρ: its variance is unchanged (within 5 of its standard errors), the
// deviations of neighbouring bins covary by ρ σ² v (v the table's variance), so correlate by
// ρ σ² v / (σ² v + s²/12), and bins two apart do not correlate; each within 5/√pairs (the
// sample correlation's standard error is at most 1/√pairs), a false alarm under 1e-6 each. A
// draw shared whole (a = b) would correlate by 0.5, one not shared by 0: both fail.
TEST(Receiver, LevelJitterCorrelatesNeighbouringBinsAsConfigured) {
  constexpr double kRho = 0.4;
  const LevelJitterDeviations m = MeasureLevelJitter(kRho);
  const double expected = m.expected_variance;
  const auto n = static_cast<double>(m.deviations.size());
  double variance = 0.0;
  for (double d : m.deviations) variance += d * d;
  variance /= n;
  EXPECT_NEAR(variance, expected, 5.0 * expected * std::sqrt(2.0 / n));
  ASSERT_GT(m.lag_pairs[2], 1000.0);
  EXPECT_NEAR(m.lag_products[1] / m.lag_pairs[1] / expected, kRho * m.jitter_variance / expected,
              5.0 / std::sqrt(m.lag_pairs[1]));
  EXPECT_NEAR(m.lag_products[2] / m.lag_pairs[2] / expected, 0.0, 5.0 / std::sqrt(m.lag_pairs[2]));
}

TEST(Receiver, NoiseFloorMatchesItsConfiguredDistribution) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.noise.level_db = -43.0;
  const Acoustics& a = sensor.acoustics;
  const std::vector<TriangleMesh> meshes = Wall(100.0, 0.0);  // out of range: no echo
  const RayTracer tracer(meshes);
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  // Byte 0 means a level under ad_low + half a step (rounding).
  const double floor_power =
      std::pow(10.0, (a.converter.low_db + 0.5 * a.converter.span_db / 255.0) / 10.0);
  const double p = 1.0 - std::exp(-floor_power / std::pow(10.0, a.noise.level_db / 10.0));
  double zeros = 0.0;
  double n = 0.0;
  for (std::uint64_t b = 0; b < 200; ++b) {
    const auto beam = synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), b);
    for (const auto v : beam.beam.intensities) {
      zeros += v == 0 ? 1.0 : 0.0;
      n += 1.0;
    }
  }
  EXPECT_NEAR(zeros, n * p, 3.29 * std::sqrt(n * p * (1.0 - p)));
}

// Noise entering before the time-varied gain (noise_before_tvg_db P) rises with range as the
// gain does, r^(G/10) with the Micron's G = 20 dB per decade, on top of the output's own
// (noise_level_db N): bin k's power is exponential with mean N + P r_k² (r_k its centre), so it
// reads 0 with probability p_k = 1 - exp(-A / (N + P r_k²)). Over 400 beams the zeros of each
// band are a sum of binomials: within 3.29 standard deviations of Σ n p_k (0.1% false alarms,
// two-sided). With N = -46 dB and P = -50 dB, p is 0.94-0.79 over bins 80-159 (1-2 m) and
// 0.42-0.31 over bins 320-398 (4-5 m); P growing as r instead of r² fails it (checked). And -100
// dB is none: the beams are those without the key, byte for byte.
TEST(Receiver, NoiseBeforeTheGainRisesWithRangeAsTheGainDoes) {
  SensorModel sensor = QuietSensor();
  Acoustics& a = sensor.acoustics;
  a.noise.level_db = -46.0;
  const std::vector<TriangleMesh> meshes = Wall(100.0, 0.0);  // out of range: no echo
  const RayTracer tracer(meshes);
  const BeamSynthesizer output_only(sensor, tracer, {Material{}});
  a.noise.before_tvg_db = -100.0;
  const BeamSynthesizer none(sensor, tracer, {Material{}});
  a.noise.before_tvg_db = -50.0;
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  const double floor_power =
      std::pow(10.0, (a.converter.low_db + 0.5 * a.converter.span_db / 255.0) / 10.0);
  const double n_power = std::pow(10.0, a.noise.level_db / 10.0);
  const double p_power = std::pow(10.0, a.noise.before_tvg_db / 10.0);
  constexpr int kBeams = 400;
  const std::array<std::array<std::size_t, 2>, 2> bands = {{{80, 160}, {320, 399}}};
  std::array<double, 2> zeros{};
  for (std::uint64_t b = 0; b < kBeams; ++b) {
    const auto beam = synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), b);
    for (std::size_t i = 0; i < 2; ++i) {
      for (std::size_t k = bands[i][0]; k < bands[i][1]; ++k) {
        zeros[i] += beam.beam.intensities[k] == 0 ? 1.0 : 0.0;
      }
    }
    if (b < 3) {
      EXPECT_EQ(
          none.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), b).beam.intensities,
          output_only.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), b).beam.intensities);
    }
  }
  for (std::size_t i = 0; i < 2; ++i) {
    double mean = 0.0;
    double variance = 0.0;
    for (std::size_t k = bands[i][0]; k < bands[i][1]; ++k) {
      const double r = (static_cast<double>(k) + 0.5) * sensor.geometry.bin_size_m;
      const double p = 1.0 - std::exp(-floor_power / (n_power + p_power * r * r));
      mean += kBeams * p;
      variance += kBeams * p * (1.0 - p);
    }
    EXPECT_NEAR(zeros[i], mean, 3.29 * std::sqrt(variance)) << "bins from " << bands[i][0];
  }
}

// The receiver's blanking (blanking_range_m 0.025 with bins of 0.012531 m): bins 0 and 1 begin
// within it and read 0, bin 2 (from 0.0251 m) does not; under noise that lights every bin (0 dB,
// the AD window's top) the blanked beam is the plain one with those two bins zeroed, since the
// draws are the same.
TEST(Receiver, BlankingZeroesTheBinsThatBeginWithinIt) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.noise.level_db = 0.0;
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const BeamSynthesizer plain(sensor, tracer, {Material{}});
  sensor.acoustics.noise.blanking_range_m = 0.025;
  const BeamSynthesizer blanked(sensor, tracer, {Material{}});
  const auto lit = plain.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 9).beam.intensities;
  auto expected = lit;
  expected[0] = 0;
  expected[1] = 0;
  ASSERT_GT(lit[0], 0);
  ASSERT_GT(lit[1], 0);
  ASSERT_GT(lit[2], 0);
  EXPECT_EQ(blanked.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 9).beam.intensities,
            expected);
}

TEST(Receiver, QuantisationFollowsTheAdWindow) {
  const SensorModel sensor = QuietSensor();
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  const Acoustics& a = sensor.acoustics;
  EXPECT_EQ(synthesizer.receiver().Quantise(a.converter.low_db - 1.0), 0);
  EXPECT_EQ(synthesizer.receiver().Quantise(a.converter.low_db), 0);
  EXPECT_EQ(synthesizer.receiver().Quantise(a.converter.low_db + a.converter.span_db / 2),
            128);  // 127.5 rounds up
  EXPECT_EQ(synthesizer.receiver().Quantise(a.converter.low_db + a.converter.span_db), 255);
  EXPECT_EQ(synthesizer.receiver().Quantise(a.converter.low_db + 2 * a.converter.span_db), 255);
}

// The receiver's ceiling: below its knee the AD window alone; above it the output
// knee + w·tanh((x - knee) / w) (w = ceiling - knee) of the window's step x, rounded, so a level
// x = knee + w·atanh((y - knee) / w) reports y; rising with the level and never past the
// ceiling, however strong the echo; the table-driven QuantisePower agreeing with it off the
// steps' edges; and with knee = ceiling, a hard clip.
TEST(Receiver, ReceiverCeilingCompressesAboveItsKneeAndNeverPassesIt) {
  SensorModel sensor = QuietSensor();
  Acoustics& a = sensor.acoustics;
  a.converter.knee = 170.0;
  a.converter.ceiling = 191.0;
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const BeamSynthesizer ceiling(sensor, tracer, {Material{}});
  const BeamSynthesizer plain(QuietSensor(), tracer, {Material{}});
  const auto level = [&](double steps) {
    return a.converter.low_db + steps / 255.0 * a.converter.span_db;
  };
  for (double x = 0.0; x < 169.5; x += 0.25) {
    ASSERT_EQ(ceiling.receiver().Quantise(level(x)), plain.receiver().Quantise(level(x))) << x;
  }
  const double w = a.converter.ceiling - a.converter.knee;
  for (const int y : {171, 175, 180, 185, 190}) {
    EXPECT_EQ(ceiling.receiver().Quantise(
                  level(a.converter.knee + w * std::atanh((y - a.converter.knee) / w))),
              y);
  }
  EXPECT_EQ(ceiling.receiver().Quantise(level(255.0)), 191);
  EXPECT_EQ(ceiling.receiver().Quantise(level(2000.0)), 191);  // 314 dB over the window's foot
  int previous = 0;
  int compared = 0;
  for (double x = -10.0; x < 600.0; x += 0.0137) {
    const int q = ceiling.receiver().Quantise(level(x));
    ASSERT_GE(q, previous) << x;
    ASSERT_LE(q, 191) << x;
    previous = q;
    const double y =
        x <= a.converter.knee ? x : a.converter.knee + w * std::tanh((x - a.converter.knee) / w);
    if (std::abs(y - std::round(y - 0.5) - 0.5) < 1e-9) continue;  // on an edge
    ASSERT_EQ(ceiling.receiver().QuantisePower(std::pow(10.0, level(x) / 10.0)), q) << x;
    ++compared;
  }
  EXPECT_EQ(previous, 191);
  EXPECT_GT(compared, 40000);

  a.converter.knee = 191.0;
  const BeamSynthesizer clip(sensor, tracer, {Material{}});
  EXPECT_EQ(clip.receiver().Quantise(level(190.4)), 190);
  EXPECT_EQ(clip.receiver().Quantise(level(190.6)), 191);
  EXPECT_EQ(clip.receiver().Quantise(level(300.0)), 191);
  EXPECT_EQ(clip.receiver().QuantisePower(std::pow(10.0, level(190.4) / 10.0)), 190);
  EXPECT_EQ(clip.receiver().QuantisePower(std::pow(10.0, level(300.0) / 10.0)), 191);
}

// The converter's readings (Acoustics::ad_levels 160, the real log's): the window's level
// rounded to steps of 255/160 intensity units, reading k reported as floor(k · 255 / 160). Over
// a fine sweep of levels the values reported are exactly those of k = 0..160 (161 of the 256),
// never decreasing; reading k begins at (k - ½) · 255/160 units (a level just under it reports
// k - 1's value, just over it k's); QuantisePower agrees with Quantise off the readings' edges;
// under the tank's ceiling (knee 100, ceiling 191) the highest value is 191, reading 120, as in
// the real log.
TEST(Receiver, ConverterReadingsAreReportedOnThe8BitScale) {
  SensorModel sensor = QuietSensor();
  Acoustics& a = sensor.acoustics;
  a.converter.levels = 160;
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const BeamSynthesizer converter(sensor, tracer, {Material{}});
  const auto level = [&](double steps) {
    return a.converter.low_db + steps / 255.0 * a.converter.span_db;
  };
  const double step = 255.0 / 160.0;
  std::set<int> expected;
  for (int k = 0; k <= 160; ++k) expected.insert(k * 255 / 160);
  std::set<int> seen;
  int previous = 0;
  int compared = 0;
  for (double x = -5.0; x < 270.0; x += 0.0137) {
    const int v = converter.receiver().Quantise(level(x));
    ASSERT_GE(v, previous) << x;
    previous = v;
    seen.insert(v);
    const double reading = x / step;
    if (std::abs(reading - std::round(reading - 0.5) - 0.5) < 1e-9) continue;  // on an edge
    ASSERT_EQ(converter.receiver().QuantisePower(std::pow(10.0, level(x) / 10.0)), v) << x;
    ++compared;
  }
  EXPECT_EQ(seen, expected);
  EXPECT_GT(compared, 15000);
  for (const int k : {1, 2, 5, 80, 159, 160}) {
    EXPECT_EQ(converter.receiver().Quantise(level((k - 0.5) * step - 1e-6)), (k - 1) * 255 / 160)
        << k;
    EXPECT_EQ(converter.receiver().Quantise(level((k - 0.5) * step + 1e-6)), k * 255 / 160) << k;
  }
  a.converter.knee = 100.0;
  a.converter.ceiling = 191.0;
  const BeamSynthesizer tank(sensor, tracer, {Material{}});
  EXPECT_EQ(tank.receiver().Quantise(level(2000.0)), 191);
  EXPECT_EQ(tank.receiver().QuantisePower(std::pow(10.0, level(2000.0) / 10.0)), 191);
}

// A wall 20 dB over the window's top, pinged: without a ceiling its echo clips at 255; under a
// ceiling of 191 (knee 170) it crowds just under 191, and no bin passes it.
TEST(Receiver, ASaturatingEchoStaysUnderTheReceiversCeiling) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.gain.gain_db = 40.0;
  const std::vector<TriangleMesh> wall = Wall(2.0, 0.0);
  const SynthesizedBeam open = Ping(sensor, wall);
  EXPECT_EQ(*std::ranges::max_element(open.beam.intensities), 255);
  sensor.acoustics.converter.knee = 170.0;
  sensor.acoustics.converter.ceiling = 191.0;
  const SynthesizedBeam capped = Ping(sensor, wall);
  EXPECT_EQ(*std::ranges::max_element(capped.beam.intensities), 191);
  EXPECT_EQ(capped.echo_power, open.echo_power);  // the ceiling is the receiver's, not the echo's
}

}  // namespace
}  // namespace sonarbench::sim
