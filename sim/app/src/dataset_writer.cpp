#include "sonarbench/sim/app/dataset_writer.hpp"

#include <octomap/OcTree.h>
#include <omp.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "dataset_resume.hpp"
#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/labels.hpp"
#include "sonarbench/io/output_directory.hpp"
#include "sonarbench/io/text.hpp"
#include "sonarbench/mapping/mapper.hpp"
#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/report/images.hpp"
#include "sonarbench/sim/report/report.hpp"
#include "sonarbench/sim/sonar/scene_world.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"

namespace sonarbench::sim {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Present while a dataset is being written; holds the configuration's hash so a rerun knows
// whether the sweeps on disk are its own.
constexpr const char* kPartialMarker = ".sonarbench-partial.json";

void WriteText(const fs::path& path, const std::string& text) {
  WriteFileAtomically(path.string(), [&](std::ostream& out) { out << text; });
}

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", value);
  return text;
}

// Every file a dataset of `sweeps` sweeps holds (with truth when simulated, label files when
// `labels`), and the partial marker: what its output directory claims.
io::OutputClaim DatasetClaim(std::string command, std::string config, std::size_t sweeps,
                             bool simulated, bool labels, bool force) {
  io::OutputClaim claim;
  claim.command = std::move(command);
  claim.config_sha256 = std::move(config);
  claim.mode = io::OutputMode::kResume;
  claim.files = {"manifest.json", kPartialMarker, "poses/sonar.tum"};
  if (simulated) {
    claim.files.insert(claim.files.end(),
                       {"poses/sonar_true.tum", "poses/vehicle.tum", "truth/occupancy.bt"});
  }
  for (std::size_t s = 0; s < sweeps; ++s) {
    for (std::string& file : SweepFiles(s, simulated, labels)) claim.files.push_back(file);
    claim.files.push_back(SweepRecordFile(s));
  }
  claim.record = "manifest.json";
  claim.force = force;
  return claim;
}

// Readies an owned dataset directory for `config` (truth/ only when `simulated`). Returns true when
// a complete dataset of that very configuration is already there, every file the hash its
// manifest gives (nothing to do).
bool PrepareDirectory(const io::OutputDirectory& out, const std::string& config, bool simulated,
                      ResumeRecords& records) {
  const fs::path& root = out.root();
  if (records.ManifestComplete()) return true;
  for (const char* sub : {"beams", "images", "poses"}) fs::create_directories(root / sub);
  if (simulated) fs::create_directories(root / "truth");
  if (!fs::exists(root / kPartialMarker)) {
    WriteText(root / kPartialMarker,
              json{{"format", io::kDatasetFormat}, {"config_sha256", config}}.dump(2) + "\n");
  }
  return false;
}

// Writes manifest.json over the claimed files present (sha256 and size), then drops the marker
// and the sweeps' records.
void Finalize(const io::OutputDirectory& out, const std::vector<std::string>& claimed,
              json manifest, const ResumeRecords& records) {
  const fs::path& root = out.root();
  std::vector<std::string> files;
  for (const std::string& relative : claimed) {
    if (relative != "manifest.json" && relative != kPartialMarker &&
        !relative.starts_with(kSweepRecordFolder) && fs::is_regular_file(root / relative)) {
      files.push_back(relative);
    }
  }
  std::sort(files.begin(), files.end());
  json list = json::array();
  for (const auto& relative : files) {
    list.push_back({{"path", relative},
                    {"bytes", fs::file_size(root / relative)},
                    {"sha256", io::Sha256OfFile((root / relative).string())}});
  }
  manifest["files"] = list;
  WriteText(root / "manifest.json", manifest.dump(2) + "\n");
  records.RemoveAll(manifest.value("sweeps", std::size_t{0}));
  std::error_code ignored;
  fs::remove(root / kPartialMarker, ignored);
}

