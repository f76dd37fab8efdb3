#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <string>

#include "sonarbench/sim/sonar/beam_synthesizer.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

constexpr auto kDirect = static_cast<std::size_t>(EchoPath::kDirect);
constexpr auto kNoise = static_cast<std::size_t>(EchoPath::kNoise);

double Sum(const BinLabel& label) {
  return std::accumulate(label.energy.begin(), label.energy.end(), 0.0);
}

// Every `step`-th beam of a scene's first sweep, with its labels, and the same without.
struct LabelledBeams {
  std::vector<SynthesizedBeam> with, without;
};
LabelledBeams Synthesize(const Scene& scene, const RayTracer& tracer, std::size_t step,
                         EchoPower echo_power = EchoPower::kDrop) {
  const BeamSynthesizer synthesizer = SceneSynthesizer(scene, tracer, 3);
  LabelledBeams out;
  for (std::size_t b = 0; b < static_cast<std::size_t>(scene.sensor.geometry.BeamsPerSweep());
       b += step) {
    const ScheduledBeam s = ScheduleBeam(scene, b);
    for (const Labels labels : {Labels::kKeep, Labels::kDrop}) {
      (labels == Labels::kKeep ? out.with : out.without)
          .push_back(synthesizer.Synthesize(s.time_s, s.pose.head_angle_rad, s.pose.T_world_sonar,
                                            DeriveSeed(3, b), echo_power, labels));
    }
  }
  return out;
}

// Labels change no byte of a beam, and every bin's paths are non-negative.
TEST(BinLabels, LeaveTheBeamsAsTheyAre) {
  for (const char* name : {"scenes/cras-tank.yaml", "scenes/seabed.yaml"}) {
    Scene scene = LoadScene(test::SourcePath(name));
    const auto meshes = BuildSceneMeshes(scene);
    const RayTracer tracer(meshes);
    const LabelledBeams beams = Synthesize(scene, tracer, 7);
    for (std::size_t b = 0; b < beams.with.size(); ++b) {
      ASSERT_EQ(beams.with[b].beam.intensities, beams.without[b].beam.intensities) << name;
      EXPECT_TRUE(beams.without[b].labels.empty());
      ASSERT_EQ(beams.with[b].labels.size(), beams.with[b].beam.intensities.size());
      for (const BinLabel& label : beams.with[b].labels) {
        for (const float e : label.energy) ASSERT_GE(e, -1e-6 * Sum(label)) << name;
      }
    }
  }
}

// A beam synthesised into another's memory is the beam synthesised afresh, whatever the other
// held: labels or none, echo power or none.
TEST(BinLabels, ABeamSynthesizedIntoAnothersMemoryIsTheFreshOne) {
  Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  const auto meshes = BuildSceneMeshes(scene);
  const RayTracer tracer(meshes);
  const BeamSynthesizer synthesizer = SceneSynthesizer(scene, tracer, 3);
  SynthesizedBeam reused;
  for (std::size_t b = 0; b < 200; b += 13) {
    const ScheduledBeam s = ScheduleBeam(scene, b);
    const Labels labels = (b / 13) % 2 == 0 ? Labels::kKeep : Labels::kDrop;
    const EchoPower power = (b / 13) % 3 == 0 ? EchoPower::kKeep : EchoPower::kDrop;
    synthesizer.SynthesizeInto(s.time_s, s.pose.head_angle_rad, s.pose.T_world_sonar,
                               DeriveSeed(3, b), power, labels, reused);
    const SynthesizedBeam fresh = synthesizer.Synthesize(
        s.time_s, s.pose.head_angle_rad, s.pose.T_world_sonar, DeriveSeed(3, b), power, labels);
    ASSERT_EQ(reused.beam.intensities, fresh.beam.intensities) << b;
    EXPECT_EQ(reused.truth.first_hit_range_m, fresh.truth.first_hit_range_m) << b;
    EXPECT_EQ(reused.truth.axis_hit_range_m, fresh.truth.axis_hit_range_m) << b;
    EXPECT_EQ(reused.echo_power, fresh.echo_power) << b;
    EXPECT_EQ(reused.traced_rays, fresh.traced_rays) << b;
    ASSERT_EQ(reused.labels.size(), fresh.labels.size()) << b;
    for (std::size_t k = 0; k < fresh.labels.size(); ++k) {
      ASSERT_EQ(reused.labels[k].energy, fresh.labels[k].energy) << b << " bin " << k;
      ASSERT_EQ(reused.labels[k].mesh, fresh.labels[k].mesh) << b << " bin " << k;
      for (int i = 0; i < 3; ++i) {
        const float x = reused.labels[k].point_sonar_m[i], y = fresh.labels[k].point_sonar_m[i];
        ASSERT_TRUE(x == y || (std::isnan(x) && std::isnan(y))) << b << " bin " << k;
      }
    }
  }
}

