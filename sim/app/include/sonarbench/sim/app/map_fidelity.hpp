#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "sonarbench/sim/app/detector_study.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// The study with the log over the whole sweep and over each half of it ([0, 180) and [180, 360)
/// degrees of head angle; `options.heads_deg` is ignored), as fidelity.json's "maps": "settings"
/// (their names), "parts" (per part its name, "heads_deg", AgreementJson as "agreement", and
/// "rows": each setting's P@1, R@1, F1@1 and ghost split, scene and log) and "meets" (every part
/// does). `options.progress` counts the settings over the three parts.
[[nodiscard]] nlohmann::json MapFidelity(const Scene& scene, DetectorStudyOptions options,
                                         const MapGoals& goals = {});

/// The log judged against the simulator's own spread (docs/fidelity.md, "The verdict").
struct MapSpreadOptions {
  /// The simulated runs, one per seed (at least 4).
  std::vector<std::uint64_t> seeds;
  /// The verdict's size over all its judgements (each judged at level / their count).
  double level = 0.05;
};
struct MapSpread {
  nlohmann::json maps;    ///< MapFidelity's, at the first seed (null without settings)
  nlohmann::json spread;  ///< the verdict, fidelity.json's "spread"
};

/// Maps the log once and the scene at every seed, over each part as MapFidelity does, with
/// `options.items` (none: the scene's mapping only) and the scene's own mapping. Per part and
/// figure: the log against the runs at the scene's mapping (JudgeValue) and over the settings
/// (JudgeSettings); "within" when every judgement is; "size": how many runs, standing in for the
/// log and judged against the others by the same rule, are within. `options.seed` is ignored;
/// `options.progress` counts settings over parts and seeds.
[[nodiscard]] MapSpread JudgeMapsAgainstSeeds(const Scene& scene, DetectorStudyOptions options,
                                              const MapSpreadOptions& spread,
                                              const MapGoals& goals = {});

}  // namespace sonarbench::sim
