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

// A beam's rays: ray (i, j) lies in horizontal stratum i and vertical stratum j of the aperture
// (the nominal widths times each direction's aperture scale), at one of the slots (the slot
// centres, to rounding), with the two-way pattern weight of its direction (of the nominal
// widths, whatever the scale); over pings every slot of a stratum is used (32 slots, 2000
// draws: a slot missed with probability 32 · (31/32)^2000 < 1e-26).
TEST(BeamPattern, RaysFillTheirStrataWithThePatternsWeights) {
  SensorModel scaled;
  scaled.acoustics.pattern.aperture_scale_horizontal = 2.0;
  scaled.acoustics.pattern.aperture_scale_vertical = 0.5;
  for (const SensorModel& sensor : {SensorModel{}, scaled}) {
    const mapping::SensorGeometry& g = sensor.geometry;
    const Acoustics& a = sensor.acoustics;
    SCOPED_TRACE(a.pattern.aperture_scale_horizontal);
    const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
    const RayTracer tracer(meshes);
    const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
    constexpr int kSlots = BeamPattern::kJitterSlots;
    const double stratum_h = a.pattern.aperture_scale_horizontal * g.beam_width_horizontal_rad /
                             a.pattern.rays_horizontal;
    const double stratum_v =
        a.pattern.aperture_scale_vertical * g.beam_width_vertical_rad / a.pattern.rays_vertical;
    const double k_h = 4.0 * std::log(2.0) / std::pow(g.beam_width_horizontal_rad, 2);
    const double k_v = 4.0 * std::log(2.0) / std::pow(g.beam_width_vertical_rad, 2);
    Rng rng(3);
    std::vector<Eigen::Vector3f> directions;
    std::vector<double> patterns;
    std::vector<int> slot_uses(kSlots, 0);
    for (int ping = 0; ping < 2000; ++ping) {
      const double sum =
          synthesizer.pattern().DrawRays(Eigen::Matrix3d::Identity(), rng, directions, patterns);
      ASSERT_EQ(directions.size(),
                static_cast<std::size_t>(a.pattern.rays_horizontal * a.pattern.rays_vertical));
      EXPECT_NEAR(sum, std::accumulate(patterns.begin(), patterns.end(), 0.0), 1e-9 * sum);
      for (int i = 0, r = 0; i < a.pattern.rays_horizontal; ++i) {
        for (int j = 0; j < a.pattern.rays_vertical; ++j, ++r) {
          if (ping > 0 && r > 0) break;  // every ray of the first ping, then ray 0's slots
          const Eigen::Vector3d d = directions[static_cast<std::size_t>(r)].cast<double>();
          const double theta = std::atan2(d.y(), d.x());
          const double epsilon = std::asin(d.z());
          // Positions in slots of the stratum: within float rounding of a slot centre.
          const double slot_h =
              (theta / stratum_h + 0.5 * a.pattern.rays_horizontal - i) * kSlots - 0.5;
          const double slot_v =
              (epsilon / stratum_v + 0.5 * a.pattern.rays_vertical - j) * kSlots - 0.5;
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

// The pattern's bound, which culls the mirror paths' straight returns before their
// trigonometry, is never under the pattern, ahead or behind, with or without sidelobes and a
// back lobe, over 20000 random directions; and it culls: 20° off the axis ahead, where the
// tank's 3° main lobe without its sidelobes is e^-62 one way, it is under 1e-20.
TEST(BeamPattern, OneWayPatternBoundIsNeverUnderThePattern) {
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const SensorModel tank_sensor = LoadScene(test::SourcePath("scenes/cras-tank.yaml")).sensor;
  const SensorModel main_lobe = [&] {
    SensorModel sensor = tank_sensor;
    sensor.acoustics.pattern.sidelobe_extent_deg = 0.0;
    return sensor;
  }();
  for (const SensorModel* with : {&tank_sensor, &main_lobe}) {
    const char* what = with == &main_lobe ? "the tank without sidelobes" : "the tank";
    for (const bool back_lobe : {true, false}) {
      SensorModel sensor = *with;
      if (!back_lobe) sensor.acoustics.pattern.back_lobe_width_deg = 0.0;
      const BeamSynthesizer synthesizer(sensor, tracer, {Material{}});
      Rng rng(91);
      for (int i = 0; i < 20000; ++i) {
        const Eigen::Vector3d u =
            Eigen::Vector3d(rng.Normal(), rng.Normal(), rng.Normal()).normalized();
        const double pattern = synthesizer.pattern().OneWayPatternTowards(u);
        ASSERT_GE(synthesizer.pattern().OneWayPatternBound(u), pattern * (1.0 - 1e-12))
            << what << (back_lobe ? "" : " without its back lobe") << ", towards " << u.transpose();
        if (u.x() <= 0.0 && !back_lobe) {
          EXPECT_EQ(pattern, 0.0);
        }
      }
    }
  }
  const BeamSynthesizer tank(main_lobe, tracer, {Material{}});
  const double off = 20.0 * kDegToRad;
  EXPECT_LT(tank.pattern().OneWayPatternBound({std::cos(off), std::sin(off), 0.0}), 1e-20);
  EXPECT_EQ(tank.pattern().OneWayPatternBound(Eigen::Vector3d::UnitX()), 1.0);
}

// Sidelobes: plates facing the sonar 2 m out, each taller than the fan, return echo powers in
// the ratio of the two-way horizontal pattern's integrals over their bearings, exp(-4 ln2
// θ²/w²) + S (θ_s² / (θ_s² + θ²))²: one over the main lobe's rays (±1.5°), one at 8-12° to the
// left, one at 18-22° to the right (where only sidelobe rays, 0.5° strata with a quarter of the
// main lobe's vertical strata, reach). No range loss (spreading = TVG, no absorption) and
// incidence within 2° of normal (cos ≥ 0.9994), so the ratios are the pattern's, averaged over
// 64 pings: 1% holds their sampling (under 0.1%, one standard error) many times over. Without
// sidelobes the side plates are not heard at all.
TEST(BeamPattern, SidelobesHearPlatesOffTheAxisAsThePatternSays) {
  SensorModel sensor = QuietSensor();
  Acoustics& a = sensor.acoustics;
  a.pattern.sidelobe_extent_deg =
      24.0;  // (24 - 1.5) / 45: 0.5° strata, edges on whole half degrees
  a.pattern.sidelobe_db = -20.0;
  a.pattern.sidelobe_width_deg = 5.0;
  a.pattern.sidelobe_rays_horizontal = 45;
  a.pattern.sidelobe_rays_vertical = 40;
  const double deg = mapping::kDegToRad;
  const double main_lobe = TotalPowerOverPings(sensor, Plate(2.0, 0.0, 1.5 * deg, 4.0));
  const double left = TotalPowerOverPings(sensor, Plate(2.0, 10.0 * deg, 2.0 * deg, 4.0));
  const double right = TotalPowerOverPings(sensor, Plate(2.0, -20.0 * deg, 2.0 * deg, 4.0));
  const double w = sensor.geometry.beam_width_horizontal_rad;
  const double s = std::pow(10.0, a.pattern.sidelobe_db / 10.0);
  const double ts2 = std::pow(a.pattern.sidelobe_width_deg * deg, 2);
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
  narrow.acoustics.pattern.sidelobe_extent_deg = 0.0;
  EXPECT_EQ(TotalPowerOverPings(narrow, Plate(2.0, 10.0 * deg, 2.0 * deg, 4.0)), 0.0);
}

// The first-hit truth is the main lobe's: a plate only the sidelobes reach, nearer than the
// wall ahead, is heard at its range but not reported as what the beam hit.
TEST(BeamPattern, SidelobesLeaveTheFirstHitToTheMainLobe) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.pattern.sidelobe_extent_deg = 24.0;
  sensor.acoustics.pattern.sidelobe_db = -10.0;
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
TEST(BeamPattern, BackLobeHearsAPlateBehindAsItsPatternSays) {
  SensorModel sensor = QuietSensor();
  Acoustics& a = sensor.acoustics;
  a.pattern.back_lobe_width_deg = 20.0;
  a.pattern.back_lobe_db = -10.0;
  a.pattern.back_lobe_rays = 24;
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
      std::pow(10.0, 2.0 * a.pattern.back_lobe_db / 10.0) *
      integral(60.0, [&](double p) { return std::exp(-k_b * p * p) * std::cos(p); }) *
      integral(60.0, [&](double e) { return std::exp(-k_b * e * e) * std::pow(std::cos(e), 2); });
  EXPECT_NEAR(back_lobe / main_lobe, expected_back / expected_main,
              0.01 * expected_back / expected_main);

  SensorModel none = sensor;
  none.acoustics.pattern.back_lobe_width_deg = 0.0;
  EXPECT_EQ(TotalPowerOverPings(none, behind), 0.0);
  EXPECT_EQ(TotalPowerOverPings(none, ahead), main_lobe);
}

}  // namespace
}  // namespace sonarbench::sim
