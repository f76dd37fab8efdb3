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

// Pearson correlation of two equally long sequences.
double Correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const auto n = static_cast<double>(a.size());
  const double ma = std::accumulate(a.begin(), a.end(), 0.0) / n;
  const double mb = std::accumulate(b.begin(), b.end(), 0.0) / n;
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    ab += (a[k] - ma) * (b[k] - mb);
    aa += (a[k] - ma) * (a[k] - ma);
    bb += (b[k] - mb) * (b[k] - mb);
  }
  return ab / std::sqrt(aa * bb);
}

// Speckle factors from `draw` (which fills a sequence) correlate along range by (1 - m/L)² at
// lag m < L = `window`, 0 from m = L: estimated on 64 independent sequences of 16384, the mean
// estimate within 5 standard errors of the 64 (a false alarm under 1e-5 per lag) plus 4/n for
// the estimator's O(1/n) bias, lags 1-6.
template <typename Draw>
void ExpectCorrelatedOverTheWindow(int window, Draw draw) {
  constexpr int kSequences = 64;
  constexpr std::size_t kLength = 16384;
  std::array<std::vector<double>, 7> estimates;
  std::vector<double> x(kLength);
  for (int b = 0; b < kSequences; ++b) {
    draw(x);
    const double mean = std::accumulate(x.begin(), x.end(), 0.0) / kLength;
    double variance = 0.0;
    for (double v : x) variance += (v - mean) * (v - mean);
    for (std::size_t m = 1; m < estimates.size(); ++m) {
      double covariance = 0.0;
      for (std::size_t k = 0; k + m < kLength; ++k) covariance += (x[k] - mean) * (x[k + m] - mean);
      estimates[m].push_back(covariance / variance);
    }
  }
  for (std::size_t m = 1; m < estimates.size(); ++m) {
    const std::vector<double>& e = estimates[m];
    const double mean = std::accumulate(e.begin(), e.end(), 0.0) / kSequences;
    double sd = 0.0;
    for (double v : e) sd += (v - mean) * (v - mean);
    sd = std::sqrt(sd / (kSequences - 1));
    const double lag = static_cast<double>(m) / window;
    const double expected = m < static_cast<std::size_t>(window) ? (1.0 - lag) * (1.0 - lag) : 0.0;
    EXPECT_NEAR(mean, expected, 5.0 * sd / std::sqrt(kSequences) + 4.0 / kLength) << "lag " << m;
  }
}

// Beams one head step apart share all but one sector: over 64 pairs of sequences of 16384
// (sectors 0 .. 2R+1 of a place seeded from seed_base + pair; beam A hears 0 .. 2R, beam B
// 1 .. 2R+1, and with `own` each its own last, w's last weight), their factors correlate by ρ²,
// ρ = Σ w_d w_{d+1} over the shared weights, bin for bin: the mean within 5 standard errors plus
// 4/n (a false alarm under 1e-5). Returns beam A's factors 4 windows apart (independent), for a
// test of their distribution.
std::vector<double> ExpectNeighboursShareSectors(const std::vector<double>& w, int window,
                                                 int looks, std::uint64_t seed_base,
                                                 bool own = false) {
  const std::size_t shared = w.size() - (own ? 1 : 0);
  double rho = 0.0;
  for (std::size_t d = 0; d + 1 < shared; ++d) rho += w[d] * w[d + 1];
  constexpr int kPairs = 64;
  constexpr std::size_t kLength = 16384;
  std::vector<double> a(kLength);
  std::vector<double> b(kLength);
  std::vector<double> correlations;
  std::vector<double> independent;
  for (int pair = 0; pair < kPairs; ++pair) {
    std::vector<std::uint64_t> place;
    for (std::size_t d = 0; d < shared + 1; ++d) place.push_back(DeriveSeed(seed_base + pair, d));
    std::vector<std::uint64_t> seeds_a(place.begin(), place.begin() + shared);
    std::vector<std::uint64_t> seeds_b(place.begin() + 1, place.end());
    if (own) {
      seeds_a.push_back(DeriveSeed(seed_base + pair, 1000));
      seeds_b.push_back(DeriveSeed(seed_base + pair, 1001));
    }
    SectorSpeckle(a, window, w, seeds_a, looks);
    SectorSpeckle(b, window, w, seeds_b, looks);
    for (std::size_t k = 0; k < kLength; k += 4 * static_cast<std::size_t>(window)) {
      independent.push_back(a[k]);
    }
    correlations.push_back(Correlation(a, b));
  }
  const double mean = std::accumulate(correlations.begin(), correlations.end(), 0.0) / kPairs;
  double sd = 0.0;
  for (double c : correlations) sd += (c - mean) * (c - mean);
  sd = std::sqrt(sd / (kPairs - 1));
  EXPECT_NEAR(mean, rho * rho, 5.0 * sd / std::sqrt(kPairs) + 4.0 / kLength);
  return independent;
}

