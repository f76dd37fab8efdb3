#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/labels.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/sim/sonar/beam_synthesizer.hpp"
#include "sonarbench/sim/world/scene.hpp"

namespace sonarbench::sim {

/// Which part of a run this process writes: shard `index` (0-based) of `count`. Sweep s belongs
/// to shard s mod count. Every beam's random draws come from DeriveSeed(seed, beam index), a
/// hash, so the bytes of a sweep do not depend on the sharding.
struct Shard {
  int index = 0;
  int count = 1;
};

/// The files a scene reads: the scene, the scenes it extends, its sensor model and mesh files.
/// Outputs never overwrite them.
[[nodiscard]] std::vector<std::string> SceneInputFiles(const Scene& scene);

/// Parses "K/N" (1 <= K <= N, K 1-based as cluster array jobs count); throws InputError.
[[nodiscard]] Shard ParseShard(const std::string& text);
/// The shard of a SLURM array job, from SLURM_ARRAY_TASK_ID, _MIN and _COUNT; nullopt outside
/// one. Throws InputError when the variables are malformed.
[[nodiscard]] std::optional<Shard> ShardFromSlurm();

/// SHA-256 of what determines a scene's outputs: the tool and schema versions, the seed, and the
/// SHA-256 of the scene file, the sensor model file and every mesh file.
[[nodiscard]] std::string SceneConfigHash(const Scene& scene, std::uint64_t seed);
/// The configuration a simulated dataset records: SceneConfigHash with label files, another
/// hash without them (a rerun never mixes the two).
[[nodiscard]] std::string DatasetConfigHash(const Scene& scene, std::uint64_t seed, bool labels);

struct DatasetOptions {
  std::optional<std::uint64_t> seed;
  int threads = 0;
  /// Replace an existing dataset (or a partial one of another configuration).
  bool force = false;
  Shard shard;
  /// Write the per-bin label files (truth/labels_NNNN.bin); the beams are the same bytes either
  /// way.
  bool labels = true;
  /// Called after each sweep this process handles: sweeps handled and the shard's total.
  std::function<void(std::size_t done, std::size_t total)> progress;
};

struct DatasetSummary {
  std::size_t sweeps_total = 0;
  std::size_t sweeps_written = 0;
  /// Sweeps of this shard already complete on disk (a resumed run), skipped.
  std::size_t sweeps_skipped = 0;
  /// manifest.json written: every sweep present.
  bool complete = false;
  /// The dataset was already complete with this configuration: nothing was written.
  bool already_complete = false;
  std::string config_sha256;
};

/// A sweep's labels as its label file holds them (io::EncodeLabelFile) into `out`, a beam each
/// (its memory reused): each bin's shares, mesh and point, beams on `threads` threads (0: all
/// cores). Throws InputError for a scene of more meshes than the file numbers.
void LabelFileBeams(std::span<const SynthesizedBeam> beams, int threads,
                    std::vector<io::BeamLabels>& out);

/// Simulates a scene into a dataset directory (io::ReadDataset's format). Every file is
/// written atomically; a sweep is complete when the record this writer left for it lists each of
/// its files with the sha256 the file still has, and a rerun skips complete sweeps. manifest.json
/// is written last, once every sweep is present (by whichever shard finishes last, or by a rerun
/// without --shard). A directory holding another configuration's dataset, or files that are not a
/// dataset, is refused unless `force`.
DatasetSummary SimulateDataset(const Scene& scene, const std::string& dir,
                               const DatasetOptions& options);

/// A recorded log's beams (with their poses) and what the manifest says of it.
struct ImportedLog {
  std::vector<mapping::Beam> beams;
  std::size_t truncated_beams = 0;
  /// Added to the manifest's `log` (beside `file` and `truncated_beams`).
  nlohmann::json info = nlohmann::json::object();
  /// Options that change what is read from the file; part of the configuration hash.
  nlohmann::json options = nlohmann::json::object();
};

/// A .mat log as an ImportedLog: static at the origin.
[[nodiscard]] ImportedLog ImportedMatLog(io::MatLog log);

/// Writes a recorded log (a .mat log, static at the origin, or a ROS 2 bag) as a dataset: its
/// beams by sweep, polar images, the sonar's poses, no truth. Same atomicity and overwrite rules;
/// `sensor_file` ("" for none), like the log, is an input no output may overwrite.
DatasetSummary ImportLogDataset(const std::string& log_path, const ImportedLog& log,
                                const mapping::SensorGeometry& sensor, const std::string& dir,
                                bool force, const std::string& sensor_file = "");

}  // namespace sonarbench::sim
