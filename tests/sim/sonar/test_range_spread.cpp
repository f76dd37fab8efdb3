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

// A quiet sensor with a second trip at +3 dB, and its synthesizer (of a wall it never pings).
struct SecondTripAt3Db {
  SecondTripAt3Db() : sensor(Sensor()), tracer(Wall(1.0, 0.0)), synthesizer(sensor, tracer, {{}}) {}
  static SensorModel Sensor() {
    SensorModel s = QuietSensor();
    s.acoustics.tail.second_trip_db = 3.0;
    return s;
  }
  SensorModel sensor;
  RayTracer tracer;
  BeamSynthesizer synthesizer;
  std::size_t bins = static_cast<std::size_t>(sensor.geometry.num_bins);
  double bin = sensor.geometry.bin_size_m;
};

// Reverberation: a wall at normal incidence echoes over a few bins; the tail that echo feeds
// starts in the bin after each echo bin, falls by exp(-bin / length) per bin once the echo has
// passed (10·log10(e) / length dB per metre), and holds R = 10^(reverberation_db/10) of the
// echo's power in all: with the wall at 0.5 m and a 0.2 m length the beam's end (5 m) cuts
// exp(-22) of it. The rays are the same in both pings (same seed), so the echo is too.
TEST(RangeSpread, ReverberationTailDecaysAtItsLengthAndHoldsItsShare) {
  SensorModel dry = QuietSensor();
  SensorModel wet = dry;
  wet.acoustics.tail.reverberation_length_m = 0.2;
  wet.acoustics.tail.reverberation_db = -3.0;
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
TEST(RangeSpread, PulseSkirtsShareTheEchoExponentiallyOnBothSides) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.pulse.skirt_length_m = 0.05;
  sensor.acoustics.pulse.skirt_db = 3.0;
  const RayTracer tracer(Wall(1.0, 0.0));
  const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
  const auto bins = static_cast<std::size_t>(sensor.geometry.num_bins);
  const double q = std::exp(-sensor.geometry.bin_size_m / 0.05);
  const double share = std::pow(10.0, 0.3);
  std::vector<double> echo(bins, 0.0);
  echo[200] = 2.0;
  std::vector<double> heard = echo;
  AddPulseSkirts(sensor, heard);
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
  AddPulseSkirts(sensor, other);
  AddPulseSkirts(sensor, both);
  for (std::size_t k = 0; k < bins; ++k) {
    EXPECT_NEAR(both[k], heard[k] + other[k], 1e-12 * both[k]) << "bin " << k;
  }
  std::vector<double> unchanged = echo;
  AddPulseSkirts(QuietSensor(), unchanged);
  EXPECT_EQ(unchanged, echo);
}

// Through the whole synthesis, a wall at normal incidence 2 m ahead: with skirts its echo starts
// in front of the wall, each bin there q times the next (q = exp(-bin / length)), up to the
// bin before the wall's; and the beam holds the same power as without them (the skirts share
// the echo out; the beam's ends cut under 1e-21 of it).
TEST(RangeSpread, WallEchoGainsSkirtsAndKeepsItsPower) {
  const SensorModel bare = QuietSensor();
  SensorModel skirted = bare;
  skirted.acoustics.pulse.skirt_length_m = 0.04;
  skirted.acoustics.pulse.skirt_db = 0.0;
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

// The second trip, exactly: one first-trip echo in bin i (power P, pulse-spread) and one
// impulse in bin j (power Q) give T · g(m) · (P / g(i)) · (Q / g(j)) / 2 to each of bins
// m = i + j and i + j + 1, g(k) = ((k + ½) bins)^(G/10) the time-varied gain, T the level;
// nothing elsewhere, nothing for a pair whose sum is past the last bin, nothing at -100 dB.
TEST(RangeSpread, SecondTripIsTheTripsProductAtTheSummedRange) {
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
  AddSecondTrip(trip.sensor, synthesizer.receiver(), heard, impulse);
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
  AddSecondTrip(trip.sensor, synthesizer.receiver(), far_heard, far_impulse);
  EXPECT_EQ(far_heard, far);
  // At -100 dB (the default): nothing at all.
  std::vector<double> unchanged = echo;
  const SensorModel quiet = QuietSensor();
  AddSecondTrip(quiet, Receiver(quiet), unchanged, impulse);
  EXPECT_EQ(unchanged, echo);
}

// The second trip's products run as vector code as wide as the machine has (AVX-512, AVX2 or
// the baseline), built without fused multiply-adds: bit for bit the scalar sum of its
// documentation, in its order (over i increasing), for dense random trips (every bin of both
// non-zero, some under the 1e-6 floor). Fusing would round each product-sum once instead of
// twice and change the low bits of most bins.
TEST(RangeSpread, SecondTripIsTheScalarSumBitForBit) {
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
  AddSecondTrip(trip.sensor, synthesizer.receiver(), heard, impulse);
  for (std::size_t k = 0; k < bins; ++k) EXPECT_EQ(heard[k], expected[k]) << "bin " << k;
}

// A wall at normal incidence 1 m ahead, through the whole synthesis: with no time-varied gain
// (and spreading to match) the second trip is the two trips' convolution, so it starts where
// the first trip's echo and impulse start summed (within two bins of twice the wall's range), its
// centre of mass is theirs summed, and it holds T times their powers' product.
TEST(RangeSpread, WallRingsAgainAtTwiceItsRange) {
  SensorModel flat = QuietSensor();
  flat.acoustics.gain.spreading_db_per_decade = 0.0;
  flat.acoustics.gain.tvg_db_per_decade = 0.0;
  SensorModel ringing = flat;
  ringing.acoustics.tail.second_trip_db = -3.0;
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
  short_pulse.acoustics.pulse.length_m = flat.geometry.bin_size_m;
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
TEST(RangeSpread, SecondTripReverberatesOnEachTrip) {
  SensorModel flat = QuietSensor();
  flat.acoustics.gain.spreading_db_per_decade = 0.0;
  flat.acoustics.gain.tvg_db_per_decade = 0.0;
  flat.acoustics.tail.reverberation_length_m = 0.1;
  flat.acoustics.tail.reverberation_db = -3.0;
  SensorModel ringing = flat;
  ringing.acoustics.tail.second_trip_db = -3.0;
  SensorModel impulse = QuietSensor();
  impulse.acoustics.gain.spreading_db_per_decade = 0.0;
  impulse.acoustics.gain.tvg_db_per_decade = 0.0;
  impulse.acoustics.pulse.length_m = flat.geometry.bin_size_m;
  const std::vector<TriangleMesh> wall = Wall(1.0, 0.0);
  const double once = TotalPower(Ping(flat, wall));
  const double twice = TotalPower(Ping(ringing, wall));
  const double h = TotalPower(Ping(impulse, wall));
  const double reverberation = std::pow(10.0, -0.3);
  const double echo = once / (1.0 + reverberation);
  const double expected = std::pow(10.0, -0.3) * (1.0 + reverberation) * (1.0 + reverberation);
  EXPECT_NEAR((twice - once) / (echo * h), expected, 5e-6 * expected);
}

}  // namespace
}  // namespace sonarbench::sim