json ManifestBase(const mapping::SensorGeometry& sensor, std::size_t sweeps, std::size_t beams,
                  const std::string& config) {
  json m = {{"format", io::kDatasetFormat},
            {"schema_version", io::kDatasetSchemaVersion},
            {"tool", ReportHeader()["tool"]},
            {"config_sha256", config},
            {"units",
             {{"time", "s, since the start of the run"},
              {"length", "m"},
              {"head_angle", "rad in beam files; keys ending in _deg are degrees"},
              {"intensity", "8-bit, 0-255, one byte per range bin"}}},
            {"frames",
             {{"world", "right-handed, z up"},
              {"sonar",
               "x along head angle 0, z the head's rotation axis; a ray at head angle θ and "
               "elevation ε points along (cos θ cos ε, sin θ cos ε, sin ε)"},
              {"poses",
               "poses/sonar.tum holds T_world_sonar at each beam's time (head angle 0) as the "
               "navigation reports it (what a mapper uses); poses/sonar_true.tum the true one "
               "the beams were rendered from; poses/vehicle.tum the true T_world_vehicle"}}},
            {"quaternion_order", "x y z w (TUM: time tx ty tz qx qy qz qw), Hamilton"},
            {"beam_file",
             "little-endian: 'SBBEAMS1', u32 beam count, per beam f64 time_s, f64 "
             "head_angle_rad, f64 bin_size_m, u32 bin count, u8 intensities"},
            {"sensor", io::SensorGeometryJson(sensor)},
            {"sweeps", sweeps},
            {"beams_per_sweep", sensor.BeamsPerSweep()},
            {"beams", beams}};
  return m;
}

void WriteBeams(const fs::path& path, std::span<const mapping::Beam> beams) {
  WriteFileAtomically(path.string(), [&](std::ostream& out) { io::WriteBeamFile(out, beams); });
}

std::string TruthCsv(std::span<const SynthesizedBeam> beams, std::size_t first_index,
                     const Scene& scene) {
  std::string csv =
      "beam,time_s,head_angle_rad,first_hit_range_m,first_hit_mesh,axis_hit_range_m\n";
  for (std::size_t i = 0; i < beams.size(); ++i) {
    const SynthesizedBeam& b = beams[i];
    csv += std::to_string(first_index + i) + "," + Number(b.beam.time_s) + "," +
           Number(b.beam.head_angle_rad) + ",";
    if (b.truth.first_hit_range_m) {
      csv += Number(*b.truth.first_hit_range_m) + "," + scene.meshes[b.truth.first_hit_mesh].name;
    } else {
      csv += ",";
    }
    csv += ",";
    if (b.truth.axis_hit_range_m) csv += Number(*b.truth.axis_hit_range_m);
    csv += "\n";
  }
  return csv;
}

void WriteTruthOccupancy(const fs::path& path, const std::vector<TriangleMesh>& meshes,
                         double resolution) {
  octomap::OcTree tree(resolution);
  const mapping::KeySet cells = VoxelizeMeshes(meshes, tree);
  std::vector<octomap::OcTreeKey> sorted(cells.begin(), cells.end());
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) {
    return std::tie(a[0], a[1], a[2]) < std::tie(b[0], b[1], b[2]);
  });
  for (const auto& key : sorted) tree.updateNode(key, true, true);
  tree.updateInnerOccupancy();
  WriteFileAtomically(path.string(),
                      [&](std::ostream& out) { mapping::WriteOctomapBinary(tree, out); });
}

}  // namespace