// Frozen speckle: with a correlation length, two pings from the same pose and head angle but
// different ping seeds hear the same echo (same ray jitter, same speckle) and differ only by
// background noise: with the noise 300 dB down, byte for byte. Another run seed, or no
// correlation length, gives other speckle. Along a wall at normal incidence (the same echo from
// anywhere along it), a 2 cm move within the 5 cm cell keeps the speckle, a move into the next
// cell draws new speckle on most of the wall's bins.
TEST(Speckle, SpeckleIsFrozenPerPlaceWithACorrelationLength) {
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  Material wall;
  wall.reflectivity = 0.5;
  SensorModel sensor;
  sensor.acoustics.noise.level_db = -300.0;
  sensor.acoustics.speckle.correlation_m = 0.05;
  const BeamSynthesizer frozen(sensor, tracer, {wall}, 7);
  Eigen::Isometry3d here = Eigen::Isometry3d::Identity();
  here.translation() = Eigen::Vector3d(0.01, 0.01, 0.01);
  const auto a = frozen.Synthesize(0.0, 0.0, here, 1);
  const auto b = frozen.Synthesize(8.5, 0.0, here, 2);
  EXPECT_EQ(a.echo_power, b.echo_power);  // the same jitter: the same rays, the same echoes
  EXPECT_EQ(a.beam.intensities, b.beam.intensities);
  const BeamSynthesizer other_run(sensor, tracer, {wall}, 8);
  EXPECT_NE(a.beam.intensities, other_run.Synthesize(0.0, 0.0, here, 1).beam.intensities);
  // Bins of the wall's echo where two beams differ by more than 2 intensity units.
  const auto differing = [&a](const SynthesizedBeam& other) {
    int wall_bins = 0;
    int differ = 0;
    for (std::size_t k = 0; k < a.echo_power.size(); ++k) {
      if (a.echo_power[k] < 1e-4) continue;
      ++wall_bins;
      differ += std::abs(int{a.beam.intensities[k]} - int{other.beam.intensities[k]}) > 2;
    }
    return std::pair{differ, wall_bins};
  };
  Eigen::Isometry3d along = here;
  along.translation().y() += 0.02;  // the same cell
  const auto [same_cell_differ, wall_bins] = differing(frozen.Synthesize(0.0, 0.0, along, 3));
  ASSERT_GE(wall_bins, 4);  // the pulse spans 4 bins
  EXPECT_LE(same_cell_differ, 1) << "of " << wall_bins;
  along.translation().y() += 0.03;  // the next cell
  const auto [next_cell_differ, bins] = differing(frozen.Synthesize(0.0, 0.0, along, 3));
  EXPECT_GE(2 * next_cell_differ, bins);
  sensor.acoustics.speckle.correlation_m = 0.0;
  const BeamSynthesizer fresh(sensor, tracer, {wall}, 7);
  EXPECT_NE(fresh.Synthesize(0.0, 0.0, here, 1).beam.intensities,
            fresh.Synthesize(8.5, 0.0, here, 2).beam.intensities);
}

