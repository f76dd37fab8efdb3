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

// The nearest point of a wall at normal incidence is on the beam axis, at its range d: the echo
// starts in bin floor(d / bin). The stratified rays nearest the axis are within half a stratum
// (≤ 0.2°) of it, which lengthens their range by d·(1/cos 0.2° - 1) < 1e-5 d, far below a bin.
TEST(BeamSynthesizer, WallAtKnownRangeEchoesInItsBin) {
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
    const long pulse_bins = static_cast<long>(std::ceil(sensor.acoustics.pulse.length_m / bin));
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

// A vehicle part 1 m ahead of a sonar mounted 0.2 m forward and 0.1 m up on the vehicle, turned
// 90° so that its head angle 0 looks along the vehicle's y: heard at 1 m (its first bin
// floor(1 m / bin), as a wall's) by the beam looking at it, the same wherever the vehicle is and
// however it is turned (the rays are the same in the sonar's frame; their turn into the
// vehicle's is in floats: 1e-4 of the power), by none looking away; and it is not the scene, so
// the beam's truth holds no hit (the scene's one wall lies out of range).
TEST(BeamSynthesizer, VehiclePartEchoesAtItsRangeWhereverTheVehicleIs) {
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
TEST(BeamSynthesizer, VehiclePartShadowsTheSceneBehindIt) {
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
TEST(BeamSynthesizer, VehicleEchoesHaveNoSkirtsSecondTripOrReverberation) {
  const SensorModel quiet = QuietSensor();
  SensorModel tank = quiet;
  tank.acoustics.pulse.skirt_length_m = 0.05;
  tank.acoustics.pulse.skirt_db = 3.0;
  tank.acoustics.tail.second_trip_db = 0.0;
  tank.acoustics.tail.reverberation_length_m = 0.5;
  tank.acoustics.tail.reverberation_db = -3.0;
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

TEST(BeamSynthesizer, EchoFollowsLambertsLawWithIncidence) {
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
TEST(BeamSynthesizer, EchoFollowsSpreadingAndAbsorptionWithRange) {
  SensorModel sensor = QuietSensor();
  sensor.acoustics.gain.spreading_db_per_decade = 40.0;
  sensor.acoustics.gain.tvg_db_per_decade = 10.0;
  sensor.acoustics.gain.absorption_db_per_m = 0.5;
  // Absorption depends on each ray's own range, so compare ray by ray: use a narrow fan where
  // every ray's range is within 0.1% of the axis range.
  sensor.geometry.beam_width_vertical_rad = 3.0 * kDegToRad;
  const double near = TotalPower(Ping(sensor, Wall(1.0, 0.0)));
  const double far = TotalPower(Ping(sensor, Wall(2.0, 0.0)));
  const double expected_db = -(30.0 * std::log10(2.0) + 0.5 * 1.0);
  EXPECT_NEAR(10.0 * std::log10(far / near), expected_db, 0.01);
}

// A beam of the tank (multipath, the vehicle's parts, the back lobe) counts as traced exactly the
// rays its queries of the scene's and the parts' tracers carry: what synthesis_bench replays.
TEST(BeamSynthesizer, CountsAsTracedTheRaysOfItsQueries) {
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

TEST(BeamSynthesizer, NothingInRangeGivesOnlyTheNoiseFloor) {
  const SensorModel sensor = QuietSensor();
  const SynthesizedBeam beam = Ping(sensor, Wall(sensor.geometry.MaxRangeM() + 1.0, 0.0));
  EXPECT_FALSE(beam.truth.first_hit_range_m.has_value());
  for (double p : beam.echo_power) EXPECT_EQ(p, 0.0);
  for (auto v : beam.beam.intensities) EXPECT_EQ(v, 0);
}

}  // namespace
}  // namespace sonarbench::sim