void LabelFileBeams(std::span<const SynthesizedBeam> beams, int threads,
                    std::vector<io::BeamLabels>& out) {
  out.resize(beams.size());
  const int n_threads = threads > 0 ? threads : omp_get_max_threads();
  bool unnumbered = false;  // a mesh past the file's 16 bits (an exception cannot leave the loop)
#pragma omp parallel for num_threads(n_threads) schedule(static) reduction(|| : unnumbered)
  for (std::int64_t b = 0; b < static_cast<std::int64_t>(beams.size()); ++b) {
    const std::vector<BinLabel>& bins = beams[static_cast<std::size_t>(b)].labels;
    io::BeamLabels& labels = out[static_cast<std::size_t>(b)];
    labels.shares.resize(bins.size());
    labels.mesh.resize(bins.size());
    labels.point_sonar_m.resize(bins.size());
    for (std::size_t k = 0; k < bins.size(); ++k) {
      const BinLabel& bin = bins[k];
      io::ShareInto(bin.energy, labels.shares[k]);
      unnumbered = unnumbered || (bin.mesh != kNoMesh && bin.mesh >= io::kNoLabelMesh);
      labels.mesh[k] =
          bin.mesh == kNoMesh ? io::kNoLabelMesh : static_cast<std::uint16_t>(bin.mesh);
      labels.point_sonar_m[k] = bin.point_sonar_m;
    }
  }
  if (unnumbered) {
    throw InputError("the label files number meshes in 16 bits: a scene of at most " +
                     std::to_string(io::kNoLabelMesh) + " meshes");
  }
}

std::string SceneConfigHash(const Scene& scene, std::uint64_t seed) {
  json inputs = {{"tool", ReportHeader()["tool"]},
                 {"schema_version", io::kDatasetSchemaVersion},
                 {"seed", seed},
                 {"scene_sha256", io::Sha256OfFile(scene.file)},
                 {"sensor_model_sha256", io::Sha256OfFile(scene.sensor_model_file)}};
  json meshes = json::array();
  for (const MeshSpec& mesh : scene.meshes) {
    meshes.push_back(mesh.file.path.empty() ? json(nullptr)
                                            : json(io::Sha256OfFile(mesh.file.path)));
  }
  inputs["mesh_files_sha256"] = meshes;
  // The vehicle's part files too (a scene without parts hashes as it always did).
  if (!scene.vehicle.empty()) {
    json parts = json::array();
    for (const MeshSpec& part : scene.vehicle) {
      parts.push_back(part.file.path.empty() ? json(nullptr)
                                             : json(io::Sha256OfFile(part.file.path)));
    }
    inputs["vehicle_files_sha256"] = parts;
  }
  // The scenes it extends are part of it (a scene that extends none hashes as it always did).
  if (!scene.extends.empty()) {
    json bases = json::array();
    for (const std::string& file : scene.extends) bases.push_back(io::Sha256OfFile(file));
    inputs["extends_sha256"] = bases;
  }
  return io::Sha256(inputs.dump());
}

std::string DatasetConfigHash(const Scene& scene, std::uint64_t seed, bool labels) {
  const std::string scene_config = SceneConfigHash(scene, seed);
  return labels ? scene_config : io::Sha256(scene_config + "/without label files");
}

std::vector<std::string> SceneInputFiles(const Scene& scene) {
  std::vector<std::string> files = {scene.file, scene.sensor_model_file};
  files.insert(files.end(), scene.extends.begin(), scene.extends.end());
  for (const auto* list : {&scene.meshes, &scene.vehicle}) {
    for (const MeshSpec& mesh : *list) {
      if (!mesh.file.path.empty()) files.push_back(mesh.file.path);
    }
  }
  return files;
}

Shard ParseShard(const std::string& text) {
  // Digits, a slash, digits: nothing else, not even a blank.
  int k = 0;
  int n = 0;
  const char* end = text.data() + text.size();
  const auto [after_k, k_error] = std::from_chars(text.data(), end, k);
  const bool slash = k_error == std::errc() && after_k != end && *after_k == '/';
  const auto [after_n, n_error] =
      slash ? std::from_chars(after_k + 1, end, n) : std::from_chars_result{end, std::errc()};
  const bool digits = !text.empty() && std::isdigit(static_cast<unsigned char>(text.front())) &&
                      slash && after_k + 1 != end &&
                      std::isdigit(static_cast<unsigned char>(after_k[1]));
  if (!digits || n_error != std::errc() || after_n != end || n < 1 || k < 1 || k > n) {
    throw InputError("--shard " + io::Quoted(text) + ": expected K/N with 1 <= K <= N, e.g. 3/8");
  }
  return {k - 1, n};
}

