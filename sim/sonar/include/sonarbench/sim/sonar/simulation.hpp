#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "sonarbench/sim/sonar/beam_synthesizer.hpp"
#include "sonarbench/sim/world/geometry.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// Number of beams a scene's run produces: sweeps × beams per revolution.
[[nodiscard]] std::size_t ScenarioBeamCount(const Scene& scene);

/// Time [s], head angle and sonar pose of beam `index` of a scene's run: the head steps by the
/// sensor's step angle from the scene's start angle, one beam every 1/beams_per_second, and the
/// sonar rides the vehicle's true pose at that beam's own time (motion distortion included).
struct ScheduledBeam {
  double time_s = 0.0;
  BeamPose pose;
};
[[nodiscard]] ScheduledBeam ScheduleBeam(const Scene& scene, std::size_t index);

/// The sonar pose the navigation reports for beam `index` at `time_s`: the true pose with the
/// scene's NavigationError applied to the vehicle (its noise seeded from `seed` and the index).
/// Without navigation error, the true pose.
[[nodiscard]] Eigen::Isometry3d ReportedSonarPose(const Scene& scene, std::size_t index,
                                                  double time_s, std::uint64_t seed);

/// Synthesises every beam of the scene's run, in time order, on `threads` threads (0 = all).
/// Beam b draws only from DeriveSeed(seed, b): the output does not depend on the thread count.
/// Each beam is rendered from the true pose and carries the reported one (ReportedSonarPose) in
/// `beam.T_world_sonar`; the true one is in `truth.T_world_sonar`. `on_sweep`, when set, is
/// called after each sweep with the sweeps done and the total; `on_labels`, when set, with each
/// sweep's beams and their labels (Labels::kKeep), which the beams returned no longer hold.
[[nodiscard]] std::vector<SynthesizedBeam> SimulateScene(
    const Scene& scene, const RayTracer& tracer, std::uint64_t seed, int threads,
    const std::function<void(std::size_t done, std::size_t total)>& on_sweep = {},
    const std::function<void(std::span<const SynthesizedBeam>)>& on_labels = {});

/// The synthesizer of a scene's run: its sensor, its meshes' materials (mesh i's at i, as
/// BuildSceneMeshes orders them), its vehicle's parts (BuildVehicleMeshes) and the run seed.
/// Build it once per run: it tables the range loss, the AD steps and the jitter slots, and
/// builds the vehicle's BVH.
[[nodiscard]] BeamSynthesizer SceneSynthesizer(const Scene& scene, const RayTracer& tracer,
                                               std::uint64_t seed);

/// Synthesises beams [first, last) of the scene's run with `synthesizer` (SceneSynthesizer of
/// the same scene and seed), on `threads` threads (0 = all); beam b draws only from
/// DeriveSeed(seed, b), so any split of a run gives the same beams. Their echo power is dropped
/// (EchoPower::kDrop); their bins' labels kept with Labels::kKeep.
[[nodiscard]] std::vector<SynthesizedBeam> SimulateBeams(const Scene& scene,
                                                         const BeamSynthesizer& synthesizer,
                                                         std::uint64_t seed, int threads,
                                                         std::size_t first, std::size_t last,
                                                         Labels labels = Labels::kDrop);

/// SimulateBeams into `beams` (resized to last - first), their memory reused: a caller that
/// keeps `beams` from sweep to sweep allocates once.
void SimulateBeamsInto(const Scene& scene, const BeamSynthesizer& synthesizer, std::uint64_t seed,
                       int threads, std::size_t first, std::size_t last, Labels labels,
                       std::vector<SynthesizedBeam>& beams);

/// The beams alone, as the mapper takes them.
[[nodiscard]] std::vector<mapping::Beam> BeamsOf(std::span<const SynthesizedBeam> synthesized);

}  // namespace sonarbench::sim
