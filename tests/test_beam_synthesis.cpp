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

#include "sonarbench/mapping/detection.hpp"
#include "sonarbench/sim/beam_synthesizer.hpp"
#include "sonarbench/sim/mesh.hpp"
#include "sonarbench/sim/pulse_spreader.hpp"
#include "sonarbench/sim/random.hpp"
#include "sonarbench/sim/simulation.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

using mapping::kDegToRad;

// A sensor with no noise, speckle or self-reflection, and range losses that cancel (spreading
// equals the time-varied gain, no absorption), so echoes can be predicted exactly.
SensorModel QuietSensor() {
  SensorModel model;
  model.acoustics.speckle = false;
  model.acoustics.noise_level_db = -300.0;
  model.acoustics.absorption_db_per_m = 0.0;
  model.acoustics.spreading_db_per_decade = 20.0;
  model.acoustics.tvg_db_per_decade = 20.0;
  model.acoustics.gain_db = 0.0;
  return model;
}

// A 20 m × 20 m plane `range` metres along the sonar's x axis, turned by `incidence_rad` about z.
std::vector<TriangleMesh> Wall(double range, double incidence_rad) {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kPlane;
  spec.size_m = {20.0, 20.0, 0.0};
  spec.T_world_mesh = mapping::PoseFromXyzRpy({range, 0, 0}, {0, 0, 0}) *
                      Eigen::AngleAxisd(incidence_rad, Eigen::Vector3d::UnitZ()) *
                      Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY());
  return {BuildMesh(spec, 0)};
}

// A 10 m × 10 m plane through (1, 0, 0) at 45° about z: it turns a ray along +x towards +y.
MeshSpec MirrorTurningXToY() {
  MeshSpec mirror;
  mirror.type = MeshSpec::Type::kPlane;
  mirror.size_m = {10.0, 10.0, 0.0};
  mirror.T_world_mesh = mapping::PoseFromXyzRpy({1.0, 0, 0}, {0, 0, 0}) *
                        Eigen::AngleAxisd(-std::numbers::pi / 4, Eigen::Vector3d::UnitZ()) *
                        Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY());
  return mirror;
}

// Kolmogorov-Smirnov distance of `sample` from the continuous distribution function `cdf`.
template <typename Cdf>
double KsDistance(std::vector<double> sample, Cdf cdf) {
  std::sort(sample.begin(), sample.end());
  const auto n = static_cast<double>(sample.size());
  double d = 0.0;
  for (std::size_t i = 0; i < sample.size(); ++i) {
    const double f = cdf(sample[i]);
    d = std::max({d, f - static_cast<double>(i) / n, static_cast<double>(i + 1) / n - f});
  }
  return d;
}

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
    BeamSynthesizer::SectorSpeckle(a, window, w, seeds_a, looks);
    BeamSynthesizer::SectorSpeckle(b, window, w, seeds_b, looks);
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

SynthesizedBeam Ping(const SensorModel& sensor, const std::vector<TriangleMesh>& meshes,
                     std::uint64_t seed = 11) {
  const RayTracer tracer(meshes);
  Material material;
  material.reflectivity = 0.5;
  material.backscatter_exponent = 1.0;
  const BeamSynthesizer synthesizer(sensor, tracer, {material});
  return synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), seed);
}

double TotalPower(const SynthesizedBeam& beam) {
  return std::accumulate(beam.echo_power.begin(), beam.echo_power.end(), 0.0);
}

// The nearest point of a wall at normal incidence is on the beam axis, at its range d: the echo
// starts in bin floor(d / bin). The stratified rays nearest the axis are within half a stratum
// (≤ 0.2°) of it, which lengthens their range by d·(1/cos 0.2° - 1) < 1e-5 d, far below a bin.
TEST(BeamSynthesis, WallAtKnownRangeEchoesInItsBin) {
  const SensorModel sensor = QuietSensor();
  const double bin = sensor.geometry.bin_size_m;
  for (double range : {0.75, 2.2, 3.9}) {
    SCOPED_TRACE(range);
    const SynthesizedBeam beam = Ping(sensor, Wall(range, 0.0));
    const auto first = std::find_if(beam.echo_power.begin(), beam.echo_power.end(),
                                    [](double p) { return p > 0.0; });
    ASSERT_NE(first, beam.echo_power.end());
    EXPECT_EQ(first - beam.echo_power.begin(), static_cast<long>(std::floor(range / bin)));
    // The strongest bin lies within the pulse behind the leading edge: most power arrives from
    // near the axis, at ranges d .. d + L.
    const auto peak = std::max_element(beam.echo_power.begin(), beam.echo_power.end());
    const long pulse_bins = static_cast<long>(std::ceil(sensor.acoustics.pulse_length_m / bin));
    EXPECT_GE(peak - beam.echo_power.begin(), first - beam.echo_power.begin());
    EXPECT_LE(peak - first, pulse_bins);
    // The ground truth beside the beam knows the wall's range.
    ASSERT_TRUE(beam.truth.axis_hit_range_m.has_value());
    EXPECT_NEAR(*beam.truth.axis_hit_range_m, range, 1e-5 * range);
    // And the mapper's detection finds it on the quantised beam within its smoothing half-window.
    mapping::DetectionConfig detection;
    detection.threshold = 45;
    detection.smoothing_bins = 5;
    const auto ranges = mapping::DetectThreshold(beam.beam, sensor.geometry, detection);
    ASSERT_FALSE(ranges.empty());
    EXPECT_NEAR(ranges[0], range, (detection.smoothing_bins / 2 + 1) * bin);
  }
}

// With n = 1 each ray's echo is ρ·b·(d̂·n̂), linear in its direction, so the summed echo of a
// plane filling the aperture is ρ·(Σ b d̂)·n̂: turning the plane by φ about the beam's vertical
// scales it by cos φ, up to the horizontal component of Σ b d̂ (zero for the symmetric pattern;
// under 1% for the jittered rays, which the same seed keeps identical between the two pings).
// A plane part of the vehicle, `ahead` metres in front of the sonar along its head-angle-0 axis
// and facing it, posed in the vehicle's frame through the sonar's mounting: `size` wide and
// tall, its centre `up` metres above the sonar's axis.
MeshSpec PartAhead(const SensorModel& sensor, double ahead, double size, double up) {
  MeshSpec part;
  part.type = MeshSpec::Type::kPlane;
  part.size_m = {size, size, 0.0};
  part.T_world_mesh = sensor.geometry.T_vehicle_sonar * Eigen::Translation3d(ahead, 0.0, up) *
                      Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY());
  return part;
}

Material Diffuse() {
  Material m;
  m.reflectivity = 0.5;
  m.backscatter_exponent = 1.0;
  return m;
}

// A vehicle part 1 m ahead of a sonar mounted 0.2 m forward and 0.1 m up on the vehicle, turned
// 90° so that its head angle 0 looks along the vehicle's y: heard at 1 m (its first bin
// floor(1 m / bin), as a wall's) by the beam looking at it, the same wherever the vehicle is and
// however it is turned (the rays are the same in the sonar's frame; their turn into the
// vehicle's is in floats: 1e-4 of the power), by none looking away; and it is not the scene, so
// the beam's truth holds no hit (the scene's one wall lies out of range).
TEST(BeamSynthesis, VehiclePartEchoesAtItsRangeWhereverTheVehicleIs) {
  SensorModel sensor = QuietSensor();
  sensor.geometry.T_vehicle_sonar =
      mapping::PoseFromXyzRpy({0.2, 0.0, 0.1}, {0, 0, 90.0 * kDegToRad});
  const std::vector<TriangleMesh> scene = Wall(50.0, 0.0);
  const RayTracer tracer(scene);
  VehicleParts vehicle{.meshes = {BuildMesh(PartAhead(sensor, 1.0, 20.0, 0.0), 0)},
                       .materials = {Diffuse()}};
  const BeamSynthesizer synthesizer(sensor, tracer, {Diffuse()}, 0, vehicle);
  const double bin = sensor.geometry.bin_size_m;
  std::optional<double> still_power;
  for (const Eigen::Isometry3d& T_world_vehicle :
       {Eigen::Isometry3d(Eigen::Isometry3d::Identity()),
        mapping::PoseFromXyzRpy({3.0, -2.0, 1.0}, {0.1, -0.2, 70.0 * kDegToRad})}) {
    const Eigen::Isometry3d T_world_sonar = T_world_vehicle * sensor.geometry.T_vehicle_sonar;
    const SynthesizedBeam beam = synthesizer.Synthesize(0.0, 0.0, T_world_sonar, 11);
    const auto first = std::find_if(beam.echo_power.begin(), beam.echo_power.end(),
                                    [](double p) { return p > 0.0; });
    ASSERT_NE(first, beam.echo_power.end());
    EXPECT_EQ(first - beam.echo_power.begin(), static_cast<long>(std::floor(1.0 / bin)));
    EXPECT_FALSE(beam.truth.first_hit_range_m.has_value());
    if (!still_power) {
      still_power = TotalPower(beam);
    } else {
      EXPECT_NEAR(TotalPower(beam), *still_power, 1e-4 * *still_power);
    }
    const SynthesizedBeam away = synthesizer.Synthesize(0.0, std::numbers::pi, T_world_sonar, 11);
    EXPECT_EQ(TotalPower(away), 0.0);
  }
}

// A part 1 m ahead covering the fan's upper half (from the sonar's height up) in front of a
// wall at 2 m: the rays above the axis end on the part, those below reach the wall. The wall's
// echo keeps the lower half of the beam's pattern: the vertical strata lie mirrored about the
// axis, each ray jittered within its 0.22° stratum, so the halves' weights differ by far under
// 10%; the part echoes at 1 m; and the truth is the wall's, at 2 m within a bin.
TEST(BeamSynthesis, VehiclePartShadowsTheSceneBehindIt) {
  const SensorModel sensor = QuietSensor();
  const std::vector<TriangleMesh> scene = Wall(2.0, 0.0);
  const RayTracer tracer(scene);
  const BeamSynthesizer bare(sensor, tracer, {Diffuse()});
  VehicleParts vehicle{.meshes = {BuildMesh(PartAhead(sensor, 1.0, 20.0, 10.0), 0)},
                       .materials = {Diffuse()}};
  const BeamSynthesizer shadowed(sensor, tracer, {Diffuse()}, 0, vehicle);
  const SynthesizedBeam without = bare.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 11);
  const SynthesizedBeam with = shadowed.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 11);
  const double bin = sensor.geometry.bin_size_m;
  const auto power_from = [&](const SynthesizedBeam& beam, double from_m, double to_m) {
    double sum = 0.0;
    for (std::size_t k = 0; k < beam.echo_power.size(); ++k) {
      if (k * bin >= from_m && k * bin < to_m) sum += beam.echo_power[k];
    }
    return sum;
  };
  const double wall_without = power_from(without, 1.5, 5.0);
  ASSERT_GT(wall_without, 0.0);
  EXPECT_NEAR(power_from(with, 1.5, 5.0) / wall_without, 0.5, 0.05);
  EXPECT_EQ(power_from(without, 0.0, 1.5), 0.0);
  EXPECT_GT(power_from(with, 1.0 - bin, 1.5), 0.0);
  EXPECT_EQ(power_from(with, 0.0, 1.0 - bin), 0.0);
  ASSERT_TRUE(with.truth.first_hit_range_m.has_value());
  EXPECT_NEAR(*with.truth.first_hit_range_m, 2.0, bin);
  EXPECT_EQ(with.truth.first_hit_mesh, 0u);
}

// The tank's answers to its echoes (skirts around each pulse, the second trip, the
// reverberation tail) are not the vehicle's: a part 1 m ahead echoes the same bins, bit for bit,
// with them on as off, while the same plane as the scene's wall gains skirts before 1 m and a
// tail and second trip after its pulse.
TEST(BeamSynthesis, VehicleEchoesHaveNoSkirtsSecondTripOrReverberation) {
  const SensorModel quiet = QuietSensor();
  SensorModel tank = quiet;
  tank.acoustics.pulse_skirt_length_m = 0.05;
  tank.acoustics.pulse_skirt_db = 3.0;
  tank.acoustics.second_trip_db = 0.0;
  tank.acoustics.reverberation_length_m = 0.5;
  tank.acoustics.reverberation_db = -3.0;
  const MeshSpec plane = PartAhead(quiet, 1.0, 20.0, 0.0);
  const std::vector<TriangleMesh> far = Wall(50.0, 0.0);
  const RayTracer far_tracer(far);
  const VehicleParts vehicle{.meshes = {BuildMesh(plane, 0)}, .materials = {Diffuse()}};
  const auto part_echo = [&](const SensorModel& sensor) {
    return BeamSynthesizer(sensor, far_tracer, {Diffuse()}, 0, vehicle)
        .Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 11)
        .echo_power;
  };
  const std::vector<double> plain = part_echo(quiet);
  ASSERT_GT(std::accumulate(plain.begin(), plain.end(), 0.0), 0.0);
  EXPECT_EQ(part_echo(tank), plain);

  const std::vector<TriangleMesh> wall = {BuildMesh(plane, 0)};
  const RayTracer wall_tracer(wall);
  const std::vector<double> walled = BeamSynthesizer(tank, wall_tracer, {Diffuse()})
                                         .Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 11)
                                         .echo_power;
  const double bin = quiet.geometry.bin_size_m;
  const auto first = static_cast<std::size_t>(std::floor(1.0 / bin));
  const auto after = static_cast<std::size_t>(std::ceil((1.0 + 0.1) / bin));
  EXPECT_EQ(plain[first - 1], 0.0);
  EXPECT_GT(walled[first - 1], 0.0);
  EXPECT_EQ(plain[after], 0.0);
  EXPECT_GT(walled[after], 0.0);
  EXPECT_GT(walled[2 * first + 2], 0.0);  // the second trip, at twice the range
}

TEST(BeamSynthesis, EchoFollowsLambertsLawWithIncidence) {
  const SensorModel sensor = QuietSensor();
  const double normal = TotalPower(Ping(sensor, Wall(2.0, 0.0)));
  ASSERT_GT(normal, 0.0);
  for (double degrees : {20.0, 40.0, 60.0}) {
    SCOPED_TRACE(degrees);
    const double tilted = TotalPower(Ping(sensor, Wall(2.0, degrees * kDegToRad)));
    EXPECT_NEAR(tilted / normal, std::cos(degrees * kDegToRad), 0.01);
  }
}

// Doubling the range of the same plane doubles every ray's range: the summed echo changes by
// exactly 10^(-((S - G)·log10 2 + α·Δr)/10), S spreading, G gain per decade, α absorption.
TEST(BeamSynthesis, EchoFollowsSpreadingAndAbsorptionWithRange) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.spreading_db_per_decade = 40.0;
  sensor.acoustics.tvg_db_per_decade = 10.0;
  sensor.acoustics.absorption_db_per_m = 0.5;
  // Absorption depends on each ray's own range, so compare ray by ray: use a narrow fan where
  // every ray's range is within 0.1% of the axis range.
  sensor.geometry.beam_width_vertical_rad = 3.0 * kDegToRad;
  const double near = TotalPower(Ping(sensor, Wall(1.0, 0.0)));
  const double far = TotalPower(Ping(sensor, Wall(2.0, 0.0)));
  const double expected_db = -(30.0 * std::log10(2.0) + 0.5 * 1.0);
  EXPECT_NEAR(10.0 * std::log10(far / near), expected_db, 0.01);
}

