#pragma once

#include <Eigen/Geometry>
#include <istream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::io {

// The mapper's types these files hold.
using mapping::Beam;
using mapping::SensorGeometry;

/// The sonarbench dataset: a directory that `sonarbench simulate` and `sonarbench import` write
/// and `sonarbench map` reads (the format is documented in docs/dataset-format.md).
///
///   manifest.json             written last: format, schema_version, tool, units, frames,
///                             quaternion order, seed, config_sha256, sensor geometry, sweep and
///                             beam counts, and the sha256 and size of every other file
///   beams/sweep_NNNN.bin      every bin of every beam of sweep NNNN (WriteBeamFile)
///   images/sweep_NNNN.png     that sweep as a polar image
///   truth/sweep_NNNN.csv      per-beam ground truth (simulated datasets)
///   truth/occupancy.bt        the scene's surface cells at the mapping resolution (simulated)
///   poses/sonar.tum           the sonar's pose at each beam, TUM format, one line per beam
///   poses/vehicle.tum         the vehicle's pose at each beam (simulated datasets)
inline constexpr const char* kDatasetFormat = "sonarbench-dataset";
inline constexpr int kDatasetSchemaVersion = 1;

/// File name of sweep `sweep`'s file in `folder` with `extension`: "beams/sweep_0012.bin".
[[nodiscard]] std::string SweepFile(const std::string& folder, std::size_t sweep,
                                    const std::string& extension);

/// Writes beams in the dataset's binary layout, little-endian:
///   "SBBEAMS1" (8 bytes), u32 beam count, then per beam: f64 time_s, f64 head_angle_rad,
///   f64 bin_size_m, u32 bin count, that many u8 intensities.
/// Poses are not in this file: they are in poses/sonar.tum.
void WriteBeamFile(std::ostream& out, std::span<const Beam> beams);
/// Reads a beam file; throws InputError naming `name` on a bad magic, a short file or trailing
/// bytes.
[[nodiscard]] std::vector<Beam> ReadBeamFile(std::istream& in, const std::string& name);

/// One TUM trajectory line: "time tx ty tz qx qy qz qw" (quaternion x, y, z, w; Hamilton).
[[nodiscard]] std::string TumLine(double time_s, const Eigen::Isometry3d& pose);
struct StampedPose {
  double time_s = 0.0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};
/// Reads a TUM file ('#' lines are comments); throws InputError naming the file and line.
[[nodiscard]] std::vector<StampedPose> ReadTum(const std::string& path);

/// SHA-256 of a file's bytes, as 64 lowercase hex digits.
[[nodiscard]] std::string Sha256OfFile(const std::string& path);
/// SHA-256 of `bytes`.
[[nodiscard]] std::string Sha256(const std::string& bytes);

/// The sensor geometry as the manifest stores it (the keys of a sensor model's `geometry`).
[[nodiscard]] nlohmann::json SensorGeometryJson(const SensorGeometry& g);

/// A dataset read back: its sensor, every beam with its pose, and the manifest.
struct Dataset {
  SensorGeometry sensor;
  std::vector<Beam> beams;
  std::size_t sweeps = 0;
  nlohmann::json manifest;
};

/// Reads a dataset directory: checks the manifest's format and schema version, the sha256 of
/// every file it lists, and that poses match beams one to one. Throws InputError naming the
/// file and what was expected.
[[nodiscard]] Dataset ReadDataset(const std::string& dir);

}  // namespace sonarbench::io