// With nothing to echo, a bin holds noise of exponential power with mean N (noise_level_db); it
// reads 0 when that power is under the AD window's floor A, which happens with probability
// p = 1 - exp(-A / N). Over 200 beams × 399 bins the count of zeros is binomial; it must lie
// within 3.29 standard deviations of n·p (a 0.1% false-alarm rate, two-sided).
// Speckle correlated over the pulse (window L = 4 bins, the Micron's 5 cm pulse):
//  - factors L apart come from disjoint windows, so they are independent: a KS test against the
//    exponential of mean 1 at a 0.1% false-alarm rate (bound 1.949/√n), plus 1/1024 for the
//    tabled phases (the factor's distribution moves by less than one phase step);
//  - the first factor of a fresh sequence has its window drawn in full (mean 1, not 1/L);
//  - factors m bins apart correlate by (1 - m/L)², 0 from m = L: estimated on 64 independent
//    sequences, the mean estimate within 5 standard errors of the 64 (a false alarm under 1e-5
//    per lag) plus 4/n for the estimator's O(1/n) bias;
//  - L = 1 is the exponential draws themselves.
TEST(Speckle, SpeckleIsExponentialAndCorrelatedOverThePulse) {
  constexpr int kWindow = 4;
  Rng rng(2024);
  std::vector<double> factors(800000);
  CorrelatedSpeckle(factors, kWindow, rng);
  std::vector<double> independent;
  for (std::size_t k = 0; k < factors.size(); k += kWindow) independent.push_back(factors[k]);
  const auto n = static_cast<double>(independent.size());
  EXPECT_LT(KsDistance(independent, [](double v) { return 1.0 - std::exp(-v); }),
            1.949 / std::sqrt(n) + 1.0 / kSpecklePhases);

  double first = 0.0;
  constexpr int kFresh = 20000;
  for (int i = 0; i < kFresh; ++i) {
    std::array<double, 1> one{};
    CorrelatedSpeckle(one, kWindow, rng);
    first += one[0];
  }
  EXPECT_NEAR(first / kFresh, 1.0, 5.0 / std::sqrt(static_cast<double>(kFresh)));

  ExpectCorrelatedOverTheWindow(
      kWindow, [&](std::vector<double>& x) { CorrelatedSpeckle(x, kWindow, rng); });

  Rng a(7);
  Rng b(7);
  std::vector<double> single(100);
  CorrelatedSpeckle(single, 1, a);
  for (double v : single) EXPECT_EQ(v, b.Exponential());
}

// The speckle's window is the range response's extent in bins: the pulse (5 cm, 4 bins of
// 1.2531 cm) alone, or with skirts the pulse and one e-folding of each (5 + 2 · 5 cm: 12 bins),
// rounded; a pulse shorter than half a bin still has a window of one.
TEST(Speckle, SpeckleWindowSpansThePulseAndItsSkirts) {
  SensorModel sensor;
  sensor.acoustics.pulse.length_m = 0.05;
  const RayTracer tracer(Wall(1.0, 0.0));
  EXPECT_EQ(BeamSynthesizer(sensor, tracer, {Material{}}).speckle().window, 4);
  sensor.acoustics.pulse.skirt_length_m = 0.05;
  EXPECT_EQ(BeamSynthesizer(sensor, tracer, {Material{}}).speckle().window, 12);
  sensor.acoustics.pulse.skirt_length_m = 0.0;
  sensor.acoustics.pulse.length_m = 0.005;
  EXPECT_EQ(BeamSynthesizer(sensor, tracer, {Material{}}).speckle().window, 1);
}

// The place's angular correlation θ: sector s's scatterers are Σ_e c_e u_{s+e}, c_e ∝ q^|e|,
// q = exp(-Δ/θ), whose autocorrelation is r_c(m) = q^|m| (1 + |m| (1 - q²) / (1 + q²)). A beam's
// weights are the pattern's convolved with c, so two beams m steps apart share amplitude
// ρ(m) = (r_p ⊛ r_c)(m) / (r_p ⊛ r_c)(0), r_p the pattern weights' own autocorrelation: at
// 7.2° (4 steps) and 14.4°, for m = 1..6, within 2√(δ/2) + δ, δ = 1e-3 (the cut tails hold under
// δ of the power, under δ/2 a side, and by Cauchy-Schwarz the products they lose sum to under
// √(δ/2) a side; renormalising moves ρ by under δ). A kernel e-folding over 2θ fails from m = 2
// on (at 7.2°, ρ(2) 0.976 against 0.928).
// The weights' squares sum to 1, they are symmetric, and they reach further than the pattern.
TEST(Speckle, AngularCorrelationConvolvesTheSectorsWithAnExponential) {
  SensorModel micron = QuietSensor();
  micron.acoustics.speckle.correlation_m = 0.05;
  const std::vector<TriangleMesh> none;
  const RayTracer tracer(none);
  const std::vector<double> p = BeamSynthesizer(micron, tracer, {Material{}}).speckle().weights;
  const auto autocorrelation = [](const std::vector<double>& w, int m) {
    double sum = 0.0;
    for (std::size_t d = 0; d + static_cast<std::size_t>(std::abs(m)) < w.size(); ++d) {
      sum += w[d] * w[d + static_cast<std::size_t>(std::abs(m))];
    }
    return sum;
  };
  const double kTolerance = 2.0 * std::sqrt(0.5e-3) + 1e-3;
  for (const double degrees : {7.2, 14.4}) {
    SCOPED_TRACE(degrees);
    micron.acoustics.speckle.angular_correlation_deg = degrees;
    const std::vector<double> w = BeamSynthesizer(micron, tracer, {Material{}}).speckle().weights;
    ASSERT_EQ(w.size() % 2, 1u);
    EXPECT_GT(w.size(), p.size());
    double squares = 0.0;
    for (std::size_t d = 0; d < w.size(); ++d) {
      squares += w[d] * w[d];
      EXPECT_NEAR(w[d], w[w.size() - 1 - d], 1e-12);
    }
    EXPECT_NEAR(squares, 1.0, 1e-12);
    const double q = std::exp(-micron.geometry.step_angle_rad / (degrees * std::numbers::pi / 180));
    const auto r_c = [&](int m) {
      return std::pow(q, std::abs(m)) * (1.0 + std::abs(m) * (1.0 - q * q) / (1.0 + q * q));
    };
    const auto expected = [&](int m) {
      double sum = 0.0;
      const int reach = static_cast<int>(p.size());
      for (int k = -reach; k <= reach; ++k) sum += autocorrelation(p, k) * r_c(m - k);
      return sum;
    };
    for (int m = 1; m <= 6; ++m) {
      EXPECT_NEAR(autocorrelation(w, m), expected(m) / expected(0), kTolerance) << "m " << m;
    }
  }
}