// Reverberation: a wall at normal incidence echoes over a few bins; the tail that echo feeds
// starts in the bin after each echo bin, falls by exp(-bin / length) per bin once the echo has
// passed (10·log10(e) / length dB per metre), and holds R = 10^(reverberation_db/10) of the
// echo's power in all: with the wall at 0.5 m and a 0.2 m length the beam's end (5 m) cuts
// exp(-22) of it. The rays are the same in both pings (same seed), so the echo is too.
TEST(BeamSynthesis, ReverberationTailDecaysAtItsLengthAndHoldsItsShare) {
  SensorModel dry = QuietSensor();
  SensorModel wet = dry;
  wet.acoustics.reverberation_length_m = 0.2;
  wet.acoustics.reverberation_db = -3.0;
  const SynthesizedBeam echo = Ping(dry, Wall(0.5, 0.0));
  const SynthesizedBeam heard = Ping(wet, Wall(0.5, 0.0));
  const std::vector<double>& p = echo.echo_power;
  ASSERT_EQ(heard.echo_power.size(), p.size());
  const auto first = static_cast<std::size_t>(
      std::find_if(p.begin(), p.end(), [](double x) { return x > 0.0; }) - p.begin());
  const auto last = static_cast<std::size_t>(
      p.rend() - std::find_if(p.rbegin(), p.rend(), [](double x) { return x > 0.0; }) - 1);
  ASSERT_LT(last + 10, p.size());
  std::vector<double> tail(p.size());
  for (std::size_t k = 0; k < p.size(); ++k) tail[k] = heard.echo_power[k] - p[k];
  // Nothing before the echo's second bin.
  for (std::size_t k = 0; k <= first; ++k) EXPECT_EQ(tail[k], 0.0) << "bin " << k;
  EXPECT_GT(tail[first + 1], 0.0);
  // Past the echo, a pure exponential in range.
  const double bin = dry.geometry.bin_size_m;
  const double per_bin = std::exp(-bin / 0.2);
  for (std::size_t k = last + 2; k < last + 200; ++k) {
    EXPECT_NEAR(tail[k] / tail[k - 1], per_bin, 1e-9) << "bin " << k;
  }
  const double total_echo = std::accumulate(p.begin(), p.end(), 0.0);
  const double total_tail = std::accumulate(tail.begin(), tail.end(), 0.0);
  EXPECT_NEAR(total_tail / total_echo, std::pow(10.0, -0.3), 1e-6);
}

// The pulse's skirts, exactly: one echo of power P in bin j keeps P / (1 + S) there and puts
// P · S (1 - q) / (2q) · q^m / (1 + S) m bins to either side, q = exp(-bin / length),
// S = 10^(db/10); the whole echo's power is kept (the two skirts' geometric series, which the
// beam's ends cut at q^199 < 1e-21 here), and each side's bins fall by q. Nothing changes at length
// 0.
TEST(BeamSynthesis, PulseSkirtsShareTheEchoExponentiallyOnBothSides) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.pulse_skirt_length_m = 0.05;
  sensor.acoustics.pulse_skirt_db = 3.0;
  const RayTracer tracer(Wall(1.0, 0.0));
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  const auto bins = static_cast<std::size_t>(sensor.geometry.num_bins);
  const double q = std::exp(-sensor.geometry.bin_size_m / 0.05);
  const double share = std::pow(10.0, 0.3);
  std::vector<double> echo(bins, 0.0);
  echo[200] = 2.0;
  std::vector<double> heard = echo;
  synthesizer.AddPulseSkirts(heard);
  for (std::size_t k = 0; k < bins; ++k) {
    const double m = std::abs(static_cast<double>(k) - 200.0);
    const double expected =
        k == 200 ? 2.0 / (1.0 + share)
                 : 2.0 * share * (1.0 - q) / (2.0 * q) * std::pow(q, m) / (1.0 + share);
    EXPECT_NEAR(heard[k], expected, 1e-12 * expected) << "bin " << k;
  }
  EXPECT_NEAR(std::accumulate(heard.begin(), heard.end(), 0.0), 2.0, 1e-12);
  // Two echoes: the sum of each one's (the skirts are linear in the echo).
  std::vector<double> other(bins, 0.0);
  other[210] = 0.5;
  std::vector<double> both = echo;
  both[210] = 0.5;
  synthesizer.AddPulseSkirts(other);
  synthesizer.AddPulseSkirts(both);
  for (std::size_t k = 0; k < bins; ++k) {
    EXPECT_NEAR(both[k], heard[k] + other[k], 1e-12 * both[k]) << "bin " << k;
  }
  const BeamSynthesizer none(QuietSensor(), tracer, {Material{}});
  std::vector<double> unchanged = echo;
  none.AddPulseSkirts(unchanged);
  EXPECT_EQ(unchanged, echo);
}

// Through the whole synthesis, a wall at normal incidence 2 m ahead: with skirts its echo starts
// in front of the wall, each bin there q times the next (q = exp(-bin / length)), up to the
// bin before the wall's; and the beam holds the same power as without them (the skirts share
// the echo out; the beam's ends cut under 1e-21 of it).
TEST(BeamSynthesis, WallEchoGainsSkirtsAndKeepsItsPower) {
  const SensorModel bare = QuietSensor();
  SensorModel skirted = bare;
  skirted.acoustics.pulse_skirt_length_m = 0.04;
  skirted.acoustics.pulse_skirt_db = 0.0;
  const std::vector<TriangleMesh> wall = Wall(2.0, 0.0);
  const SynthesizedBeam without = Ping(bare, wall);
  const SynthesizedBeam with = Ping(skirted, wall);
  const double bin = bare.geometry.bin_size_m;
  const auto wall_bin = static_cast<std::size_t>(2.0 / bin);
  ASSERT_EQ(without.echo_power[wall_bin - 1], 0.0);
  ASSERT_GT(without.echo_power[wall_bin], 0.0);
  const double q = std::exp(-bin / 0.04);
  for (std::size_t k = 1; k < wall_bin; ++k) {
    EXPECT_NEAR(with.echo_power[k - 1] / with.echo_power[k], q, 1e-9) << "bin " << k;
  }
  EXPECT_NEAR(TotalPower(with) / TotalPower(without), 1.0, 1e-12);
}

// A quiet sensor with a second trip at +3 dB, and its synthesizer (of a wall it never pings).
struct SecondTripAt3Db {
  SecondTripAt3Db() : sensor(Sensor()), tracer(Wall(1.0, 0.0)), synthesizer(sensor, tracer, {{}}) {}
  static SensorModel Sensor() {
    SensorModel s = QuietSensor();
    s.acoustics.second_trip_db = 3.0;
    return s;
  }
  SensorModel sensor;
  RayTracer tracer;
  BeamSynthesizer synthesizer;
  std::size_t bins = static_cast<std::size_t>(sensor.geometry.num_bins);
  double bin = sensor.geometry.bin_size_m;
};

// The second trip, exactly: one first-trip echo in bin i (power P, pulse-spread) and one
// impulse in bin j (power Q) give T · g(m) · (P / g(i)) · (Q / g(j)) / 2 to each of bins
// m = i + j and i + j + 1, g(k) = ((k + ½) bins)^(G/10) the time-varied gain, T the level;
// nothing elsewhere, nothing for a pair whose sum is past the last bin, nothing at -100 dB.
TEST(BeamSynthesis, SecondTripIsTheTripsProductAtTheSummedRange) {
  const SecondTripAt3Db trip;
  const BeamSynthesizer& synthesizer = trip.synthesizer;
  const std::size_t bins = trip.bins;
  const double bin = trip.bin;
  const auto g = [&](std::size_t k) { return std::pow((k + 0.5) * bin, 20.0 / 10.0); };
  std::vector<double> echo(bins, 0.0);
  std::vector<double> impulse(bins, 0.0);
  echo[50] = 0.25;
  impulse[60] = 0.125;
  std::vector<double> heard = echo;
  synthesizer.AddSecondTrip(heard, impulse);
  const double half = 0.5 * std::pow(10.0, 0.3) * (0.25 / g(50)) * (0.125 / g(60));
  for (std::size_t k = 0; k < bins; ++k) {
    double expected = echo[k];
    if (k == 110 || k == 111) expected += half * g(k);
    EXPECT_NEAR(heard[k], expected, 1e-12 * std::max(expected, 1e-30)) << "bin " << k;
  }
  // Past the last bin: nothing.
  std::vector<double> far(bins, 0.0);
  std::vector<double> far_impulse(bins, 0.0);
  far[bins - 100] = 1.0;
  far_impulse[100] = 1.0;
  std::vector<double> far_heard = far;
  synthesizer.AddSecondTrip(far_heard, far_impulse);
  EXPECT_EQ(far_heard, far);
  // At -100 dB (the default): nothing at all.
  const BeamSynthesizer none(QuietSensor(), trip.tracer, {Material{}});
  std::vector<double> unchanged = echo;
  none.AddSecondTrip(unchanged, impulse);
  EXPECT_EQ(unchanged, echo);
}

// The second trip's products run as vector code as wide as the machine has (AVX-512, AVX2 or
// the baseline), built without fused multiply-adds: bit for bit the scalar sum of its
// documentation, in its order (over i increasing), for dense random trips (every bin of both
// non-zero, some under the 1e-6 floor). Fusing would round each product-sum once instead of
// twice and change the low bits of most bins.
TEST(BeamSynthesis, SecondTripIsTheScalarSumBitForBit) {
  const SecondTripAt3Db trip;
  const BeamSynthesizer& synthesizer = trip.synthesizer;
  const std::size_t bins = trip.bins;
  const double bin = trip.bin;
  Rng rng(7);
  std::vector<double> echo(bins);
  std::vector<double> impulse(bins);
  for (std::size_t k = 0; k < bins; ++k) {
    echo[k] = rng.Exponential() * (k % 17 == 0 ? 1e-9 : 1.0);
    impulse[k] = rng.Exponential() * (k % 23 == 0 ? 1e-9 : 1.0);
  }
  std::vector<double> g(bins);
  std::vector<double> out(bins);
  std::vector<double> back(bins);
  for (std::size_t k = 0; k < bins; ++k) {
    g[k] = std::pow((k + 0.5) * bin, 20.0 / 10.0);
    out[k] = echo[k] * (1.0 / g[k]);
    back[k] = impulse[k] * (1.0 / g[k]);
  }
  const double floor_out = 1e-6 * *std::max_element(out.begin(), out.end());
  const double floor_back = 1e-6 * *std::max_element(back.begin(), back.end());
  std::size_t first = 0;
  while (back[first] < floor_back) ++first;
  std::size_t last = bins - 1;
  while (back[last] < floor_back) --last;
  std::vector<double> sums(bins, 0.0);
  for (std::size_t i = 0; i < bins; ++i) {
    if (out[i] < floor_out) continue;
    for (std::size_t j = first; j <= last && i + j < bins; ++j) sums[i + j] += out[i] * back[j];
  }
  std::vector<double> expected = echo;
  double previous = 0.0;
  for (std::size_t m = 0; m < bins; ++m) {
    expected[m] += std::pow(10.0, 0.3) * g[m] * (0.5 * (sums[m] + previous));
    previous = sums[m];
  }
  std::vector<double> heard = echo;
  synthesizer.AddSecondTrip(heard, impulse);
  for (std::size_t k = 0; k < bins; ++k) EXPECT_EQ(heard[k], expected[k]) << "bin " << k;
}

// A wall at normal incidence 1 m ahead, through the whole synthesis: with no time-varied gain
// (and spreading to match) the second trip is the two trips' convolution, so it starts where
// the first trip's echo and impulse start summed (within two bins of twice the wall's range), its
// centre of mass is theirs summed, and it holds T times their powers' product.
TEST(BeamSynthesis, WallRingsAgainAtTwiceItsRange) {
  SensorModel flat = QuietSensor();
  flat.acoustics.spreading_db_per_decade = 0.0;
  flat.acoustics.tvg_db_per_decade = 0.0;
  SensorModel ringing = flat;
  ringing.acoustics.second_trip_db = -3.0;
  const std::vector<TriangleMesh> wall = Wall(1.0, 0.0);
  const SynthesizedBeam once = Ping(flat, wall);
  const SynthesizedBeam twice = Ping(ringing, wall);
  const std::vector<double>& p = once.echo_power;
  ASSERT_EQ(twice.echo_power.size(), p.size());
  std::vector<double> second(p.size());
  for (std::size_t k = 0; k < p.size(); ++k) second[k] = twice.echo_power[k] - p[k];
  const auto first_of = [](const std::vector<double>& v) {
    return static_cast<std::size_t>(
        std::find_if(v.begin(), v.end(), [](double x) { return x > 1e-15; }) - v.begin());
  };
  const auto centre_of = [](const std::vector<double>& v) {
    double mass = 0.0;
    double moment = 0.0;
    for (std::size_t k = 0; k < v.size(); ++k) {
      mass += v[k];
      moment += (k + 0.5) * v[k];
    }
    return moment / mass;
  };
  // The first trip's impulse response: the same rays' echoes, each over one bin, which a pulse
  // one bin long gives.
  SensorModel short_pulse = flat;
  short_pulse.acoustics.pulse_length_m = flat.geometry.bin_size_m;
  const std::vector<double>& h = Ping(short_pulse, wall).echo_power;
  const std::size_t wall_bin = first_of(p);
  EXPECT_EQ(wall_bin, static_cast<std::size_t>(1.0 / flat.geometry.bin_size_m));
  EXPECT_EQ(first_of(h), wall_bin);
  EXPECT_EQ(first_of(second), 2 * wall_bin);
  // Each trip's echo is known only to its bin, taken as spread evenly over it: the sum of two
  // ranges, each within a bin, starts up to two bins before twice the wall's bin.
  const auto twice_wall = static_cast<std::size_t>(2.0 / flat.geometry.bin_size_m);
  EXPECT_GE(first_of(second) + 2, twice_wall);
  EXPECT_LE(first_of(second), twice_wall);
  EXPECT_NEAR(centre_of(second), centre_of(p) + centre_of(h), 1e-9);
  const double total_p = std::accumulate(p.begin(), p.end(), 0.0);
  const double total_h = std::accumulate(h.begin(), h.end(), 0.0);
  const double total_second = std::accumulate(second.begin(), second.end(), 0.0);
  EXPECT_NEAR(total_second / (total_p * total_h), std::pow(10.0, -0.3), 1e-9);
}

