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

// Multipath: a mirror that scatters nothing back (reflectivity 0, specular 1) at 45° one metre
// ahead turns the beam towards a plane one metre to the side. The mirror's image of that plane
// lies two metres ahead, so the ghost's echo starts in bin floor(2.0 / bin) exactly as a wall at
// 2 m would; without the specular reflection there is no echo at all.
TEST(Multipath, SpecularBounceEchoesAtTheSummedRange) {
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
TEST(Multipath, MultipathOffAMirrorFloorLiesWithinItsMirrorPaths) {
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
  const double pulse = sensor.acoustics.pulse.length_m;
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
TEST(Multipath, GlintIsTheMirrorLobeTowardsTheSonar) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.pattern.aperture_scale_horizontal = 0.1;
  sensor.acoustics.pattern.aperture_scale_vertical = 0.1;
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
TEST(Multipath, GlintsFeedNoReverberationOrSecondTrip) {
  SensorModel skirts = QuietSensor();
  skirts.acoustics.pattern.aperture_scale_horizontal = 0.1;
  skirts.acoustics.pattern.aperture_scale_vertical = 0.1;
  skirts.acoustics.pulse.skirt_length_m = 0.05;
  skirts.acoustics.pulse.skirt_db = 3.0;
  SensorModel tank = skirts;
  tank.acoustics.tail.second_trip_db = 0.0;
  tank.acoustics.tail.reverberation_length_m = 0.5;
  tank.acoustics.tail.reverberation_db = -3.0;
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
TEST(Multipath, CornerSendsItsGlintStraightBack) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.pattern.aperture_scale_horizontal = 0.1;
  sensor.acoustics.pattern.aperture_scale_vertical = 0.1;
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
  const double pulse = sensor.acoustics.pulse.length_m;
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
TEST(Multipath, RoughMirrorTiltsRaysByItsSpread) {
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
    const Eigen::Vector3f d = synthesizer.mirror_spread().Spread(mirror, normal, rough, rng);
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
TEST(Multipath, RoughMirrorKeepsRaysOnItsSide) {
  const RayTracer tracer(Wall(1.0, 0.0));
  Material perfect;
  perfect.specular = 1.0;
  const BeamSynthesizer synthesizer(QuietSensor(), tracer, {perfect});
  const Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
  const Eigen::Vector3f grazing(std::cos(0.0349f), 0.0f, std::sin(0.0349f));
  Rng rng(5);
  Rng untouched(5);
  EXPECT_EQ(synthesizer.mirror_spread().Spread(grazing, normal, perfect, rng), grazing);
  EXPECT_EQ(rng.Next(), untouched.Next());
  Material rough = perfect;
  rough.specular_spread_rad = 8.0 * kDegToRad;
  int folded = 0;
  for (int i = 0; i < 10000; ++i) {
    const Eigen::Vector3f d = synthesizer.mirror_spread().Spread(grazing, normal, rough, rng);
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
TEST(Multipath, RoughMirrorSpreadsTheGhostSideways) {
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
TEST(Multipath, RoughMirrorEchoComesBackThroughItsReceivePattern) {
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

// A mirror path's last leg heard behind: a mirror 1 m ahead (no echo of its own) sends each
// ray back past the sonar to a plate 2 m behind it (no mirror), whose echo straight back comes
// from behind at (4 + 2) / 2 = 3 m. It is heard through the back lobe's one-way pattern B (and,
// by reciprocity, sent through it), so its power is B's: 10 times as much at -10 dB as at -20
// dB, to rounding (the rays and their normalisation are the same), and none without a back
// lobe. Nothing else lies at 2.9-3.6 m: the plate's own echoes through the back lobe end before
// 2 / cos² 30° + the pulse = 2.72 m, the mirror path back the way it came is at 4 m.
TEST(Multipath, BackLobeHearsAMirrorPathsLastLegInProportionToItsLevel) {
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
    sensor.acoustics.pattern.back_lobe_width_deg = back_lobe_width_deg;
    sensor.acoustics.pattern.back_lobe_db = back_lobe_db;
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

}  // namespace
}  // namespace sonarbench::sim