// Speckle shared between beams through their azimuth sectors (a static sonar's scatterers are
// the place's; the Micron's beams, 3° wide and 1.8° apart, share most of theirs):
//  - the sector weights are the square roots of the pattern's shares: squares summing to 1,
//    symmetric, and the neighbouring beams' amplitude correlation ρ = Σ w_d w_{d+1} within 0.03
//    of the continuous Gaussian pattern's exp(-Δ²/8σ²) = 0.779 (the sectors are a head step
//    wide: the coarseness costs 0.024);
//  - one sector of weight 1 is CorrelatedSpeckle's sequence for that sector's seed;
//  - a beam's factors are exponential of mean 1 (KS on factors a window apart, as above);
//  - two beams one sector apart correlate by ρ², bin for bin (64 independent pairs of
//    sequences; the mean within 5 standard errors plus 4/n, a false alarm under 1e-5).
TEST(Speckle, NeighbouringBeamsShareTheirSectorsSpeckle) {
  const SensorModel micron = QuietSensor();
  const std::vector<TriangleMesh> none;
  const RayTracer tracer(none);
  const BeamSynthesizer synthesizer(micron, tracer, {Material{}});
  const std::vector<double>& w = synthesizer.speckle().weights;
  ASSERT_EQ(w.size(), 2u * kPatternReach + 1);
  double squares = 0.0;
  double rho = 0.0;
  for (std::size_t d = 0; d < w.size(); ++d) {
    squares += w[d] * w[d];
    EXPECT_NEAR(w[d], w[w.size() - 1 - d], 1e-12);
    if (d + 1 < w.size()) rho += w[d] * w[d + 1];
  }
  EXPECT_NEAR(squares, 1.0, 1e-12);
  const mapping::SensorGeometry& g = micron.geometry;
  const double sigma = g.beam_width_horizontal_rad / std::sqrt(8.0 * std::log(2.0));
  EXPECT_NEAR(rho, std::exp(-g.step_angle_rad * g.step_angle_rad / (8.0 * sigma * sigma)), 0.03);

  constexpr int kWindow = 4;
  std::vector<double> direct(500);
  std::vector<double> sector(500);
  Rng rng(99);
  CorrelatedSpeckle(direct, kWindow, rng);
  const std::array<double, 1> one = {1.0};
  const std::array<std::uint64_t, 1> seed = {99};
  SectorSpeckle(sector, kWindow, one, seed);
  EXPECT_EQ(direct, sector);

  const std::vector<double> independent = ExpectNeighboursShareSectors(w, kWindow, 1, 1000);
  const auto n = static_cast<double>(independent.size());
  EXPECT_LT(KsDistance(independent, [](double v) { return 1.0 - std::exp(-v); }),
            1.949 / std::sqrt(n) + 1.0 / kSpecklePhases);
}