// Each trip reverberates. With no time-varied gain the beam is ρ ⊛ (E + T · ρ ⊛ E ⊛ h), E
// the first trip's echo, h its impulse response (a one-bin pulse's echo), ρ the reverberation
// (the echo itself and a tail holding R of it): its power is (1 + R)(ΣE + T · ΣE · Σh (1 + R)).
// So the second trip, the beam less the beam without it, holds T (1 + R)² ΣE Σh; a second trip
// that did not reverberate on its way back would hold T (1 + R) ΣE Σh, 1.5 times less. The
// tails (0.1 m) end within the beam: the last, from 2.1 m, loses exp(-29) of itself. E and h
// are one wall's echo, whose only bins under 1e-6 of their largest (which AddSecondTrip skips)
// can be the two at each end, where the pulse just grazes a bin: each trip loses under 2e-6 of
// its total, the product under 5e-6.
TEST(BeamSynthesis, SecondTripReverberatesOnEachTrip) {
  SensorModel flat = QuietSensor();
  flat.acoustics.spreading_db_per_decade = 0.0;
  flat.acoustics.tvg_db_per_decade = 0.0;
  flat.acoustics.reverberation_length_m = 0.1;
  flat.acoustics.reverberation_db = -3.0;
  SensorModel ringing = flat;
  ringing.acoustics.second_trip_db = -3.0;
  SensorModel impulse = QuietSensor();
  impulse.acoustics.spreading_db_per_decade = 0.0;
  impulse.acoustics.tvg_db_per_decade = 0.0;
  impulse.acoustics.pulse_length_m = flat.geometry.bin_size_m;
  const std::vector<TriangleMesh> wall = Wall(1.0, 0.0);
  const double once = TotalPower(Ping(flat, wall));
  const double twice = TotalPower(Ping(ringing, wall));
  const double h = TotalPower(Ping(impulse, wall));
  const double reverberation = std::pow(10.0, -0.3);
  const double echo = once / (1.0 + reverberation);
  const double expected = std::pow(10.0, -0.3) * (1.0 + reverberation) * (1.0 + reverberation);
  EXPECT_NEAR((twice - once) / (echo * h), expected, 5e-6 * expected);
}

// Multipath: a mirror that scatters nothing back (reflectivity 0, specular 1) at 45° one metre
// ahead turns the beam towards a plane one metre to the side. The mirror's image of that plane
// lies two metres ahead, so the ghost's echo starts in bin floor(2.0 / bin) exactly as a wall at
// 2 m would; without the specular reflection there is no echo at all.
TEST(BeamSynthesis, SpecularBounceEchoesAtTheSummedRange) {
  const SensorModel sensor = QuietSensor();
  const MeshSpec mirror = MirrorTurningXToY();
  MeshSpec target;
  target.type = MeshSpec::Type::kPlane;
  target.size_m = {20.0, 20.0, 0.0};
  target.T_world_mesh = mapping::PoseFromXyzRpy({0, 1.0, 0}, {std::numbers::pi / 2, 0, 0});
  const std::vector<TriangleMesh> meshes{BuildMesh(mirror, 0), BuildMesh(target, 0)};
  const RayTracer tracer(meshes);
  Material glass;
  glass.reflectivity = 0.0;
  glass.specular = 1.0;
  Material wall;
  wall.reflectivity = 0.5;
  const BeamSynthesizer with_multipath(sensor, tracer, {glass, wall});
  const SynthesizedBeam beam =
      with_multipath.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 3);
  const auto first = std::find_if(beam.echo_power.begin(), beam.echo_power.end(),
                                  [](double p) { return p > 0.0; });
  ASSERT_NE(first, beam.echo_power.end());
  EXPECT_EQ(first - beam.echo_power.begin(),
            static_cast<long>(std::floor(2.0 / sensor.geometry.bin_size_m)));
  glass.specular = 0.0;
  const BeamSynthesizer without(sensor, tracer, {glass, wall});
  EXPECT_EQ(TotalPower(without.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 3)), 0.0);
}

// Multipath off a mirror floor 0.3 m below a sonar pitched 10° down, facing a wall 1 m ahead
// (the wall scatters, the floor only mirrors). Seen directly, the wall spans ranges 1 m to
// √(1 + 0.3² + tan²1.5°) = 1.0444 m. Rays steeper than atan(0.3) meet the floor first, no nearer
// than 0.3 / tan 27.5° = 0.576 m, and go up to the wall no higher than z = -0.3 + 0.424·tan 27.5°
// = -0.0793 m; through the floor's image of the sonar that point lies at
// √(1 + 0.5207² + tan²1.5°) = 1.1277 m, the longest mirror path, and the straight return is
// shorter. So one bounce adds echoes past the direct echo's last bin and none past 1.1277 m plus
// the pulse, and changes nothing of the direct echo (the same random draws).
TEST(BeamSynthesis, MultipathOffAMirrorFloorLiesWithinItsMirrorPaths) {
  SensorModel sensor = QuietSensor();
  MeshSpec floor;
  floor.type = MeshSpec::Type::kPlane;
  floor.size_m = {20.0, 20.0, 0.0};
  floor.T_world_mesh = mapping::PoseFromXyzRpy({0, 0, -0.3}, {0, 0, 0});
  std::vector<TriangleMesh> meshes = Wall(1.0, 0.0);
  meshes.push_back(BuildMesh(floor, 0));
  const RayTracer tracer(meshes);
  Material wall;
  wall.reflectivity = 1.0;
  Material mirror;
  mirror.reflectivity = 0.0;
  mirror.specular = 1.0;
  const Eigen::Isometry3d pitched_down =
      mapping::PoseFromXyzRpy({0, 0, 0}, {0, 10.0 * kDegToRad, 0});
  auto ping = [&](int bounces) {
    sensor.acoustics.max_bounces = bounces;
    const BeamSynthesizer synthesizer(sensor, tracer, {wall, mirror});
    return synthesizer.Synthesize(0.0, 0.0, pitched_down, 5).echo_power;
  };
  const std::vector<double> direct = ping(0);
  const std::vector<double> multipath = ping(1);
  const double bin = sensor.geometry.bin_size_m;
  const double pulse = sensor.acoustics.pulse_length_m;
  const auto last_direct = static_cast<std::size_t>((1.0444 + pulse) / bin);
  const auto last_mirror = static_cast<std::size_t>((1.1277 + pulse) / bin);
  double past_direct = 0.0;
  for (std::size_t k = 0; k < direct.size(); ++k) {
    if (k > last_direct) {
      EXPECT_EQ(direct[k], 0.0) << "bin " << k;
    }
    if (k > last_mirror) {
      EXPECT_EQ(multipath[k], 0.0) << "bin " << k;
    }
    EXPECT_GE(multipath[k], direct[k] * (1.0 - 1e-12)) << "bin " << k;
    if (k > last_direct) past_direct += multipath[k];
  }
  EXPECT_GT(past_direct, 0.0);
}

// A rough mirror's glint, g exp(-α²/2σ²) with α the angle between its mirror direction and the
// way back to the sonar. A wall at normal incidence, the aperture narrowed to 0.3° × 3.5° so
// that every ray meets it within 1.76° of the normal (α ≤ 3.51°): with σ = 20° each ray's glint
// lies between g exp(-(3.51/20)²/2) = 0.9847 g and g, so the echo lies between 0.9847 and 1
// times that of a plain reflector of reflectivity g and exponent 0 (the same rays, the same
// weights). At 30° incidence, with σ = 2°, α ≥ 56.5° and the glint is nothing (e^-399).
TEST(BeamSynthesis, GlintIsTheMirrorLobeTowardsTheSonar) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.aperture_scale_horizontal = 0.1;
  sensor.acoustics.aperture_scale_vertical = 0.1;
  Material plain;
  plain.reflectivity = 0.2;
  plain.backscatter_exponent = 0.0;
  Material glint;
  glint.reflectivity = 0.0;
  glint.glint = 0.2;
  const auto echo = [&](double incidence_rad, const Material& m) {
    const std::vector<TriangleMesh> meshes = Wall(2.0, incidence_rad);
    const RayTracer tracer(meshes);
    return TotalPower(BeamSynthesizer(sensor, tracer, {m})
                          .Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 4));
  };
  glint.specular_spread_rad = 20.0 * kDegToRad;
  const double reference = echo(0.0, plain);
  ASSERT_GT(reference, 0.0);
  EXPECT_GE(echo(0.0, glint), 0.9847 * reference);
  EXPECT_LE(echo(0.0, glint), reference * (1.0 + 1e-12));
  glint.specular_spread_rad = 2.0 * kDegToRad;
  const double oblique = echo(30.0 * kDegToRad, plain);
  ASSERT_GT(oblique, 0.0);
  EXPECT_LT(echo(30.0 * kDegToRad, glint), 1e-100 * oblique);
}

// A glint is the sonar's mirror image, sound that came straight back: it takes the pulse's
// skirts like any echo but feeds neither the reverberation nor the second trip. A wall 1 m
// ahead at normal incidence that only glints is heard bit for bit the same with the tank's
// reverberation and second trip as without them (skirts in both, and heard in front of the
// wall); the same wall as a diffuse reflector gains a tail and a second trip.
TEST(BeamSynthesis, GlintsFeedNoReverberationOrSecondTrip) {
  SensorModel skirts = QuietSensor();
  skirts.acoustics.aperture_scale_horizontal = 0.1;
  skirts.acoustics.aperture_scale_vertical = 0.1;
  skirts.acoustics.pulse_skirt_length_m = 0.05;
  skirts.acoustics.pulse_skirt_db = 3.0;
  SensorModel tank = skirts;
  tank.acoustics.second_trip_db = 0.0;
  tank.acoustics.reverberation_length_m = 0.5;
  tank.acoustics.reverberation_db = -3.0;
  Material glint;
  glint.reflectivity = 0.0;
  glint.specular_spread_rad = 20.0 * kDegToRad;
  glint.glint = 0.2;
  Material diffuse;
  diffuse.reflectivity = 0.2;
  diffuse.backscatter_exponent = 0.0;
  const std::vector<TriangleMesh> wall = Wall(1.0, 0.0);
  const RayTracer tracer(wall);
  const auto echo = [&](const SensorModel& sensor, const Material& m) {
    return BeamSynthesizer(sensor, tracer, {m})
        .Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 12)
        .echo_power;
  };
  const std::vector<double> glint_alone = echo(skirts, glint);
  ASSERT_GT(std::accumulate(glint_alone.begin(), glint_alone.end(), 0.0), 0.0);
  EXPECT_EQ(echo(tank, glint), glint_alone);
  const double bin = skirts.geometry.bin_size_m;
  const auto first = static_cast<std::size_t>(std::floor(1.0 / bin));
  const auto after = static_cast<std::size_t>(std::ceil((1.0 + 0.5) / bin));
  EXPECT_GT(glint_alone[first - 1], 0.0);  // the skirts
  const std::vector<double> diffuse_alone = echo(skirts, diffuse);
  const std::vector<double> diffuse_in_tank = echo(tank, diffuse);
  EXPECT_GT(diffuse_in_tank[after], 2.0 * diffuse_alone[after]);                  // the tail
  EXPECT_GT(diffuse_in_tank[2 * first + 2], 2.0 * diffuse_alone[2 * first + 2]);  // second trip
}

// A corner of two walls square to each other (a dihedral, its edge vertical, 2 m ahead, each
// wall 45° off the beam) sends sound straight back: every ray leaves the second wall parallel to
// the way it came, towards the sonar. With walls that only glint (no diffuse backscatter), the
// direct echo is nothing (α = 90° at 45° incidence) and the corner is heard through its mirror
// path alone: from its apex's range, 2 m (out and back the unfolded path is twice it), to that
// of the rays farthest off the horizontal, 2 m / cos 1.75° in the narrowed fan, plus the pulse;
// the glint there is of the order of g, where the walls' own (at 45°) is e^-162 g.
TEST(BeamSynthesis, CornerSendsItsGlintStraightBack) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.aperture_scale_horizontal = 0.1;
  sensor.acoustics.aperture_scale_vertical = 0.1;
  std::vector<TriangleMesh> meshes;
  for (const double turn : {45.0, -45.0}) {
    MeshSpec wall;
    wall.type = MeshSpec::Type::kPlane;
    wall.size_m = {4.0, 4.0, 0.0};
    // A plane through the apex (2, 0, 0), its normal 45° off -x, half of it behind the other.
    const Eigen::Vector3d normal(-std::cos(turn * kDegToRad), -std::sin(turn * kDegToRad), 0.0);
    const Eigen::Vector3d along = Eigen::Vector3d::UnitZ().cross(normal);
    wall.T_world_mesh = Eigen::Isometry3d::Identity();
    wall.T_world_mesh.linear().col(0) = along;
    wall.T_world_mesh.linear().col(1) = Eigen::Vector3d::UnitZ();
    wall.T_world_mesh.linear().col(2) = along.cross(Eigen::Vector3d::UnitZ());
    wall.T_world_mesh.translation() =
        Eigen::Vector3d(2.0, 0.0, 0.0) + 2.0 * along * (turn > 0 ? -1.0 : 1.0);
    meshes.push_back(BuildMesh(wall, meshes.size()));
  }
  const RayTracer tracer(meshes);
  Material corner;
  corner.reflectivity = 0.0;
  corner.specular = 1.0;
  corner.specular_spread_rad = 5.0 * kDegToRad;
  corner.glint = 0.2;
  const auto ping = [&](int bounces) {
    sensor.acoustics.max_bounces = bounces;
    return BeamSynthesizer(sensor, tracer, {corner, corner})
        .Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 6)
        .echo_power;
  };
  const std::vector<double> direct = ping(0);
  const std::vector<double> back = ping(1);
  const double bin = sensor.geometry.bin_size_m;
  const double pulse = sensor.acoustics.pulse_length_m;
  const auto first = static_cast<std::size_t>(2.0 / bin);
  const auto last = static_cast<std::size_t>((2.0 / std::cos(1.75 * kDegToRad) + pulse) / bin);
  double inside = 0.0;
  for (std::size_t k = 0; k < back.size(); ++k) {
    EXPECT_LT(direct[k], 1e-30) << "bin " << k;
    if (k < first || k > last) {
      EXPECT_EQ(back[k], 0.0) << "bin " << k;
    } else {
      inside += back[k];
    }
  }
  // Each ray's straight return brings 2 √pattern · p_rx · g e^-α²/2σ² with α ≤ 3.5° (at least
  // 0.78 g per unit of pattern): of the order of g in all; without it the walls give e^-162 g.
  EXPECT_GT(inside, 0.1 * corner.glint);
}

// A rough mirror tilts a reflected ray off the mirror direction m by atan(σ·|g|), g a standard
// 2-D Gaussian offset across m, towards g's direction: tan(tilt) / σ is Rayleigh distributed,
// P(≤ x) = 1 - exp(-x²/2), and the tilt's direction about m uniform. The offsets are tabled, 64
// Rayleigh quantiles × 64 directions, so each distribution may be 1/128 off the continuous one
// at a table step; on top, Kolmogorov-Smirnov's 1.949/√n is a 0.1% false-alarm rate. With
// σ = 5° and m 60° off the normal, the largest tilt (atan(3.11 σ) = 15°) never meets the
// surface, so no ray is folded back and the distributions hold exactly.
TEST(BeamSynthesis, RoughMirrorTiltsRaysByItsSpread) {
  const RayTracer tracer(Wall(1.0, 0.0));
  Material rough;
  rough.specular = 1.0;
  rough.specular_spread_rad = 5.0 * kDegToRad;
  const BeamSynthesizer synthesizer(QuietSensor(), tracer, {rough});
  const Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
  const Eigen::Vector3f mirror(std::sin(1.047f), 0.0f, std::cos(1.047f));
  const Eigen::Vector3f u = mirror.cross(Eigen::Vector3f::UnitY()).normalized();
  const Eigen::Vector3f v = mirror.cross(u);
  constexpr int kDraws = 100000;
  Rng rng(77);
  std::vector<double> radius;
  std::vector<double> direction;
  for (int i = 0; i < kDraws; ++i) {
    const Eigen::Vector3f d = synthesizer.SpreadMirror(mirror, normal, rough, rng);
    ASSERT_NEAR(d.norm(), 1.0f, 1e-5f);
    const double along = d.dot(mirror);
    const Eigen::Vector2d across(d.dot(u), d.dot(v));
    radius.push_back(across.norm() / along / rough.specular_spread_rad);
    direction.push_back(std::atan2(across.y(), across.x()));
  }
  const double bound = 1.0 / 128.0 + 1.949 / std::sqrt(static_cast<double>(kDraws));
  EXPECT_LT(KsDistance(radius, [](double x) { return 1.0 - std::exp(-0.5 * x * x); }), bound);
  EXPECT_LT(KsDistance(direction,
                       [](double a) { return (a + std::numbers::pi) / (2 * std::numbers::pi); }),
            bound);
}