std::optional<Shard> ShardFromSlurm() {
  const char* id = std::getenv("SLURM_ARRAY_TASK_ID");
  const char* count = std::getenv("SLURM_ARRAY_TASK_COUNT");
  if (id == nullptr || count == nullptr) return std::nullopt;
  const char* min = std::getenv("SLURM_ARRAY_TASK_MIN");
  auto number = [](const char* name, const char* value) {
    const std::string_view text(value);
    int v = -1;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || error != std::errc() || end != text.data() + text.size() || v < 0) {
      throw InputError(std::string("environment variable ") + name + "=" + io::Quoted(text) +
                       ": expected a non-negative integer");
    }
    return v;
  };
  const int task = number("SLURM_ARRAY_TASK_ID", id);
  const int tasks = number("SLURM_ARRAY_TASK_COUNT", count);
  const int first = min != nullptr ? number("SLURM_ARRAY_TASK_MIN", min) : 0;
  // --array=1-5:2 runs tasks 1, 3 and 5: a step of 2 between them.
  const char* step_text = std::getenv("SLURM_ARRAY_TASK_STEP");
  const int step = step_text != nullptr ? number("SLURM_ARRAY_TASK_STEP", step_text) : 1;
  if (tasks < 1 || step < 1 || task < first || (task - first) % step != 0 ||
      (task - first) / step >= tasks) {
    throw InputError("SLURM_ARRAY_TASK_ID " + std::to_string(task) + " is outside the array (min " +
                     std::to_string(first) + ", step " + std::to_string(step) + ", count " +
                     std::to_string(tasks) + "): pass --shard K/N");
  }
  return Shard{(task - first) / step, tasks};
}

namespace {

// The dataset's poses (reported, true, the vehicle's) and its truth occupancy.
void WritePosesAndTruth(const fs::path& root, const Scene& scene, std::uint64_t seed,
                        std::size_t beam_count, const std::vector<TriangleMesh>& meshes) {
  std::string sonar;
  std::string sonar_true;
  std::string vehicle;
  for (std::size_t b = 0; b < beam_count; ++b) {
    const ScheduledBeam scheduled = ScheduleBeam(scene, b);
    sonar += io::TumLine(scheduled.time_s, ReportedSonarPose(scene, b, scheduled.time_s, seed));
    sonar_true += io::TumLine(scheduled.time_s, scheduled.pose.T_world_sonar);
    vehicle += io::TumLine(scheduled.time_s, scene.trajectory.T_world_vehicle(scheduled.time_s));
  }
  WriteText(root / "poses/sonar.tum", sonar);
  WriteText(root / "poses/sonar_true.tum", sonar_true);
  WriteText(root / "poses/vehicle.tum", vehicle);
  WriteTruthOccupancy(root / "truth/occupancy.bt", meshes, scene.mapping.resolution_m);
}

// A simulated dataset's manifest.json.
json SimulatedManifest(const Scene& scene, const DatasetSummary& summary, std::uint64_t seed,
                       std::size_t beam_count, bool labels) {
  json manifest =
      ManifestBase(scene.sensor.geometry, summary.sweeps_total, beam_count, summary.config_sha256);
  manifest["source"] = "simulate";
  manifest["scene"] = {{"name", scene.name}, {"file", scene.file}};
  manifest["seed"] = seed;
  manifest["navigation_error"] = {
      {"drift_m_per_s", scene.navigation.drift_m_per_s},
      {"heading_drift_deg_per_s", scene.navigation.heading_drift_rad_per_s / mapping::kDegToRad},
      {"position_noise_m", scene.navigation.position_noise_m},
      {"heading_noise_deg", scene.navigation.heading_noise_rad / mapping::kDegToRad}};
  manifest["truth"] = {
      {"per_beam",
       "truth/sweep_NNNN.csv: beam, time_s, head_angle_rad, first_hit_range_m "
       "(nearest surface any ray of the beam's main lobe hit), first_hit_mesh, "
       "axis_hit_range_m; empty when nothing within range"},
      {"occupancy", "truth/occupancy.bt: every cell a mesh surface crosses, at resolution_m"},
      {"resolution_m", scene.mapping.resolution_m}};
  if (labels) {
    manifest["truth"]["labels"] =
        "truth/labels_NNNN.bin: per bin, each echo path's share of its power, the mesh that "
        "answers it directly and that mesh's strongest return's point (docs/dataset-format.md)";
    manifest["truth"]["paths"] = kEchoPathNames;
  }
  json mesh_names = json::array();
  for (const MeshSpec& mesh : scene.meshes) mesh_names.push_back(mesh.name);
  manifest["meshes"] = mesh_names;
  return manifest;
}

}  // namespace