// With Acoustics::speckle_own_share ν each head step hears ν of its speckle's power on its own:
//  - the weights are the sectors' times √(1 - ν), then √ν, the beam's own: squares summing to 1;
//  - two beams one sector apart, each with its own last seed, correlate by ((1 - ν) ρ)², ρ the
//    sectors' Σ w_d w_{d+1} without it (64 pairs, as above), and each beam's factors stay
//    exponential of mean 1 (KS, as above).
TEST(Speckle, EachHeadStepHearsItsOwnShareOfTheSpeckle) {
  SensorModel micron = QuietSensor();
  const std::vector<TriangleMesh> none;
  const RayTracer tracer(none);
  const std::vector<double> sectors =
      BeamSynthesizer(micron, tracer, {Material{}}).speckle().weights;
  constexpr double kOwn = 0.3;
  micron.acoustics.speckle.own_share = kOwn;
  const std::vector<double> w = BeamSynthesizer(micron, tracer, {Material{}}).speckle().weights;
  ASSERT_EQ(w.size(), sectors.size() + 1);
  double squares = 0.0;
  for (std::size_t d = 0; d < w.size(); ++d) {
    squares += w[d] * w[d];
    if (d < sectors.size()) {
      EXPECT_NEAR(w[d], std::sqrt(1.0 - kOwn) * sectors[d], 1e-15);
    }
  }
  EXPECT_NEAR(w.back(), std::sqrt(kOwn), 1e-15);
  EXPECT_NEAR(squares, 1.0, 1e-12);
  const std::vector<double> independent = ExpectNeighboursShareSectors(w, 4, 1, 3000, true);
  const auto n = static_cast<double>(independent.size());
  EXPECT_LT(KsDistance(independent, [](double v) { return 1.0 - std::exp(-v); }),
            1.949 / std::sqrt(n) + 1.0 / kSpecklePhases);
}

// Speckle of N looks (Acoustics::speckle_looks, N = 3 here) is the mean of N independent looks:
//  - SectorSpeckle's is exactly the mean of look 0 (the one-look factors for the sectors'
//    seeds) and looks 1 .. N-1 (the one-look factors for DeriveSeed(seed, l));
//  - its factors are gamma-distributed of mean 1 and shape N: KS on factors a window apart
//    against 1 - e^(-Nx) Σ_{i<N} (Nx)^i / i!, at a 0.1% false-alarm rate (1.949/√n), plus
//    N/1024 for the tabled phases (each look's factor moves by less than one phase step);
//  - they correlate along range by (1 - m/L)², as one look does (averaging independent looks
//    scales covariance and variance alike): the mean estimate over 64 sequences within 5
//    standard errors plus 4/n (a false alarm under 1e-5 per lag);
//  - two beams one sector apart still correlate by ρ², as in the test above.
TEST(Speckle, SpeckleLooksAreIndependentLooksAveraged) {
  constexpr int kWindow = 4;
  constexpr int kLooks = 3;
  const auto gamma_cdf = [](double x) {
    const double t = kLooks * x;
    return 1.0 - std::exp(-t) * (1.0 + t + 0.5 * t * t);
  };
  const auto expect_gamma = [&](const std::vector<double>& sample) {
    EXPECT_LT(KsDistance(sample, gamma_cdf), 1.949 / std::sqrt(static_cast<double>(sample.size())) +
                                                 static_cast<double>(kLooks) / kSpecklePhases);
  };

  const std::array<std::uint64_t, 2> seeds = {11, 12};
  const std::array<double, 2> weights = {0.6, 0.8};
  std::vector<double> averaged(300);
  SectorSpeckle(averaged, kWindow, weights, seeds, kLooks);
  std::vector<double> sum(300);
  std::vector<double> look(300);
  SectorSpeckle(sum, kWindow, weights, seeds);
  for (std::uint64_t l = 1; l < kLooks; ++l) {
    const std::array<std::uint64_t, 2> look_seeds = {DeriveSeed(11, l), DeriveSeed(12, l)};
    SectorSpeckle(look, kWindow, weights, look_seeds);
    for (std::size_t k = 0; k < sum.size(); ++k) sum[k] += look[k];
  }
  for (std::size_t k = 0; k < sum.size(); ++k) {
    EXPECT_EQ(averaged[k], sum[k] * (1.0 / kLooks)) << "bin " << k;
  }

  Rng rng(2025);
  std::vector<double> independent;
  ExpectCorrelatedOverTheWindow(kWindow, [&](std::vector<double>& x) {
    CorrelatedSpeckle(x, kWindow, rng, kLooks);
    for (std::size_t k = 0; k < x.size(); k += kWindow) independent.push_back(x[k]);
  });
  expect_gamma(independent);

  const SensorModel micron = QuietSensor();
  const std::vector<TriangleMesh> none;
  const RayTracer tracer(none);
  const BeamSynthesizer synthesizer(micron, tracer, {Material{}});
  const std::vector<double>& w = synthesizer.speckle().weights;
  expect_gamma(ExpectNeighboursShareSectors(w, kWindow, kLooks, 5000));
}

}  // namespace
}  // namespace sonarbench::sim