// A perfect mirror (spread 0) returns the mirror direction itself and draws nothing, so scenes
// without rough mirrors keep their bytes. A ray leaving a rough mirror 2° above its surface with
// an 8° spread would go into the surface about 40% of the time: every one comes out on the
// mirror's side, at unit length.
TEST(BeamSynthesis, RoughMirrorKeepsRaysOnItsSide) {
  const RayTracer tracer(Wall(1.0, 0.0));
  Material perfect;
  perfect.specular = 1.0;
  const BeamSynthesizer synthesizer(QuietSensor(), tracer, {perfect});
  const Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
  const Eigen::Vector3f grazing(std::cos(0.0349f), 0.0f, std::sin(0.0349f));
  Rng rng(5);
  Rng untouched(5);
  EXPECT_EQ(synthesizer.SpreadMirror(grazing, normal, perfect, rng), grazing);
  EXPECT_EQ(rng.Next(), untouched.Next());
  Material rough = perfect;
  rough.specular_spread_rad = 8.0 * kDegToRad;
  int folded = 0;
  for (int i = 0; i < 10000; ++i) {
    const Eigen::Vector3f d = synthesizer.SpreadMirror(grazing, normal, rough, rng);
    ASSERT_GT(d.dot(normal), 0.0f) << d.transpose();
    ASSERT_NEAR(d.norm(), 1.0f, 1e-5f);
    folded += d.z() > grazing.z() ? 1 : 0;
  }
  // Above the mirror direction: the half tilted up, plus the folded ones tilted down by more than
  // twice the 2° (P(g < -2 tan 2°/σ) = 0.31): 81% of the draws, ±0.4% (one standard deviation).
  EXPECT_GT(folded, 7500);
}

// The mirror of SpecularBounceEchoesAtTheSummedRange, with the target now a strip 0.1-0.5 m to
// the side of where the mirror sends the beam (the beam leaves it within 1.5° of +y, so reaches
// y = 1 m within 3 cm of x = 1 m; the strip is 5.7-26.6° off). A perfect mirror puts no echo on
// it; a rough one does, more the rougher it is (a ray reaches the strip when its tilt towards
// it, σ·g with g standard normal, exceeds tan 5.7°: 0.2% of rays for σ = 2°, 24% for 8°), and
// its echo still lies past the 2 m of the image (a tilted path is only longer).
TEST(BeamSynthesis, RoughMirrorSpreadsTheGhostSideways) {
  const SensorModel sensor = QuietSensor();
  const MeshSpec mirror = MirrorTurningXToY();
  MeshSpec strip;
  strip.type = MeshSpec::Type::kPlane;
  strip.size_m = {0.4, 20.0, 0.0};
  strip.T_world_mesh = mapping::PoseFromXyzRpy({1.3, 1.0, 0}, {std::numbers::pi / 2, 0, 0});
  const std::vector<TriangleMesh> meshes{BuildMesh(mirror, 0), BuildMesh(strip, 0)};
  const RayTracer tracer(meshes);
  Material wall;
  wall.reflectivity = 0.5;
  auto ghost = [&](double spread_deg) {
    Material glass;
    glass.reflectivity = 0.0;
    glass.specular = 1.0;
    glass.specular_spread_rad = spread_deg * kDegToRad;
    const BeamSynthesizer synthesizer(sensor, tracer, {glass, wall});
    return synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 3).echo_power;
  };
  const auto image_bin = static_cast<std::size_t>(std::floor(2.0 / sensor.geometry.bin_size_m));
  auto total = [&](const std::vector<double>& power) {
    for (std::size_t k = 0; k < image_bin && k < power.size(); ++k) {
      EXPECT_EQ(power[k], 0.0) << "bin " << k;
    }
    return std::accumulate(power.begin(), power.end(), 0.0);
  };
  const double perfect = total(ghost(0.0));
  const double slightly = total(ghost(2.0));
  const double rough = total(ghost(8.0));
  EXPECT_EQ(perfect, 0.0);
  EXPECT_GT(rough, 10.0 * slightly) << slightly << " vs " << rough;
  EXPECT_GT(rough, 0.0);
}

// Through a rough mirror the echo does not come back along its way out: the way back is tilted
// afresh, so it reaches the sonar from a direction off the way out and the receive pattern
// weighs that. The mirror of SpecularBounceEchoesAtTheSummedRange, halfway along the 2 m path
// to a wide wall (its image): a tilt δ at the mirror moves the image seen from the sonar by
// δ/2, so the way back arrives c = (δ_out - δ_back)/2 off the way out, c ~ N(0, σ²/2) per
// axis. With the one-way pattern p(a) = exp(-k a²/2) per axis (k = 4 ln 2 / w², the rays
// uniform over the nominal width w), the ghost's power against a perfect mirror's is, per
// axis, ∫ p(a) E[p(a + c)] da / ∫ p(a)² da, with E[p(a + c)] = exp(-k a²/(2(1 + kτ²))) /
// √(1 + kτ²), τ² = σ²/2; times 1 - σ² for the tilted incidence on the wall (E[cos t] for a
// tilt t of mean square 2σ²). The synthesis draws δ_out and averages over δ_back in closed
// form; this checks the unfolding that places the image and the (L - s)/L weighting. Tolerance:
// the small-angle terms, of order σ² = 2% at 8°, plus four standard errors of the mean over 40
// pings.
TEST(BeamSynthesis, RoughMirrorEchoComesBackThroughItsReceivePattern) {
  const SensorModel sensor = QuietSensor();
  MeshSpec target;
  target.type = MeshSpec::Type::kPlane;
  target.size_m = {40.0, 40.0, 0.0};
  target.T_world_mesh = mapping::PoseFromXyzRpy({0, 1.0, 0}, {std::numbers::pi / 2, 0, 0});
  const std::vector<TriangleMesh> meshes{BuildMesh(MirrorTurningXToY(), 0), BuildMesh(target, 0)};
  const RayTracer tracer(meshes);
  Material wall;
  wall.reflectivity = 0.5;
  const double sigma = 8.0 * kDegToRad;
  auto ghost = [&](double spread, std::uint64_t seed) {
    Material glass;
    glass.reflectivity = 0.0;
    glass.specular = 1.0;
    glass.specular_spread_rad = spread;
    const BeamSynthesizer synthesizer(sensor, tracer, {glass, wall});
    return TotalPower(synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), seed));
  };
  constexpr int kPings = 40;
  std::vector<double> ratio;
  for (int i = 0; i < kPings; ++i) {
    const auto seed = static_cast<std::uint64_t>(100 + i);
    ratio.push_back(ghost(sigma, seed) / ghost(0.0, seed));
  }
  const double mean = std::accumulate(ratio.begin(), ratio.end(), 0.0) / kPings;
  double sum_sq = 0.0;
  for (double r : ratio) sum_sq += (r - mean) * (r - mean);
  const double standard_error = std::sqrt(sum_sq / (kPings - 1) / kPings);

  auto per_axis = [&](double width) {
    const double k = 4.0 * std::log(2.0) / (width * width);
    const double spread = 1.0 + k * sigma * sigma / 2.0;
    double through = 0.0;
    double direct = 0.0;
    constexpr int kSteps = 10000;
    for (int j = 0; j < kSteps; ++j) {
      const double a = width * ((j + 0.5) / kSteps - 0.5);
      const double p = std::exp(-0.5 * k * a * a);
      through += p * std::exp(-0.5 * k * a * a / spread) / std::sqrt(spread);
      direct += p * p;
    }
    return through / direct;
  };
  const auto& g = sensor.geometry;
  const double expected = per_axis(g.beam_width_horizontal_rad) *
                          per_axis(g.beam_width_vertical_rad) * (1.0 - sigma * sigma);
  std::printf("rough/perfect ghost power %.4f ± %.4f, expected %.4f\n", mean, standard_error,
              expected);
  EXPECT_NEAR(mean, expected, 0.02 * expected + 4.0 * standard_error);
  // Without the fresh way back (the echo retracing its way out) it would be about 1 - σ².
  EXPECT_LT(mean, 0.8);
}

// The straight return's occlusion ray: a wall 1 m ahead blocks a segment that reaches it, not
// one that stops 1 cm short, from either side.
TEST(RayTracer, OccludedOnlyBySurfacesWithinTheSegment) {
  const std::vector<TriangleMesh> meshes = Wall(1.0, 0.0);
  const RayTracer tracer(meshes);
  const Eigen::Vector3f x = Eigen::Vector3f::UnitX();
  EXPECT_FALSE(tracer.Occluded(Eigen::Vector3f::Zero(), x, 0.99f));
  EXPECT_TRUE(tracer.Occluded(Eigen::Vector3f::Zero(), x, 1.01f));
  EXPECT_FALSE(tracer.Occluded(Eigen::Vector3f(2.0f, 0, 0), -x, 0.99f));
  EXPECT_TRUE(tracer.Occluded(Eigen::Vector3f(2.0f, 0, 0), -x, 1.01f));
}

// The synthesis traces each beam's rays as one coherent stream: it must find what one query per
// ray finds. Rays in every direction from inside a tank (walls, floor, open top, and a box
// whose edges some rays graze): the same rays hit, the same meshes, the same distances to
// float rounding (1e-5 relative: a few ulps of the float tfar), the same normals.
TEST(RayTracer, BundleFindsWhatSingleRaysFind) {
  MeshSpec tank;
  tank.type = MeshSpec::Type::kTank;
  tank.size_m = {4.4, 4.4, 2.0};
  MeshSpec box;
  box.size_m = {0.5, 0.3, 0.4};
  box.T_world_mesh = mapping::PoseFromXyzRpy({1.0, 0.5, 0.3}, {0, 0, 0.4});
  const std::vector<TriangleMesh> meshes = {BuildMesh(tank, 1), BuildMesh(box, 1)};
  const RayTracer tracer(meshes);
  Rng rng(77);
  const Eigen::Vector3f origin(0.2f, -0.1f, 0.8f);
  std::vector<Eigen::Vector3f> directions(1000);
  for (auto& d : directions) {
    d = Eigen::Vector3f(static_cast<float>(rng.Normal()), static_cast<float>(rng.Normal()),
                        static_cast<float>(rng.Normal()))
            .normalized();
  }
  std::vector<std::optional<Hit>> bundle(directions.size());
  tracer.IntersectBundle(origin, directions, 3.0f, bundle);
  int hits = 0;
  for (std::size_t i = 0; i < directions.size(); ++i) {
    const auto single = tracer.Intersect(origin, directions[i], 3.0f);
    ASSERT_EQ(single.has_value(), bundle[i].has_value()) << "ray " << i;
    if (!single) continue;
    ++hits;
    EXPECT_EQ(single->mesh, bundle[i]->mesh) << "ray " << i;
    EXPECT_NEAR(single->distance, bundle[i]->distance, 1e-5f * single->distance) << "ray " << i;
    EXPECT_GT(std::abs(single->normal.dot(bundle[i]->normal)), 1.0f - 1e-5f) << "ray " << i;
  }
  EXPECT_GT(hits, 500);   // the walls and floor within 3 m of most directions
  EXPECT_LT(hits, 1000);  // the open top lets some out
  std::vector<std::optional<Hit>> short_hits(3);
  EXPECT_THROW(tracer.IntersectBundle(origin, directions, 3.0f, short_hits), std::invalid_argument);
}

// A beam's rays: ray (i, j) lies in horizontal stratum i and vertical stratum j of the aperture
// (the nominal widths times each direction's aperture scale), at one of the slots (the slot
// centres, to rounding), with the two-way pattern weight of its direction (of the nominal
// widths, whatever the scale); over pings every slot of a stratum is used (32 slots, 2000
// draws: a slot missed with probability 32 · (31/32)^2000 < 1e-26).
TEST(BeamSynthesis, RaysFillTheirStrataWithThePatternsWeights) {
  SensorModel scaled;
  scaled.acoustics.aperture_scale_horizontal = 2.0;
  scaled.acoustics.aperture_scale_vertical = 0.5;
  for (const SensorModel& sensor : {SensorModel{}, scaled}) {
    const mapping::SensorGeometry& g = sensor.geometry;
    const Acoustics& a = sensor.acoustics;
    SCOPED_TRACE(a.aperture_scale_horizontal);
    const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
    const RayTracer tracer(meshes);
    const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
    constexpr int kSlots = BeamSynthesizer::kJitterSlots;
    const double stratum_h =
        a.aperture_scale_horizontal * g.beam_width_horizontal_rad / a.rays_horizontal;
    const double stratum_v =
        a.aperture_scale_vertical * g.beam_width_vertical_rad / a.rays_vertical;
    const double k_h = 4.0 * std::log(2.0) / std::pow(g.beam_width_horizontal_rad, 2);
    const double k_v = 4.0 * std::log(2.0) / std::pow(g.beam_width_vertical_rad, 2);
    Rng rng(3);
    std::vector<Eigen::Vector3f> directions;
    std::vector<double> patterns;
    std::vector<int> slot_uses(kSlots, 0);
    for (int ping = 0; ping < 2000; ++ping) {
      const double sum =
          synthesizer.DrawRays(Eigen::Matrix3d::Identity(), rng, directions, patterns);
      ASSERT_EQ(directions.size(), static_cast<std::size_t>(a.rays_horizontal * a.rays_vertical));
      EXPECT_NEAR(sum, std::accumulate(patterns.begin(), patterns.end(), 0.0), 1e-9 * sum);
      for (int i = 0, r = 0; i < a.rays_horizontal; ++i) {
        for (int j = 0; j < a.rays_vertical; ++j, ++r) {
          if (ping > 0 && r > 0) break;  // every ray of the first ping, then ray 0's slots
          const Eigen::Vector3d d = directions[static_cast<std::size_t>(r)].cast<double>();
          const double theta = std::atan2(d.y(), d.x());
          const double epsilon = std::asin(d.z());
          // Positions in slots of the stratum: within float rounding of a slot centre.
          const double slot_h = (theta / stratum_h + 0.5 * a.rays_horizontal - i) * kSlots - 0.5;
          const double slot_v = (epsilon / stratum_v + 0.5 * a.rays_vertical - j) * kSlots - 0.5;
          ASSERT_NEAR(slot_h, std::round(slot_h), 1e-2) << "ray " << i << ", " << j;
          ASSERT_NEAR(slot_v, std::round(slot_v), 1e-2) << "ray " << i << ", " << j;
          ASSERT_GE(std::round(slot_h), 0);
          ASSERT_LT(std::round(slot_h), kSlots);
          ASSERT_GE(std::round(slot_v), 0);
          ASSERT_LT(std::round(slot_v), kSlots);
          EXPECT_NEAR(patterns[static_cast<std::size_t>(r)],
                      std::exp(-k_h * theta * theta - k_v * epsilon * epsilon), 1e-6);
          if (r == 0) ++slot_uses[static_cast<std::size_t>(std::round(slot_v))];
        }
      }
    }
    for (int slot = 0; slot < kSlots; ++slot) EXPECT_GT(slot_uses[slot], 0) << "slot " << slot;
  }
}

