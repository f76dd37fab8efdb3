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