// Without speckle and self-reflection, a bin's paths but the noise sum to its noise-free echo
// power times the gain, to rounding (each path a float: 2^-24 of it).
TEST(BinLabels, PathsSumToTheBinsEchoPower) {
  Scene scene = LoadScene(test::SourcePath("scenes/cras-tank.yaml"));
  scene.sensor.acoustics.speckle.on = false;
  scene.sensor.acoustics.self_reflection.profile_db.clear();
  const auto meshes = BuildSceneMeshes(scene);
  const RayTracer tracer(meshes);
  const LabelledBeams beams = Synthesize(scene, tracer, 5, EchoPower::kKeep);
  const double gain = std::pow(10.0, scene.sensor.acoustics.gain.gain_db / 10.0);
  std::size_t checked = 0;
  for (const SynthesizedBeam& beam : beams.with) {
    for (std::size_t k = 0; k < beam.labels.size(); ++k) {
      const double echo = gain * beam.echo_power[k];
      const double paths = Sum(beam.labels[k]) - beam.labels[k].energy[kNoise];
      ASSERT_NEAR(paths, echo, 1e-6 * echo + 1e-300) << "bin " << k;
      checked += echo > 0.0;
    }
  }
  EXPECT_GT(checked, 1000u);
}

// A bin labelled direct from mesh M: the ray from the sonar through its labelled point, at an
// elevation inside the main lobe, first meets M at the point's range, and that range lies where the
// bin can hear it: from a pulse length before the bin to its end, a bin either side.
TEST(BinLabels, ADirectBinsRayMeetsItsMeshWhereTheBinHearsIt) {
  for (const char* name : {"scenes/cras-tank.yaml", "scenes/seabed.yaml"}) {
    Scene scene = LoadScene(test::SourcePath(name));
    const auto meshes = BuildSceneMeshes(scene);
    const RayTracer tracer(meshes);
    const LabelledBeams beams = Synthesize(scene, tracer, 1);
    const double bin = scene.sensor.geometry.bin_size_m;
    const double pulse = scene.sensor.acoustics.pulse.length_m;
    const double half_vertical = 0.5 * scene.sensor.geometry.beam_width_vertical_rad;
    std::size_t checked = 0;
    for (const SynthesizedBeam& beam : beams.with) {
      const Eigen::Isometry3d& T = beam.truth.T_world_sonar;
      const Eigen::Matrix3d R_world_beam =
          T.linear() *
          Eigen::AngleAxisd(beam.beam.head_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      for (std::size_t k = 0; k < beam.labels.size(); ++k) {
        const BinLabel& label = beam.labels[k];
        if (label.mesh == kNoMesh) continue;
        ASSERT_GT(label.energy[kDirect], 0.0) << name << " bin " << k;
        const Eigen::Vector3d point = label.point_sonar_m.cast<double>();
        const Eigen::Vector3d world = T.linear() * point.normalized();
        // Its elevation in the beam, asin(z / |p|), within the main lobe's vertical aperture.
        const double elevation = std::asin((R_world_beam.transpose() * world).z());
        ASSERT_NEAR(elevation, std::asin(point.z() / point.norm()), 1e-5) << name << " bin " << k;
        ASSERT_LE(std::abs(elevation), half_vertical + 1e-5) << name << " bin " << k;
        const auto hit = tracer.Intersect(T.translation().cast<float>(), world.cast<float>(),
                                          static_cast<float>(point.norm() + 1.0));
        ASSERT_TRUE(hit) << name << " bin " << k;
        EXPECT_EQ(hit->mesh, label.mesh) << name << " bin " << k;
        EXPECT_NEAR(hit->distance, point.norm(), 1e-3) << name << " bin " << k;
        const double lo = static_cast<double>(k) * bin - pulse - bin;
        const double hi = static_cast<double>(k + 2) * bin;
        EXPECT_GE(point.norm(), lo) << name << " bin " << k;
        EXPECT_LE(point.norm(), hi) << name << " bin " << k;
        ++checked;
      }
    }
    EXPECT_GT(checked, 2000u) << name;
  }
}

}  // namespace
}  // namespace sonarbench::sim