// Rays from anywhere in the tank, traced as one incoherent stream, and their occlusion tests as
// another: the same answers as one query per ray (distances to float rounding, as above).
TEST(RayTracer, StreamsFindWhatSingleRaysFind) {
  MeshSpec tank;
  tank.type = MeshSpec::Type::kTank;
  tank.size_m = {4.4, 4.4, 2.0};
  const std::vector<TriangleMesh> meshes = {BuildMesh(tank, 1)};
  const RayTracer tracer(meshes);
  Rng rng(78);
  std::vector<Ray> rays(1000);
  for (Ray& ray : rays) {
    ray.origin = Eigen::Vector3f(static_cast<float>(4.0 * rng.Uniform() - 2.0),
                                 static_cast<float>(4.0 * rng.Uniform() - 2.0),
                                 static_cast<float>(1.8 * rng.Uniform() + 0.1));
    ray.direction =
        Eigen::Vector3f(static_cast<float>(rng.Normal()), static_cast<float>(rng.Normal()),
                        static_cast<float>(rng.Normal()))
            .normalized();
    ray.max_distance = static_cast<float>(3.0 * rng.Uniform());
  }
  std::vector<std::optional<Hit>> hits(rays.size());
  tracer.IntersectStream(rays, hits);
  std::vector<bool> occluded;
  tracer.OccludedStream(rays, occluded);
  ASSERT_EQ(occluded.size(), rays.size());
  int found = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Ray& ray = rays[i];
    const auto single = tracer.Intersect(ray.origin, ray.direction, ray.max_distance);
    ASSERT_EQ(single.has_value(), hits[i].has_value()) << "ray " << i;
    EXPECT_EQ(tracer.Occluded(ray.origin, ray.direction, ray.max_distance), occluded[i])
        << "ray " << i;
    if (!single) continue;
    ++found;
    EXPECT_EQ(single->mesh, hits[i]->mesh) << "ray " << i;
    EXPECT_NEAR(single->distance, hits[i]->distance, 1e-5f * single->distance) << "ray " << i;
    EXPECT_GT(std::abs(single->normal.dot(hits[i]->normal)), 1.0f - 1e-5f) << "ray " << i;
  }
  EXPECT_GT(found, 200);  // segments up to 3 m long inside a 4.4 m tank: many reach a wall,
  EXPECT_LT(found, 900);  // many do not
  EXPECT_THROW(tracer.IntersectStream(rays, std::span(hits).first(3)), std::invalid_argument);
}

// While recording, a tracer logs each query it answers, in order, with its rays; before and
// after, nothing.
TEST(RayTracer, RecordsEveryQueryWithItsRaysWhileRecording) {
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const Eigen::Vector3f origin(0.0f, 0.5f, 0.0f);
  const std::vector<Eigen::Vector3f> directions = {Eigen::Vector3f::UnitX(),
                                                   Eigen::Vector3f(0.6f, 0.8f, 0.0f)};
  const std::vector<Ray> rays = {{origin, Eigen::Vector3f::UnitX(), 3.0f},
                                 {origin, -Eigen::Vector3f::UnitX(), 1.0f},
                                 {origin, Eigen::Vector3f::UnitY(), 2.0f}};
  std::vector<std::optional<Hit>> hits(rays.size());
  std::vector<bool> occluded;
  RayQueryLog log;
  (void)tracer.Intersect(origin, Eigen::Vector3f::UnitX(), 3.0f);
  tracer.Record(&log);
  tracer.IntersectBundle(origin, directions, 4.0f, std::span(hits).first(2));
  tracer.IntersectStream(rays, hits);
  tracer.OccludedStream(std::span(rays).first(2), occluded);
  (void)tracer.Intersect(origin, Eigen::Vector3f::UnitZ(), 5.0f);
  (void)tracer.Occluded(origin, Eigen::Vector3f::UnitX(), 6.0f);
  tracer.Record(nullptr);
  tracer.IntersectStream(rays, hits);

  using Query = RayQueryLog::Query;
  ASSERT_EQ(log.entries.size(), 5u);
  const std::vector<Query> queries = {Query::kBundle, Query::kStream, Query::kOccludedStream,
                                      Query::kSingle, Query::kSingleOccluded};
  const std::vector<std::size_t> sizes = {2, 3, 2, 1, 1};
  for (std::size_t e = 0; e < log.entries.size(); ++e) {
    EXPECT_EQ(log.entries[e].query, queries[e]) << "entry " << e;
    EXPECT_EQ(log.entries[e].rays.size(), sizes[e]) << "entry " << e;
  }
  EXPECT_EQ(log.RayCount(), 9u);
  const auto same = [](const Ray& a, const Ray& b) {
    return a.origin == b.origin && a.direction == b.direction && a.max_distance == b.max_distance;
  };
  EXPECT_TRUE(same(log.entries[0].rays[1], {origin, directions[1], 4.0f}));
  for (std::size_t i = 0; i < rays.size(); ++i) EXPECT_TRUE(same(log.entries[1].rays[i], rays[i]));
  EXPECT_TRUE(same(log.entries[2].rays[1], rays[1]));
  EXPECT_TRUE(same(log.entries[3].rays[0], {origin, Eigen::Vector3f::UnitZ(), 5.0f}));
  EXPECT_TRUE(same(log.entries[4].rays[0], {origin, Eigen::Vector3f::UnitX(), 6.0f}));
}

// A beam of the tank (multipath, the vehicle's parts, the back lobe) counts as traced exactly the
// rays its queries of the scene's and the parts' tracers carry: what synthesis_bench replays.
TEST(BeamSynthesis, CountsAsTracedTheRaysOfItsQueries) {
  const Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  const auto meshes = BuildSceneMeshes(scene);
  const RayTracer tracer(meshes);
  const BeamSynthesizer synthesizer = SceneSynthesizer(scene, tracer, 3);
  ASSERT_NE(synthesizer.VehicleTracer(), nullptr);
  RayQueryLog log;
  RayQueryLog vehicle_log;
  tracer.Record(&log);
  synthesizer.VehicleTracer()->Record(&vehicle_log);
  const std::vector<SynthesizedBeam> beams = SimulateBeams(scene, synthesizer, 3, 1, 40, 42);
  tracer.Record(nullptr);
  synthesizer.VehicleTracer()->Record(nullptr);
  ASSERT_EQ(beams.size(), 2u);
  const std::size_t primaries = PrimaryRays(scene.sensor.acoustics);
  // Each beam: a bundle of its primaries against each tracer, then its mirror paths' streams.
  EXPECT_EQ(vehicle_log.RayCount(), 2 * primaries);
  EXPECT_GT(log.RayCount(), 4 * primaries);
  EXPECT_EQ(log.RayCount() + vehicle_log.RayCount(), beams[0].traced_rays + beams[1].traced_rays);
  EXPECT_THROW((void)SimulateBeams(scene, synthesizer, 3, 1, 42, 40), std::invalid_argument);
}

// The pattern's bound, which culls the mirror paths' straight returns before their
// trigonometry, is never under the pattern, ahead or behind, with or without sidelobes and a
// back lobe, over 20000 random directions; and it culls: 20° off the axis ahead, where the
// tank's 3° main lobe without its sidelobes is e^-62 one way, it is under 1e-20.
TEST(BeamSynthesis, OneWayPatternBoundIsNeverUnderThePattern) {
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const SensorModel tank_sensor = LoadScene(test::SourcePath("scenes/cras-tank.yaml")).sensor;
  const SensorModel main_lobe = [&] {
    SensorModel sensor = tank_sensor;
    sensor.acoustics.sidelobe_extent_deg = 0.0;
    return sensor;
  }();
  for (const SensorModel* with : {&tank_sensor, &main_lobe}) {
    const char* what = with == &main_lobe ? "the tank without sidelobes" : "the tank";
    for (const bool back_lobe : {true, false}) {
      SensorModel sensor = *with;
      if (!back_lobe) sensor.acoustics.back_lobe_width_deg = 0.0;
      const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
      Rng rng(91);
      for (int i = 0; i < 20000; ++i) {
        const Eigen::Vector3d u =
            Eigen::Vector3d(rng.Normal(), rng.Normal(), rng.Normal()).normalized();
        const double pattern = synthesizer.OneWayPatternTowards(u);
        ASSERT_GE(synthesizer.OneWayPatternBound(u), pattern * (1.0 - 1e-12))
            << what << (back_lobe ? "" : " without its back lobe") << ", towards " << u.transpose();
        if (u.x() <= 0.0 && !back_lobe) {
          EXPECT_EQ(pattern, 0.0);
        }
      }
    }
  }
  const BeamSynthesizer tank(main_lobe, tracer, {Material{}});
  const double off = 20.0 * kDegToRad;
  EXPECT_LT(tank.OneWayPatternBound({std::cos(off), std::sin(off), 0.0}), 1e-20);
  EXPECT_EQ(tank.OneWayPatternBound(Eigen::Vector3d::UnitX()), 1.0);
}

// Echo boxes summed by their edges give each bin what the box covers of it, as the direct sum
// over the bins would: boxes inside one bin, across many, starting before bin 0 and running
// past the last. The two differ only by rounding: each bin's sum is a running sum over at most
// 2 · 500 edges, so within 1000 · 2^-52 < 1e-12 of the total power; and bins no box reaches
// hold exactly 0.
TEST(PulseSpreader, SpreadsEachBoxOverTheBinsItCovers) {
  constexpr std::size_t kBins = 120;
  Rng rng(5);
  PulseSpreader spreader(kBins);
  std::vector<double> direct(kBins, 0.0);
  double total = 0.0;
  for (int box = 0; box < 500; ++box) {
    // Boxes between bins -2 and 100 (none reaches bins 105 on), half a bin to 5 bins long
    // and powers over six decades.
    const double start = 102.0 * rng.Uniform() - 2.0;
    const double end = start + (box % 10 == 0 ? 0.3 : 0.5 + 4.5 * rng.Uniform());
    const double power = std::pow(10.0, 6.0 * rng.Uniform() - 3.0);
    spreader.Add(start, end, power);
    total += power * (end - start);
    for (std::size_t k = 0; k < kBins; ++k) {
      const double overlap =
          std::min(static_cast<double>(k + 1), end) - std::max(static_cast<double>(k), start);
      if (overlap > 0.0) direct[k] += power * overlap;
    }
  }
  std::vector<double> spread(kBins, 0.0);
  spreader.AddTo(spread);
  for (std::size_t k = 0; k < kBins; ++k) {
    EXPECT_NEAR(spread[k], direct[k], 1e-12 * total) << "bin " << k;
    if (direct[k] == 0.0) {
      EXPECT_EQ(spread[k], 0.0) << "bin " << k;
    }
  }
  EXPECT_EQ(spread[kBins - 1], 0.0);
  // Emptied: a second read-out adds nothing.
  std::vector<double> again(kBins, 0.0);
  spreader.AddTo(again);
  EXPECT_EQ(again, std::vector<double>(kBins, 0.0));
}

// The synthesis quantises powers without a logarithm and takes range losses from a table:
// the same AD step as the dB formula for powers across and beyond the AD window (away from
// the steps' edges, where the two roundings may differ by one ulp), and the loss within its
// stated 1e-4 of the exact one, for the default sensor and for one whose spreading exceeds its
// TVG by 20 dB per decade (the table's steepest case).
TEST(BeamSynthesis, QuantisedPowersAndTabledLossesMatchTheirFormulas) {
  std::vector<TriangleMesh> meshes = Wall(1.0, 0.0);
  const RayTracer tracer(meshes);
  SensorModel sensor;
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  const Acoustics& a = sensor.acoustics;
  int compared = 0;
  for (double db = a.ad_low_db - 20.0; db <= a.ad_low_db + a.ad_span_db + 20.0; db += 0.0137) {
    const double steps = (db - a.ad_low_db) / a.ad_span_db * 255.0;
    if (std::abs(steps - std::round(steps - 0.5) - 0.5) < 1e-9) continue;  // on an edge
    ASSERT_EQ(synthesizer.QuantisePower(std::pow(10.0, db / 10.0)), synthesizer.Quantise(db))
        << db << " dB";
    ++compared;
  }
  EXPECT_GT(compared, 5000);
  EXPECT_EQ(synthesizer.QuantisePower(0.0), 0);
  // AD windows of other spans: the table's buckets narrow with the step, the result stays exact.
  for (const double span : {3.0, 120.0}) {
    SensorModel other = sensor;
    other.acoustics.ad_span_db = span;
    const BeamSynthesizer s(other, tracer, {Material{}});
    for (double db = a.ad_low_db - 5.0; db <= a.ad_low_db + span + 5.0; db += span / 2917.0) {
      const double steps = (db - a.ad_low_db) / span * 255.0;
      if (std::abs(steps - std::round(steps - 0.5) - 0.5) < 1e-9) continue;
      ASSERT_EQ(s.QuantisePower(std::pow(10.0, db / 10.0)), s.Quantise(db))
          << db << " dB, span " << span;
    }
  }
  for (const double spreading : {a.spreading_db_per_decade, a.tvg_db_per_decade + 20.0}) {
    SensorModel steep = sensor;
    steep.acoustics.spreading_db_per_decade = spreading;
    const BeamSynthesizer s(steep, tracer, {Material{}});
    const double bin = steep.geometry.bin_size_m;
    for (double r = 0.5 * bin; r <= steep.geometry.MaxRangeM() + 2 * bin; r += 0.0173 * bin) {
      const double exact = s.RangeLoss(r);
      ASSERT_NEAR(s.RangeLossFromTable(r), exact, 1e-4 * exact) << r << " m, S " << spreading;
    }
  }
}