DatasetSummary SimulateDataset(const Scene& scene, const std::string& dir,
                               const DatasetOptions& options) {
  const std::uint64_t seed = options.seed.value_or(scene.seed);
  DatasetSummary summary;
  summary.sweeps_total = static_cast<std::size_t>(scene.sweeps);
  summary.config_sha256 = DatasetConfigHash(scene, seed, options.labels);
  if (options.labels && scene.meshes.size() >= io::kNoLabelMesh) {
    throw InputError(scene.file + ": " + std::to_string(scene.meshes.size()) +
                     " meshes; the label files number meshes in 16 bits, at most " +
                     std::to_string(io::kNoLabelMesh) + " (--no-labels writes none)");
  }
  // The output directory checked, then the meshes' preflight, before the directory is made: bad
  // input leaves none.
  CheckOutputDirectory(dir);
  const SceneWorld world(scene);
  const BeamSynthesizer synthesizer = SceneSynthesizer(scene, world.tracer, seed);
  io::OutputClaim claim = DatasetClaim("simulate", summary.config_sha256, summary.sweeps_total,
                                       true, options.labels, options.force);
  claim.inputs = SceneInputFiles(scene);
  const io::OutputDirectory out(dir, claim);
  ResumeRecords records(out.root(), summary.config_sha256);
  if (PrepareDirectory(out, summary.config_sha256, true, records)) {
    summary.complete = summary.already_complete = true;
    return summary;
  }
  const fs::path& root = out.root();
  const std::size_t beam_count = ScenarioBeamCount(scene);
  const auto per_sweep = static_cast<std::size_t>(scene.sensor.geometry.BeamsPerSweep());
  const auto first_sweep = static_cast<std::size_t>(options.shard.index);
  const auto stride = static_cast<std::size_t>(options.shard.count);
  const std::size_t mine = first_sweep < summary.sweeps_total
                               ? (summary.sweeps_total - first_sweep + stride - 1) / stride
                               : 0;
  std::size_t handled = 0;
  std::vector<SynthesizedBeam> synthesized;  // a sweep's, its memory kept for the next
  std::vector<io::BeamLabels> label_beams;   // the same
  for (std::size_t s = first_sweep; s < summary.sweeps_total; s += stride) {
    const std::vector<std::string> sweep_files = SweepFiles(s, true, options.labels);
    if (records.Vouched(s, sweep_files)) {
      ++summary.sweeps_skipped;
    } else {
      const std::size_t first = s * per_sweep;
      SimulateBeamsInto(scene, synthesizer, seed, options.threads, first,
                        std::min(beam_count, first + per_sweep),
                        options.labels ? Labels::kKeep : Labels::kDrop, synthesized);
      const std::vector<mapping::Beam> beams = BeamsOf(synthesized);
      WriteBeams(root / io::SweepFile("beams", s, "bin"), beams);
      WriteText(root / io::SweepFile("truth", s, "csv"), TruthCsv(synthesized, first, scene));
      if (options.labels) {
        LabelFileBeams(synthesized, options.threads, label_beams);
        io::WriteLabelFile((root / io::LabelFile(s)).string(), label_beams);
      }
      WritePolarImage((root / io::SweepFile("images", s, "png")).string(), beams,
                      scene.name + ", seed " + std::to_string(seed) + ": sweep " +
                          std::to_string(s) + ", polar");
      records.Record(s, sweep_files);
      ++summary.sweeps_written;
    }
    if (options.progress) options.progress(++handled, mine);
  }

  for (std::size_t s = 0; s < summary.sweeps_total; ++s) {
    // Other shards' sweeps are still due.
    if (!records.Vouched(s, SweepFiles(s, true, options.labels))) return summary;
  }
  WritePosesAndTruth(root, scene, seed, beam_count, world.meshes);
  const json manifest = SimulatedManifest(scene, summary, seed, beam_count, options.labels);
  Finalize(out, claim.files, manifest, records);
  summary.complete = true;
  return summary;
}

