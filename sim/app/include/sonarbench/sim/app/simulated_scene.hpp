#pragma once

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/sonar/scene_world.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// A scene simulated once, with what every map of it is scored against (the studies' shared
/// inputs): the beams, the cells its surfaces cross and those a perfect sensor sees from the
/// beams' poses, on the scene's mapping resolution, and the beams' direct echoes.
struct SimulatedScene {
  std::vector<SynthesizedBeam> synthesized;
  std::vector<mapping::Beam> beams;
  /// Per beam, each bin's path with the most power (io::EchoPath), as the labels give it.
  std::vector<std::vector<std::uint8_t>> bin_paths;
  mapping::KeySet truth;
  mapping::KeySet observable;
  DirectEchoes direct;
};

/// The cells a perfect sensor sees from the true poses of the scene's first `beams` beams, and
/// their direct echoes; with `heads_deg`, of those whose head angle lies in [first, second)
/// degrees.
struct ObservedCells {
  mapping::KeySet observable;
  DirectEchoes direct;
};
[[nodiscard]] ObservedCells ObservedFrom(const Scene& scene, const SceneWorld& world,
                                         std::size_t beams,
                                         const std::optional<std::pair<double, double>>& heads_deg);

/// Simulates `scene` with `seed` in its `world` and voxelises its truth and observable cells; with
/// `heads_deg`, the cells and echoes that the beams whose head angle lies in [first, second)
/// degrees see (every beam is simulated and kept).
[[nodiscard]] SimulatedScene SimulateForScoring(
    const Scene& scene, const SceneWorld& world, std::uint64_t seed, int threads,
    const std::optional<std::pair<double, double>>& heads_deg = std::nullopt);

}  // namespace sonarbench::sim