// Frozen speckle: with a correlation length, two pings from the same pose and head angle but
// different ping seeds hear the same echo (same ray jitter, same speckle) and differ only by
// background noise: with the noise 300 dB down, byte for byte. Another run seed, or no
// correlation length, gives other speckle. Along a wall at normal incidence (the same echo from
// anywhere along it), a 2 cm move within the 5 cm cell keeps the speckle, a move into the next
// cell draws new speckle on most of the wall's bins.
TEST(BeamSynthesis, SpeckleIsFrozenPerPlaceWithACorrelationLength) {
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  Material wall;
  wall.reflectivity = 0.5;
  SensorModel sensor;
  sensor.acoustics.noise_level_db = -300.0;
  sensor.acoustics.speckle_correlation_m = 0.05;
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
  sensor.acoustics.speckle_correlation_m = 0.0;
  const BeamSynthesizer fresh(sensor, tracer, {wall}, 7);
  EXPECT_NE(fresh.Synthesize(0.0, 0.0, here, 1).beam.intensities,
            fresh.Synthesize(8.5, 0.0, here, 2).beam.intensities);
}

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
  sensor.acoustics.speckle_correlation_m = 0.05;
  sensor.acoustics.level_jitter_db = 2.0;
  sensor.acoustics.level_jitter_bin_correlation = bin_correlation;
  const Acoustics& a = sensor.acoustics;
  const double sigma = a.level_jitter_db;
  const double step = a.ad_span_db / 255.0;
  const BeamSynthesizer synthesizer(sensor, tracer, {wall}, 7);
  const auto reference = synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 0);
  // Bins whose exact level lies 4σ inside the AD window: no clipping at 0 or 255.
  std::vector<std::size_t> bright;
  std::vector<double> exact_db;
  for (std::size_t k = 0; k < reference.echo_power.size(); ++k) {
    const double p = reference.echo_power[k];
    if (p <= 0.0) continue;
    const double db = 10.0 * std::log10(p);
    if (db < a.ad_low_db + 4.0 * sigma || db > a.ad_low_db + a.ad_span_db - 4.0 * sigma) continue;
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
      const double level = a.ad_low_db + beam.beam.intensities[bright[i]] * step;
      out.deviations.push_back(level - exact_db[i]);
      for (std::size_t lag = 1; lag <= 2 && lag <= i; ++lag) {
        if (bright[i] != bright[i - lag] + lag) continue;
        out.lag_products[lag] += out.deviations.back() * out.deviations[first + i - lag];
        out.lag_pairs[lag] += 1.0;
      }
    }
  }
  double table_variance = 0.0;
  for (int i = 0; i < BeamSynthesizer::kLevelJitters; ++i) {
    const double z = BeamSynthesizer::NormalQuantile((i + 0.5) / BeamSynthesizer::kLevelJitters);
    table_variance += z * z / BeamSynthesizer::kLevelJitters;
  }
  out.jitter_variance = sigma * sigma * table_variance;
  out.expected_variance = out.jitter_variance + step * step / 12.0;
  EXPECT_EQ(synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 3).beam.intensities,
            synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 3).beam.intensities);
  return out;
}

// Independent bin by bin (level_jitter_bin_correlation 0), the deviations:
//  - are normal with mean 0 and the expected variance: mean within 5 standard errors, variance
//    within 5 of its own (σ² √(2/n)), a false alarm under 1e-5 each;
//  - KS against the normal at a 0.1% false-alarm rate (1.949/√n), plus the rounding's most
//    (half a step moves the distribution by at most φ(0) s / 2σ) and the table's 1/4096;
//  - neighbouring bins' deviations are uncorrelated (within 5/√n);
// and the same seed gives the same beam.
TEST(BeamSynthesis, LevelJitterIsTheReceiversPerBinAndPerPing) {
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
  const double step = QuietSensor().acoustics.ad_span_db / 255.0;
  const double rounding = 0.5 * step / sigma / std::sqrt(2.0 * std::numbers::pi);
  std::vector<double> z;
  for (double d : m.deviations) z.push_back(d / sigma);
  EXPECT_LT(KsDistance(z, [](double x) { return 0.5 * std::erfc(-x / std::numbers::sqrt2); }),
            1.949 / std::sqrt(n) + rounding + 1.0 / BeamSynthesizer::kLevelJitters);
  ASSERT_GT(m.lag_pairs[1], 1000.0);
  EXPECT_NEAR(m.lag_products[1] / m.lag_pairs[1] / expected, 0.0, 5.0 / std::sqrt(m.lag_pairs[1]));
}