ImportedLog ImportedMatLog(io::MatLog log) {
  return {std::move(log.beams), log.truncated_beams, json::object(), json::object()};
}

DatasetSummary ImportLogDataset(const std::string& log_path, const ImportedLog& log,
                                const mapping::SensorGeometry& sensor, const std::string& dir,
                                bool force, const std::string& sensor_file) {
  DatasetSummary summary;
  const auto per_sweep = static_cast<std::size_t>(sensor.BeamsPerSweep());
  summary.sweeps_total = (log.beams.size() + per_sweep - 1) / per_sweep;
  json inputs = {{"tool", ReportHeader()["tool"]},
                 {"log_sha256", io::Sha256OfFile(log_path)},
                 {"sensor", io::SensorGeometryJson(sensor)}};
  if (!log.options.empty()) inputs["options"] = log.options;
  summary.config_sha256 = io::Sha256(inputs.dump());
  CheckOutputDirectory(dir);
  io::OutputClaim claim =
      DatasetClaim("import", summary.config_sha256, summary.sweeps_total, false, false, force);
  claim.inputs = {log_path};
  if (!sensor_file.empty()) claim.inputs.push_back(sensor_file);
  const io::OutputDirectory out(dir, claim);
  ResumeRecords records(out.root(), summary.config_sha256);
  if (PrepareDirectory(out, summary.config_sha256, false, records)) {
    summary.complete = summary.already_complete = true;
    return summary;
  }
  const fs::path& root = out.root();
  const std::span<const mapping::Beam> all(log.beams);
  std::string poses;
  for (std::size_t s = 0; s < summary.sweeps_total; ++s) {
    const auto sweep = all.subspan(s * per_sweep, std::min(per_sweep, all.size() - s * per_sweep));
    const std::vector<std::string> sweep_files = SweepFiles(s, false, false);
    if (records.Vouched(s, sweep_files)) {
      ++summary.sweeps_skipped;
    } else {
      WriteBeams(root / io::SweepFile("beams", s, "bin"), sweep);
      WritePolarImage(
          (root / io::SweepFile("images", s, "png")).string(), sweep,
          fs::path(log_path).filename().string() + ": sweep " + std::to_string(s) + ", polar");
      records.Record(s, sweep_files);
      ++summary.sweeps_written;
    }
  }
  for (const mapping::Beam& beam : log.beams) poses += io::TumLine(beam.time_s, beam.T_world_sonar);
  WriteText(root / "poses/sonar.tum", poses);
  json manifest =
      ManifestBase(sensor, summary.sweeps_total, log.beams.size(), summary.config_sha256);
  manifest["source"] = "import";
  manifest["log"] = {{"file", log_path}, {"truncated_beams", log.truncated_beams}};
  manifest["log"].update(log.info);
  manifest["seed"] = nullptr;
  manifest["truth"] = nullptr;
  Finalize(out, claim.files, manifest, records);
  summary.complete = true;
  return summary;
}

}  // namespace sonarbench::sim