// With level_jitter_bin_correlation ρ (0.4 here) each bin's draw is a z_k + b z_k+1 with
// a² + b² = 1 and a b = ρ: its variance is unchanged (within 5 of its standard errors), the
// deviations of neighbouring bins covary by ρ σ² v (v the table's variance), so correlate by
// ρ σ² v / (σ² v + s²/12), and bins two apart do not correlate; each within 5/√pairs (the
// sample correlation's standard error is at most 1/√pairs), a false alarm under 1e-6 each. A
// draw shared whole (a = b) would correlate by 0.5, one not shared by 0: both fail.
TEST(BeamSynthesis, LevelJitterCorrelatesNeighbouringBinsAsConfigured) {
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

// The speckle and noise draws are exponential with mean 1 (the power of a Rayleigh amplitude).
// Kolmogorov-Smirnov against F(x) = 1 - exp(-x) on 200000 draws, fixed seed: the critical value
// at a 0.1% false-alarm rate is 1.949 / sqrt(n).
TEST(Rng, ExponentialDrawsFollowTheirDistribution) {
  constexpr int kDraws = 200000;
  Rng rng(12345);
  std::vector<double> x(kDraws);
  for (double& v : x) v = rng.Exponential();
  EXPECT_LT(KsDistance(x, [](double v) { return 1.0 - std::exp(-v); }),
            1.949 / std::sqrt(static_cast<double>(kDraws)));
}

// The ziggurat's rare paths: the tail beyond its last edge R = 7.697 and the wedges between
// layers. Over 4 M draws, the counts beyond R, beyond 10 and in (1, 1.01] are binomial with
// p = e^-R, e^-10 and e^-1 - e^-1.01; each must lie within 3.29 standard deviations of n·p (a
// 0.1% false-alarm rate each, two-sided), fixed seed.
TEST(Rng, ExponentialTailAndWedgesHaveTheirProbabilities) {
  constexpr double kDraws = 4e6;
  Rng rng(4242);
  double beyond_r = 0;
  double beyond_10 = 0;
  double in_wedge = 0;
  for (int i = 0; i < static_cast<int>(kDraws); ++i) {
    const double x = rng.Exponential();
    ASSERT_GE(x, 0.0);
    beyond_r += x > ExponentialZiggurat::kR ? 1 : 0;
    beyond_10 += x > 10.0 ? 1 : 0;
    in_wedge += (x > 1.0 && x <= 1.01) ? 1 : 0;
  }
  for (const auto& [count, p] : {std::pair{beyond_r, std::exp(-ExponentialZiggurat::kR)},
                                 std::pair{beyond_10, std::exp(-10.0)},
                                 std::pair{in_wedge, std::exp(-1.0) - std::exp(-1.01)}}) {
    const double mean = kDraws * p;
    EXPECT_NEAR(count, mean, 3.29 * std::sqrt(mean * (1 - p))) << "p " << p;
  }
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
TEST(BeamSynthesis, SpeckleIsExponentialAndCorrelatedOverThePulse) {
  constexpr int kWindow = 4;
  Rng rng(2024);
  std::vector<double> factors(800000);
  BeamSynthesizer::CorrelatedSpeckle(factors, kWindow, rng);
  std::vector<double> independent;
  for (std::size_t k = 0; k < factors.size(); k += kWindow) independent.push_back(factors[k]);
  const auto n = static_cast<double>(independent.size());
  EXPECT_LT(KsDistance(independent, [](double v) { return 1.0 - std::exp(-v); }),
            1.949 / std::sqrt(n) + 1.0 / BeamSynthesizer::kSpecklePhases);

  double first = 0.0;
  constexpr int kFresh = 20000;
  for (int i = 0; i < kFresh; ++i) {
    std::array<double, 1> one{};
    BeamSynthesizer::CorrelatedSpeckle(one, kWindow, rng);
    first += one[0];
  }
  EXPECT_NEAR(first / kFresh, 1.0, 5.0 / std::sqrt(static_cast<double>(kFresh)));

  ExpectCorrelatedOverTheWindow(kWindow, [&](std::vector<double>& x) {
    BeamSynthesizer::CorrelatedSpeckle(x, kWindow, rng);
  });

  Rng a(7);
  Rng b(7);
  std::vector<double> single(100);
  BeamSynthesizer::CorrelatedSpeckle(single, 1, a);
  for (double v : single) EXPECT_EQ(v, b.Exponential());
}

// The speckle's window is the range response's extent in bins: the pulse (5 cm, 4 bins of
// 1.2531 cm) alone, or with skirts the pulse and one e-folding of each (5 + 2 · 5 cm: 12 bins),
// rounded; a pulse shorter than half a bin still has a window of one.
TEST(BeamSynthesis, SpeckleWindowSpansThePulseAndItsSkirts) {
  SensorModel sensor;
  sensor.acoustics.pulse_length_m = 0.05;
  const RayTracer tracer(Wall(1.0, 0.0));
  EXPECT_EQ(BeamSynthesizer(sensor, tracer, {Material{}}).SpeckleWindow(), 4);
  sensor.acoustics.pulse_skirt_length_m = 0.05;
  EXPECT_EQ(BeamSynthesizer(sensor, tracer, {Material{}}).SpeckleWindow(), 12);
  sensor.acoustics.pulse_skirt_length_m = 0.0;
  sensor.acoustics.pulse_length_m = 0.005;
  EXPECT_EQ(BeamSynthesizer(sensor, tracer, {Material{}}).SpeckleWindow(), 1);
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
TEST(BeamSynthesis, AngularCorrelationConvolvesTheSectorsWithAnExponential) {
  SensorModel micron = QuietSensor();
  micron.acoustics.speckle_correlation_m = 0.05;
  const std::vector<TriangleMesh> none;
  const RayTracer tracer(none);
  const std::vector<double> p = BeamSynthesizer(micron, tracer, {Material{}}).SectorWeights();
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
    micron.acoustics.speckle_angular_correlation_deg = degrees;
    const std::vector<double> w = BeamSynthesizer(micron, tracer, {Material{}}).SectorWeights();
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
TEST(BeamSynthesis, NeighbouringBeamsShareTheirSectorsSpeckle) {
  const SensorModel micron = QuietSensor();
  const std::vector<TriangleMesh> none;
  const RayTracer tracer(none);
  const BeamSynthesizer synthesizer(micron, tracer, {Material{}});
  const std::vector<double>& w = synthesizer.SectorWeights();
  ASSERT_EQ(w.size(), 2u * BeamSynthesizer::kPatternReach + 1);
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
  BeamSynthesizer::CorrelatedSpeckle(direct, kWindow, rng);
  const std::array<double, 1> one = {1.0};
  const std::array<std::uint64_t, 1> seed = {99};
  BeamSynthesizer::SectorSpeckle(sector, kWindow, one, seed);
  EXPECT_EQ(direct, sector);

  const std::vector<double> independent = ExpectNeighboursShareSectors(w, kWindow, 1, 1000);
  const auto n = static_cast<double>(independent.size());
  EXPECT_LT(KsDistance(independent, [](double v) { return 1.0 - std::exp(-v); }),
            1.949 / std::sqrt(n) + 1.0 / BeamSynthesizer::kSpecklePhases);
}

// With Acoustics::speckle_own_share ν each head step hears ν of its speckle's power on its own:
//  - the weights are the sectors' times √(1 - ν), then √ν, the beam's own: squares summing to 1;
//  - two beams one sector apart, each with its own last seed, correlate by ((1 - ν) ρ)², ρ the
//    sectors' Σ w_d w_{d+1} without it (64 pairs, as above), and each beam's factors stay
//    exponential of mean 1 (KS, as above).
TEST(BeamSynthesis, EachHeadStepHearsItsOwnShareOfTheSpeckle) {
  SensorModel micron = QuietSensor();
  const std::vector<TriangleMesh> none;
  const RayTracer tracer(none);
  const std::vector<double> sectors = BeamSynthesizer(micron, tracer, {Material{}}).SectorWeights();
  constexpr double kOwn = 0.3;
  micron.acoustics.speckle_own_share = kOwn;
  const std::vector<double> w = BeamSynthesizer(micron, tracer, {Material{}}).SectorWeights();
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
            1.949 / std::sqrt(n) + 1.0 / BeamSynthesizer::kSpecklePhases);
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
TEST(BeamSynthesis, SpeckleLooksAreIndependentLooksAveraged) {
  constexpr int kWindow = 4;
  constexpr int kLooks = 3;
  const auto gamma_cdf = [](double x) {
    const double t = kLooks * x;
    return 1.0 - std::exp(-t) * (1.0 + t + 0.5 * t * t);
  };
  const auto expect_gamma = [&](const std::vector<double>& sample) {
    EXPECT_LT(KsDistance(sample, gamma_cdf),
              1.949 / std::sqrt(static_cast<double>(sample.size())) +
                  static_cast<double>(kLooks) / BeamSynthesizer::kSpecklePhases);
  };

  const std::array<std::uint64_t, 2> seeds = {11, 12};
  const std::array<double, 2> weights = {0.6, 0.8};
  std::vector<double> averaged(300);
  BeamSynthesizer::SectorSpeckle(averaged, kWindow, weights, seeds, kLooks);
  std::vector<double> sum(300);
  std::vector<double> look(300);
  BeamSynthesizer::SectorSpeckle(sum, kWindow, weights, seeds);
  for (std::uint64_t l = 1; l < kLooks; ++l) {
    const std::array<std::uint64_t, 2> look_seeds = {DeriveSeed(11, l), DeriveSeed(12, l)};
    BeamSynthesizer::SectorSpeckle(look, kWindow, weights, look_seeds);
    for (std::size_t k = 0; k < sum.size(); ++k) sum[k] += look[k];
  }
  for (std::size_t k = 0; k < sum.size(); ++k) {
    EXPECT_EQ(averaged[k], sum[k] * (1.0 / kLooks)) << "bin " << k;
  }

  Rng rng(2025);
  std::vector<double> independent;
  ExpectCorrelatedOverTheWindow(kWindow, [&](std::vector<double>& x) {
    BeamSynthesizer::CorrelatedSpeckle(x, kWindow, rng, kLooks);
    for (std::size_t k = 0; k < x.size(); k += kWindow) independent.push_back(x[k]);
  });
  expect_gamma(independent);

  const SensorModel micron = QuietSensor();
  const std::vector<TriangleMesh> none;
  const RayTracer tracer(none);
  const BeamSynthesizer synthesizer(micron, tracer, {Material{}});
  const std::vector<double>& w = synthesizer.SectorWeights();
  expect_gamma(ExpectNeighboursShareSectors(w, kWindow, kLooks, 5000));
}

TEST(BeamSynthesis, NoiseFloorMatchesItsConfiguredDistribution) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.noise_level_db = -43.0;
  const Acoustics& a = sensor.acoustics;
  const std::vector<TriangleMesh> meshes = Wall(100.0, 0.0);  // out of range: no echo
  const RayTracer tracer(meshes);
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  // Byte 0 means a level under ad_low + half a step (rounding).
  const double floor_power = std::pow(10.0, (a.ad_low_db + 0.5 * a.ad_span_db / 255.0) / 10.0);
  const double p = 1.0 - std::exp(-floor_power / std::pow(10.0, a.noise_level_db / 10.0));
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
TEST(BeamSynthesis, NoiseBeforeTheGainRisesWithRangeAsTheGainDoes) {
  SensorModel sensor = QuietSensor();
  Acoustics& a = sensor.acoustics;
  a.noise_level_db = -46.0;
  const std::vector<TriangleMesh> meshes = Wall(100.0, 0.0);  // out of range: no echo
  const RayTracer tracer(meshes);
  const BeamSynthesizer output_only(sensor, tracer, {Material{}});
  a.noise_before_tvg_db = -100.0;
  const BeamSynthesizer none(sensor, tracer, {Material{}});
  a.noise_before_tvg_db = -50.0;
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  const double floor_power = std::pow(10.0, (a.ad_low_db + 0.5 * a.ad_span_db / 255.0) / 10.0);
  const double n_power = std::pow(10.0, a.noise_level_db / 10.0);
  const double p_power = std::pow(10.0, a.noise_before_tvg_db / 10.0);
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

TEST(BeamSynthesis, NothingInRangeGivesOnlyTheNoiseFloor) {
  const SensorModel sensor = QuietSensor();
  const SynthesizedBeam beam = Ping(sensor, Wall(sensor.geometry.MaxRangeM() + 1.0, 0.0));
  EXPECT_FALSE(beam.truth.first_hit_range_m.has_value());
  for (double p : beam.echo_power) EXPECT_EQ(p, 0.0);
  for (auto v : beam.beam.intensities) EXPECT_EQ(v, 0);
}

// The receiver's blanking (blanking_range_m 0.025 with bins of 0.012531 m): bins 0 and 1 begin
// within it and read 0, bin 2 (from 0.0251 m) does not; under noise that lights every bin (0 dB,
// the AD window's top) the blanked beam is the plain one with those two bins zeroed, since the
// draws are the same.
TEST(BeamSynthesis, BlankingZeroesTheBinsThatBeginWithinIt) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.noise_level_db = 0.0;
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const BeamSynthesizer plain(sensor, tracer, {Material{}});
  sensor.acoustics.blanking_range_m = 0.025;
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

TEST(BeamSynthesis, QuantisationFollowsTheAdWindow) {
  const SensorModel sensor = QuietSensor();
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  const Acoustics& a = sensor.acoustics;
  EXPECT_EQ(synthesizer.Quantise(a.ad_low_db - 1.0), 0);
  EXPECT_EQ(synthesizer.Quantise(a.ad_low_db), 0);
  EXPECT_EQ(synthesizer.Quantise(a.ad_low_db + a.ad_span_db / 2), 128);  // 127.5 rounds up
  EXPECT_EQ(synthesizer.Quantise(a.ad_low_db + a.ad_span_db), 255);
  EXPECT_EQ(synthesizer.Quantise(a.ad_low_db + 2 * a.ad_span_db), 255);
}

// The receiver's ceiling: below its knee the AD window alone; above it the output
// knee + w·tanh((x - knee) / w) (w = ceiling - knee) of the window's step x, rounded, so a level
// x = knee + w·atanh((y - knee) / w) reports y; rising with the level and never past the
// ceiling, however strong the echo; the table-driven QuantisePower agreeing with it off the
// steps' edges; and with knee = ceiling, a hard clip.
TEST(BeamSynthesis, ReceiverCeilingCompressesAboveItsKneeAndNeverPassesIt) {
  SensorModel sensor = QuietSensor();
  Acoustics& a = sensor.acoustics;
  a.ad_knee = 170.0;
  a.ad_ceiling = 191.0;
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const BeamSynthesizer ceiling(sensor, tracer, {Material{}});
  const BeamSynthesizer plain(QuietSensor(), tracer, {Material{}});
  const auto level = [&](double steps) { return a.ad_low_db + steps / 255.0 * a.ad_span_db; };
  for (double x = 0.0; x < 169.5; x += 0.25) {
    ASSERT_EQ(ceiling.Quantise(level(x)), plain.Quantise(level(x))) << x;
  }
  const double w = a.ad_ceiling - a.ad_knee;
  for (const int y : {171, 175, 180, 185, 190}) {
    EXPECT_EQ(ceiling.Quantise(level(a.ad_knee + w * std::atanh((y - a.ad_knee) / w))), y);
  }
  EXPECT_EQ(ceiling.Quantise(level(255.0)), 191);
  EXPECT_EQ(ceiling.Quantise(level(2000.0)), 191);  // 314 dB over the window's foot
  int previous = 0;
  int compared = 0;
  for (double x = -10.0; x < 600.0; x += 0.0137) {
    const int q = ceiling.Quantise(level(x));
    ASSERT_GE(q, previous) << x;
    ASSERT_LE(q, 191) << x;
    previous = q;
    const double y = x <= a.ad_knee ? x : a.ad_knee + w * std::tanh((x - a.ad_knee) / w);
    if (std::abs(y - std::round(y - 0.5) - 0.5) < 1e-9) continue;  // on an edge
    ASSERT_EQ(ceiling.QuantisePower(std::pow(10.0, level(x) / 10.0)), q) << x;
    ++compared;
  }
  EXPECT_EQ(previous, 191);
  EXPECT_GT(compared, 40000);

  a.ad_knee = 191.0;
  const BeamSynthesizer clip(sensor, tracer, {Material{}});
  EXPECT_EQ(clip.Quantise(level(190.4)), 190);
  EXPECT_EQ(clip.Quantise(level(190.6)), 191);
  EXPECT_EQ(clip.Quantise(level(300.0)), 191);
  EXPECT_EQ(clip.QuantisePower(std::pow(10.0, level(190.4) / 10.0)), 190);
  EXPECT_EQ(clip.QuantisePower(std::pow(10.0, level(300.0) / 10.0)), 191);
}

// The converter's readings (Acoustics::ad_levels 160, the real log's): the window's level
// rounded to steps of 255/160 intensity units, reading k reported as floor(k · 255 / 160). Over
// a fine sweep of levels the values reported are exactly those of k = 0..160 (161 of the 256),
// never decreasing; reading k begins at (k - ½) · 255/160 units (a level just under it reports
// k - 1's value, just over it k's); QuantisePower agrees with Quantise off the readings' edges;
// under the tank's ceiling (knee 100, ceiling 191) the highest value is 191, reading 120, as in
// the real log.
TEST(BeamSynthesis, ConverterReadingsAreReportedOnThe8BitScale) {
  SensorModel sensor = QuietSensor();
  Acoustics& a = sensor.acoustics;
  a.ad_levels = 160;
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const BeamSynthesizer converter(sensor, tracer, {Material{}});
  const auto level = [&](double steps) { return a.ad_low_db + steps / 255.0 * a.ad_span_db; };
  const double step = 255.0 / 160.0;
  std::set<int> expected;
  for (int k = 0; k <= 160; ++k) expected.insert(k * 255 / 160);
  std::set<int> seen;
  int previous = 0;
  int compared = 0;
  for (double x = -5.0; x < 270.0; x += 0.0137) {
    const int v = converter.Quantise(level(x));
    ASSERT_GE(v, previous) << x;
    previous = v;
    seen.insert(v);
    const double reading = x / step;
    if (std::abs(reading - std::round(reading - 0.5) - 0.5) < 1e-9) continue;  // on an edge
    ASSERT_EQ(converter.QuantisePower(std::pow(10.0, level(x) / 10.0)), v) << x;
    ++compared;
  }
  EXPECT_EQ(seen, expected);
  EXPECT_GT(compared, 15000);
  for (const int k : {1, 2, 5, 80, 159, 160}) {
    EXPECT_EQ(converter.Quantise(level((k - 0.5) * step - 1e-6)), (k - 1) * 255 / 160) << k;
    EXPECT_EQ(converter.Quantise(level((k - 0.5) * step + 1e-6)), k * 255 / 160) << k;
  }
  a.ad_knee = 100.0;
  a.ad_ceiling = 191.0;
  const BeamSynthesizer tank(sensor, tracer, {Material{}});
  EXPECT_EQ(tank.Quantise(level(2000.0)), 191);
  EXPECT_EQ(tank.QuantisePower(std::pow(10.0, level(2000.0) / 10.0)), 191);
}

// A wall 20 dB over the window's top, pinged: without a ceiling its echo clips at 255; under a
// ceiling of 191 (knee 170) it crowds just under 191, and no bin passes it.
TEST(BeamSynthesis, ASaturatingEchoStaysUnderTheReceiversCeiling) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.gain_db = 40.0;
  const std::vector<TriangleMesh> wall = Wall(2.0, 0.0);
  const SynthesizedBeam open = Ping(sensor, wall);
  EXPECT_EQ(*std::ranges::max_element(open.beam.intensities), 255);
  sensor.acoustics.ad_knee = 170.0;
  sensor.acoustics.ad_ceiling = 191.0;
  const SynthesizedBeam capped = Ping(sensor, wall);
  EXPECT_EQ(*std::ranges::max_element(capped.beam.intensities), 191);
  EXPECT_EQ(capped.echo_power, open.echo_power);  // the ceiling is the receiver's, not the echo's
}

// A plate `height` m tall facing the sonar from `range` m along azimuth `azimuth_rad`, spanning
// azimuths azimuth ± half_angle_rad (a chord, so its edges lie exactly on those bearings).
std::vector<TriangleMesh> Plate(double range, double azimuth_rad, double half_angle_rad,
                                double height) {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kPlane;
  spec.size_m = {height, 2.0 * range * std::tan(half_angle_rad), 0.0};
  spec.T_world_mesh =
      mapping::PoseFromXyzRpy({range * std::cos(azimuth_rad), range * std::sin(azimuth_rad), 0},
                              {0, 0, 0}) *
      Eigen::AngleAxisd(azimuth_rad, Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY());
  return {BuildMesh(spec, 0)};
}

// The total echo power of Ping's beam over the pings of seeds 1-64: their strata's jitter
// averaged out.
double TotalPowerOverPings(const SensorModel& sensor, const std::vector<TriangleMesh>& meshes) {
  double total = 0.0;
  for (std::uint64_t seed = 1; seed <= 64; ++seed) total += TotalPower(Ping(sensor, meshes, seed));
  return total;
}

// ∫ f over [from, to] by the midpoint rule, 20000 steps.
template <typename F>
double Midpoint(double from, double to, const F& f) {
  constexpr int kSteps = 20000;
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) sum += f(from + (i + 0.5) / kSteps * (to - from));
  return sum * (to - from) / kSteps;
}

// Sidelobes: plates facing the sonar 2 m out, each taller than the fan, return echo powers in
// the ratio of the two-way horizontal pattern's integrals over their bearings, exp(-4 ln2
// θ²/w²) + S (θ_s² / (θ_s² + θ²))²: one over the main lobe's rays (±1.5°), one at 8-12° to the
// left, one at 18-22° to the right (where only sidelobe rays, 0.5° strata with a quarter of the
// main lobe's vertical strata, reach). No range loss (spreading = TVG, no absorption) and
// incidence within 2° of normal (cos ≥ 0.9994), so the ratios are the pattern's, averaged over
// 64 pings: 1% holds their sampling (under 0.1%, one standard error) many times over. Without
// sidelobes the side plates are not heard at all.
TEST(BeamSynthesis, SidelobesHearPlatesOffTheAxisAsThePatternSays) {
  SensorModel sensor = QuietSensor();
  Acoustics& a = sensor.acoustics;
  a.sidelobe_extent_deg = 24.0;  // (24 - 1.5) / 45: 0.5° strata, edges on whole half degrees
  a.sidelobe_db = -20.0;
  a.sidelobe_width_deg = 5.0;
  a.sidelobe_rays_horizontal = 45;
  a.sidelobe_rays_vertical = 40;
  const double deg = mapping::kDegToRad;
  const double main_lobe = TotalPowerOverPings(sensor, Plate(2.0, 0.0, 1.5 * deg, 4.0));
  const double left = TotalPowerOverPings(sensor, Plate(2.0, 10.0 * deg, 2.0 * deg, 4.0));
  const double right = TotalPowerOverPings(sensor, Plate(2.0, -20.0 * deg, 2.0 * deg, 4.0));
  const double w = sensor.geometry.beam_width_horizontal_rad;
  const double s = std::pow(10.0, a.sidelobe_db / 10.0);
  const double ts2 = std::pow(a.sidelobe_width_deg * deg, 2);
  const auto integral = [&](double from_deg, double to_deg) {
    return Midpoint(from_deg * deg, to_deg * deg, [&](double theta) {
      const double falloff = ts2 / (ts2 + theta * theta);
      return std::exp(-4.0 * std::log(2.0) * theta * theta / (w * w)) + s * falloff * falloff;
    });
  };
  const double expected_left = integral(8.0, 12.0) / integral(-1.5, 1.5);
  const double expected_right = integral(18.0, 22.0) / integral(-1.5, 1.5);
  EXPECT_NEAR(left / main_lobe, expected_left, 0.01 * expected_left);
  EXPECT_NEAR(right / main_lobe, expected_right, 0.01 * expected_right);
  EXPECT_GT(expected_left / expected_right, 4.0);  // the falloff itself is what is measured

  SensorModel narrow = sensor;
  narrow.acoustics.sidelobe_extent_deg = 0.0;
  EXPECT_EQ(TotalPowerOverPings(narrow, Plate(2.0, 10.0 * deg, 2.0 * deg, 4.0)), 0.0);
}

// The first-hit truth is the main lobe's: a plate only the sidelobes reach, nearer than the
// wall ahead, is heard at its range but not reported as what the beam hit.
TEST(BeamSynthesis, SidelobesLeaveTheFirstHitToTheMainLobe) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.sidelobe_extent_deg = 24.0;
  sensor.acoustics.sidelobe_db = -10.0;
  const double deg = mapping::kDegToRad;
  std::vector<TriangleMesh> meshes = Wall(3.0, 0.0);
  meshes.push_back(Plate(1.0, 15.0 * deg, 3.0 * deg, 4.0).front());
  const RayTracer tracer(meshes);
  Material material;
  material.reflectivity = 0.5;
  const BeamSynthesizer synthesizer(sensor, tracer, {material, material});
  const SynthesizedBeam beam = synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 11);
  ASSERT_TRUE(beam.truth.first_hit_range_m.has_value());
  EXPECT_NEAR(*beam.truth.first_hit_range_m, 3.0, sensor.geometry.bin_size_m);
  EXPECT_EQ(beam.truth.first_hit_mesh, 0u);
  const auto plate_bin = static_cast<std::size_t>(1.0 / sensor.geometry.bin_size_m);
  EXPECT_GT(beam.echo_power[plate_bin + 1], 0.0);
}

// The back lobe, sent and heard: plates facing the sonar 1 m ahead and 1 m behind, each wider
// and taller than what its lobe's rays reach (the main lobe's ±1.5° × ±17.5°, the back lobe's
// ±60° either way at σ = 20°), return echo powers in the ratio of the two-way patterns'
// integrals over them, each ray's echo cos φ cos ε of the plate's (its incidence): B² ∬
// exp(-(φ² + ε²)/σ²) cos φ cos² ε dφ dε behind (a back-lobe stratum spans cos ε dφ dε) against
// ∬ exp(-k_h θ² - k_v ε²) cos θ cos ε dθ dε ahead, both separable. No range loss, the farthest
// echo at 1 / cos² 60° = 4 m (inside the 5 m of bins), and 64 pings: 1% holds the strata's
// sampling many times over, and a stratum's cos ε, 3% here, is outside it. Without a back lobe the
// plate behind is not heard, and the plate ahead is heard the same with or without it (the back
// lobe's weights stay out of the beam's normalisation).
TEST(BeamSynthesis, BackLobeHearsAPlateBehindAsItsPatternSays) {
  SensorModel sensor = QuietSensor();
  Acoustics& a = sensor.acoustics;
  a.back_lobe_width_deg = 20.0;
  a.back_lobe_db = -10.0;
  a.back_lobe_rays = 24;
  const double deg = mapping::kDegToRad;
  const double reach = std::tan(65.0 * deg);
  const std::vector<TriangleMesh> ahead = Plate(1.0, 0.0, 65.0 * deg, 2.0 * reach);
  const std::vector<TriangleMesh> behind = Plate(1.0, std::numbers::pi, 65.0 * deg, 2.0 * reach);
  const double main_lobe = TotalPowerOverPings(sensor, ahead);
  const double back_lobe = TotalPowerOverPings(sensor, behind);
  const auto integral = [deg](double half_deg, const auto& f) {
    return Midpoint(-half_deg * deg, half_deg * deg, f);
  };
  const double k_h = 4.0 * std::log(2.0) / std::pow(sensor.geometry.beam_width_horizontal_rad, 2);
  const double k_v = 4.0 * std::log(2.0) / std::pow(sensor.geometry.beam_width_vertical_rad, 2);
  const double expected_main =
      integral(1.5, [&](double t) { return std::exp(-k_h * t * t) * std::cos(t); }) *
      integral(17.5, [&](double e) { return std::exp(-k_v * e * e) * std::cos(e); });
  const double k_b = 1.0 / std::pow(20.0 * deg, 2);
  const double expected_back =
      std::pow(10.0, 2.0 * a.back_lobe_db / 10.0) *
      integral(60.0, [&](double p) { return std::exp(-k_b * p * p) * std::cos(p); }) *
      integral(60.0, [&](double e) { return std::exp(-k_b * e * e) * std::pow(std::cos(e), 2); });
  EXPECT_NEAR(back_lobe / main_lobe, expected_back / expected_main,
              0.01 * expected_back / expected_main);

  SensorModel none = sensor;
  none.acoustics.back_lobe_width_deg = 0.0;
  EXPECT_EQ(TotalPowerOverPings(none, behind), 0.0);
  EXPECT_EQ(TotalPowerOverPings(none, ahead), main_lobe);
}

// A mirror path's last leg heard behind: a mirror 1 m ahead (no echo of its own) sends each
// ray back past the sonar to a plate 2 m behind it (no mirror), whose echo straight back comes
// from behind at (4 + 2) / 2 = 3 m. It is heard through the back lobe's one-way pattern B (and,
// by reciprocity, sent through it), so its power is B's: 10 times as much at -10 dB as at -20
// dB, to rounding (the rays and their normalisation are the same), and none without a back
// lobe. Nothing else lies at 2.9-3.6 m: the plate's own echoes through the back lobe end before
// 2 / cos² 30° + the pulse = 2.72 m, the mirror path back the way it came is at 4 m.
TEST(BeamSynthesis, BackLobeHearsAMirrorPathsLastLegInProportionToItsLevel) {
  const double deg = mapping::kDegToRad;
  std::vector<TriangleMesh> meshes = Wall(1.0, 0.0);
  const double reach = std::tan(40.0 * deg) * 2.0;
  meshes.push_back(Plate(2.0, std::numbers::pi, 40.0 * deg, 2.0 * reach).front());
  const RayTracer tracer(meshes);
  Material mirror;
  mirror.reflectivity = 0.0;
  mirror.specular = 1.0;
  Material plate;
  plate.reflectivity = 0.5;
  const auto power_at_3m = [&](double back_lobe_width_deg, double back_lobe_db) {
    SensorModel sensor = QuietSensor();
    sensor.acoustics.max_bounces = 1;
    sensor.acoustics.back_lobe_width_deg = back_lobe_width_deg;
    sensor.acoustics.back_lobe_db = back_lobe_db;
    const BeamSynthesizer synthesizer(sensor, tracer, {mirror, plate});
    const SynthesizedBeam beam =
        synthesizer.Synthesize(0.0, 0.0, Eigen::Isometry3d::Identity(), 11);
    const double bin = sensor.geometry.bin_size_m;
    double sum = 0.0;
    for (auto k = static_cast<std::size_t>(2.9 / bin); k < static_cast<std::size_t>(3.6 / bin);
         ++k) {
      sum += beam.echo_power[k];
    }
    return sum;
  };
  const double at_10 = power_at_3m(10.0, -10.0);
  const double at_20 = power_at_3m(10.0, -20.0);
  EXPECT_GT(at_20, 0.0);
  EXPECT_NEAR(at_10 / at_20, 10.0, 1e-9);
  EXPECT_EQ(power_at_3m(0.0, -10.0), 0.0);
}

// A sensor whose only return is a flat self-reflection profile, `bins` long at -21 dB: 19 dB
// above the AD window's foot, level 121.1 (quantised 121), clear of both ends by over 4σ for
// the spreads tested below (1.5 dB).
SensorModel RingingSensor(std::size_t bins) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.self_reflection_db.assign(bins, -21.0);
  return sensor;
}

// Per bin of the profile, a beam's level less the profile's, in dB (AD steps of span/255).
std::vector<double> RingingDeviations(const SensorModel& sensor, const SynthesizedBeam& beam) {
  const Acoustics& a = sensor.acoustics;
  std::vector<double> out;
  for (std::size_t k = 0; k < a.self_reflection_db.size(); ++k) {
    out.push_back(a.ad_low_db + beam.beam.intensities[k] * a.ad_span_db / 255.0 -
                  a.self_reflection_db[k]);
  }
  return out;
}

// The self-reflection is the sonar's own: the place's speckle, on here and drawn per ping,
// changes a wall's echo from ping to ping but leaves the ringing bins at the profile's level,
// whatever the ping and head angle.
TEST(BeamSynthesis, SelfReflectionIsTheSonarsOwnNotThePlacesSpeckle) {
  SensorModel sensor = RingingSensor(40);
  sensor.acoustics.speckle = true;
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
TEST(BeamSynthesis, SelfReflectionVariesFromPingToPingInItsRingingBins) {
  SensorModel sensor = RingingSensor(40);
  Acoustics& a = sensor.acoustics;
  a.self_reflection_ping_spread_db = 1.5;
  a.self_reflection_ringing_range_m = 20 * sensor.geometry.bin_size_m;
  const std::vector<TriangleMesh> none;
  const RayTracer tracer(none);
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  const double sigma = a.self_reflection_ping_spread_db;
  const double step = a.ad_span_db / 255.0;
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
  const double shift = 0.5 * BeamSynthesizer::kNepersPerDecibel * sigma * sigma;
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
  const double c = BeamSynthesizer::kNepersPerDecibel * sigma;  // the factor's log-sd
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
TEST(BeamSynthesis, SelfReflectionVariesWithHeadAngleAlikeSweepAfterSweep) {
  constexpr std::size_t kBins = 200;
  SensorModel sensor = RingingSensor(kBins);
  Acoustics& a = sensor.acoustics;
  a.self_reflection_angle_spread_db = 1.5;
  a.self_reflection_angle_correlation_deg = 5.0;
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
  const double sigma = a.self_reflection_angle_spread_db;
  const double step = a.ad_span_db / 255.0;
  const double q = std::exp(-sensor.geometry.step_angle_rad /
                            (a.self_reflection_angle_correlation_deg * kDegToRad));
  const auto r_c = [&](int m) {
    return std::pow(q, std::abs(m)) * (1.0 + std::abs(m) * (1.0 - q * q) / (1.0 + q * q));
  };
  double rho_squares = 0.0;  // over steps and the bins' lags 0 and ±1
  for (int m = -turn / 2; m < turn / 2; ++m) rho_squares += 1.5 * r_c(m) * r_c(m);
  const double n = static_cast<double>(turn) * kBins;
  double sum = 0.0;
  for (const auto& row : dev) sum += std::accumulate(row.begin(), row.end(), 0.0);
  const double mean = sum / n;
  EXPECT_NEAR(mean, -0.5 * BeamSynthesizer::kNepersPerDecibel * sigma * sigma,
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

TEST(Simulation, SameSeedSameBytesWhateverTheThreadCount) {
  Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  scene.sweeps = 1;
  const auto meshes = BuildSceneMeshes(scene);
  const RayTracer tracer(meshes);
  const auto one = SimulateScene(scene, tracer, 5, 1);
  const auto two = SimulateScene(scene, tracer, 5, 2);
  const auto other_seed = SimulateScene(scene, tracer, 6, 2);
  ASSERT_EQ(one.size(), 200u);
  ASSERT_EQ(two.size(), one.size());
  bool differs_with_seed = false;
  for (std::size_t b = 0; b < one.size(); ++b) {
    ASSERT_EQ(one[b].beam.intensities, two[b].beam.intensities) << "beam " << b;
    differs_with_seed |= one[b].beam.intensities != other_seed[b].beam.intensities;
  }
  EXPECT_TRUE(differs_with_seed);
}

// A scenario's beams drop their echo power; dropping it changes nothing else: the beams equal
// those synthesised one by one with it kept, and the kept echo power is the beam's.
TEST(Simulation, BeamsDropTheirEchoPowerAndNothingElse) {
  Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  scene.sweeps = 1;
  const auto meshes = BuildSceneMeshes(scene);
  const RayTracer tracer(meshes);
  const BeamSynthesizer synthesizer = SceneSynthesizer(scene, tracer, 5);
  const auto run = SimulateBeams(scene, synthesizer, 5, 2, 40, 60);
  ASSERT_EQ(run.size(), 20u);
  for (std::size_t b = 0; b < run.size(); ++b) {
    const ScheduledBeam s = ScheduleBeam(scene, 40 + b);
    const SynthesizedBeam kept = synthesizer.Synthesize(
        s.time_s, s.pose.head_angle_rad, s.pose.T_world_sonar, DeriveSeed(5, 40 + b));
    EXPECT_TRUE(run[b].echo_power.empty());
    ASSERT_EQ(kept.echo_power.size(), kept.beam.intensities.size());
    EXPECT_EQ(run[b].beam.intensities, kept.beam.intensities) << "beam " << 40 + b;
    EXPECT_EQ(run[b].truth.first_hit_range_m, kept.truth.first_hit_range_m);
  }
}

TEST(Simulation, ScheduleSteppsTheHeadAndKeepsTime) {
  const Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  const auto& g = scene.sensor.geometry;
  const ScheduledBeam first = ScheduleBeam(scene, 0);
  const ScheduledBeam next = ScheduleBeam(scene, 1);
  const ScheduledBeam lap = ScheduleBeam(scene, static_cast<std::size_t>(g.BeamsPerSweep()));
  EXPECT_NEAR(first.pose.head_angle_rad, scene.start_head_angle_rad, 1e-12);
  EXPECT_NEAR(next.pose.head_angle_rad - first.pose.head_angle_rad, g.step_angle_rad, 1e-12);
  EXPECT_NEAR(lap.pose.head_angle_rad, first.pose.head_angle_rad, 1e-9);
  EXPECT_NEAR(next.time_s - first.time_s, 1.0 / g.beams_per_second, 1e-12);
  // Every beam's head angle lies in [0, 2π): from the tank's start at 180°, beam 100 is a full
  // turn, which the reduction once rounded to 2π itself.
  for (std::size_t b = 0; b < ScenarioBeamCount(scene); ++b) {
    const double head = ScheduleBeam(scene, b).pose.head_angle_rad;
    ASSERT_GE(head, 0.0) << b;
    ASSERT_LT(head, 2.0 * std::numbers::pi) << b;
  }
}

}  // namespace
}  // namespace sonarbench::sim

namespace sonarbench::sim {
namespace {

// Navigation drift changes only the poses the mapper is given: the beams are rendered from the
// true poses, so their bytes are those of a run without drift; the reported sonar position is the
// true one plus drift·t, and its heading is turned by the heading drift·t.
TEST(Navigation, DriftMovesOnlyTheReportedPoses) {
  Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  scene.sweeps = 1;
  const auto meshes = BuildSceneMeshes(scene);
  const RayTracer tracer(meshes);
  const auto exact = SimulateScene(scene, tracer, 5, 2);
  scene.navigation.drift_m_per_s = {0.1, -0.05, 0.0};
  scene.navigation.heading_drift_rad_per_s = 1.0 * mapping::kDegToRad;
  const auto drifting = SimulateScene(scene, tracer, 5, 2);
  for (std::size_t b = 0; b < exact.size(); b += 13) {
    EXPECT_EQ(drifting[b].beam.intensities, exact[b].beam.intensities);
    const double t = drifting[b].beam.time_s;
    const Eigen::Isometry3d& truth = drifting[b].truth.T_world_sonar;
    const Eigen::Isometry3d& reported = drifting[b].beam.T_world_sonar;
    EXPECT_TRUE(truth.isApprox(exact[b].beam.T_world_sonar, 1e-12));
    // The tank's sonar sits at the vehicle's origin, so the vehicle's offset is the sonar's.
    EXPECT_NEAR(
        (reported.translation() - truth.translation() - Eigen::Vector3d(0.1, -0.05, 0) * t).norm(),
        0.0, 1e-9);
    const Eigen::AngleAxisd turn(reported.linear() * truth.linear().transpose());
    EXPECT_NEAR(turn.angle(), 1.0 * mapping::kDegToRad * t, 1e-9);
  }
}

// Position noise: per axis N(0, σ²). The sample variance s² of n = 2400 draws has
// (n-1)s²/σ² ~ χ²(n-1), within 1 ± 5.33·sqrt(2/(n-1)) = 1 ± 0.154 with probability 1 - 1e-7
// (normal approximation, two-sided): the false-alarm rate of this fixed-seed test.
TEST(Navigation, PositionNoiseHasItsConfiguredSpread) {
  Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  scene.sweeps = 4;
  scene.navigation.position_noise_m = 0.05;
  double sum = 0.0, sum_sq = 0.0;
  std::size_t n = 0;
  for (std::size_t b = 0; b < ScenarioBeamCount(scene); ++b) {
    const ScheduledBeam s = ScheduleBeam(scene, b);
    const Eigen::Vector3d d =
        ReportedSonarPose(scene, b, s.time_s, 9).translation() - s.pose.T_world_sonar.translation();
    for (int i = 0; i < 3; ++i) {
      sum += d[i];
      sum_sq += d[i] * d[i];
      ++n;
    }
  }
  ASSERT_EQ(n, 2400u);
  const double mean = sum / static_cast<double>(n);
  const double variance =
      (sum_sq - static_cast<double>(n) * mean * mean) / static_cast<double>(n - 1);
  const double ratio = variance / (0.05 * 0.05);
  EXPECT_NEAR(ratio, 1.0, 5.33 * std::sqrt(2.0 / static_cast<double>(n - 1))) << ratio;
  // The mean: within 5.33 σ/√n likewise.
  EXPECT_NEAR(mean, 0.0, 5.33 * 0.05 / std::sqrt(static_cast<double>(n)));
}

TEST(Navigation, SceneKeysAreReadWithUnits) {
  test::TempDir dir;
  const auto path = dir.path() / "nav.yaml";
  std::string text;
  {
    std::ifstream in(test::SourcePath("scenes/cras-tank.yaml"));
    std::stringstream s;
    s << in.rdbuf();
    text = s.str();
  }
  text.replace(text.find("sensor_model: ../"), std::string("sensor_model: ../").size(),
               "sensor_model: " + test::SourcePath("") + "/");
  std::ofstream(path) << text
                      << "\nnavigation: {drift_m_per_s: [0.01, 0, 0], heading_drift_deg_per_s: "
                         "0.2, position_noise_m: 0.02, heading_noise_deg: 0.5}\n";
  const Scene scene = LoadScene(path.string());
  EXPECT_EQ(scene.navigation.drift_m_per_s[0], 0.01);
  EXPECT_NEAR(scene.navigation.heading_drift_rad_per_s, 0.2 * mapping::kDegToRad, 1e-15);
  EXPECT_NEAR(scene.navigation.heading_noise_rad, 0.5 * mapping::kDegToRad, 1e-15);
  EXPECT_EQ(scene.navigation.position_noise_m, 0.02);
}

}  // namespace
}  // namespace sonarbench::sim
