#include "sonarbench/io/numpy_export.hpp"

#include <filesystem>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/labels.hpp"
#include "sonarbench/io/npz.hpp"
#include "sonarbench/io/version.hpp"

namespace sonarbench::io {
namespace {

namespace fs = std::filesystem;

template <typename T>
std::string_view Bytes(const std::vector<T>& v) {
  return {reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T)};
}

// Poses as rows of tx ty tz qx qy qz qw.
void AppendPose(std::vector<double>& out, const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d& t = pose.translation();
  out.insert(out.end(), {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()});
}

void AddStrings(NpzArchive& npz, const std::string& name, const std::vector<std::string>& strings) {
  const auto [bytes, width] = NumpyUnicode(strings);
  npz.Add(name, "<U" + std::to_string(width), {strings.size()}, bytes);
}

// A simulated dataset's labels (ReadDatasetLabels: a beam each) as sweeps × beams × bins arrays,
// beam b in slot b as the intensities are.
void AddLabels(NpzArchive& npz, const std::vector<BeamLabels>& labels, const Dataset& d,
               std::size_t per_sweep, std::size_t bins) {
  const std::size_t cells = d.sweeps * per_sweep * bins;
  std::vector<std::uint8_t> shares(cells * kEchoPaths, 0);
  std::vector<std::uint16_t> mesh(cells, kNoLabelMesh);
  std::vector<float> point(cells * 3, std::nanf(""));
  for (std::size_t b = 0; b < labels.size(); ++b) {
    if (labels[b].shares.size() > bins) {
      throw InputError("label of beam " + std::to_string(b) + ": " +
                       std::to_string(labels[b].shares.size()) + " bins, expected at most " +
                       std::to_string(bins));
    }
    for (std::size_t k = 0; k < labels[b].shares.size(); ++k) {
      const std::size_t at = b * bins + k;
      std::copy(labels[b].shares[k].begin(), labels[b].shares[k].end(),
                shares.begin() + static_cast<std::ptrdiff_t>(at * kEchoPaths));
      mesh[at] = labels[b].mesh[k];
      for (int i = 0; i < 3; ++i)
        point[at * 3 + static_cast<std::size_t>(i)] = labels[b].point_sonar_m[k][i];
    }
  }
  npz.Add("label_shares", "|u1", {d.sweeps, per_sweep, bins, kEchoPaths}, Bytes(shares));
  npz.Add("label_mesh", "<u2", {d.sweeps, per_sweep, bins}, Bytes(mesh));
  npz.Add("label_point_sonar_m", "<f4", {d.sweeps, per_sweep, bins, 3}, Bytes(point));
  AddStrings(npz, "label_paths", {kEchoPathNames.begin(), kEchoPathNames.end()});
  AddStrings(npz, "mesh_names", d.manifest.value("meshes", std::vector<std::string>{}));
}

}  // namespace

void WriteNpzFromDataset(const std::string& dir, const std::string& path, bool force) {
  const Dataset d = ReadDataset(dir);
  const auto per_sweep = static_cast<std::size_t>(d.sensor.BeamsPerSweep());
  // The longest beam's bins: a truncated beam is padded with zeros (bin_count says where).
  std::size_t bins = static_cast<std::size_t>(d.sensor.num_bins);
  for (const mapping::Beam& beam : d.beams) bins = std::max(bins, beam.intensities.size());
  ClaimExportFile(path, force, NpzComment(path).value_or("").rfind("sonarbench", 0) == 0,
                  "an .npz file");
  // A killed export's archive starts with the local header of its first array.
  RemoveDeadTemporaries(path, [](const std::string& head) {
    return head.starts_with("PK\x03\x04") && head.size() >= 45 &&
           head.compare(30, 15, "intensities.npy") == 0;
  });
  const std::size_t slots = d.sweeps * per_sweep;
  std::vector<std::uint8_t> intensities(slots * bins, 0);
  std::vector<std::uint8_t> valid(slots, 0);
  std::vector<std::uint32_t> bin_count(slots, 0);
  std::vector<double> time(slots, 0.0), head(slots, 0.0), pose;
  pose.reserve(slots * 7);
  for (std::size_t b = 0; b < slots; ++b) {
    if (b >= d.beams.size()) {
      AppendPose(pose, Eigen::Isometry3d::Identity());
      continue;
    }
    const mapping::Beam& beam = d.beams[b];
    std::copy(beam.intensities.begin(), beam.intensities.end(),
              intensities.begin() + static_cast<std::ptrdiff_t>(b * bins));
    valid[b] = 1;
    bin_count[b] = static_cast<std::uint32_t>(beam.intensities.size());
    time[b] = beam.time_s;
    head[b] = beam.head_angle_rad;
    AppendPose(pose, beam.T_world_sonar);
  }
  NpzArchive npz;
  npz.Add("intensities", "|u1", {d.sweeps, per_sweep, bins}, Bytes(intensities));
  npz.Add("valid", "|b1", {d.sweeps, per_sweep}, Bytes(valid));
  npz.Add("bin_count", "<u4", {d.sweeps, per_sweep}, Bytes(bin_count));
  npz.Add("time_s", "<f8", {d.sweeps, per_sweep}, Bytes(time));
  npz.Add("head_angle_rad", "<f8", {d.sweeps, per_sweep}, Bytes(head));
  npz.Add("sonar_pose", "<f8", {d.sweeps, per_sweep, 7}, Bytes(pose));
  const std::vector<double> bin_size = {d.sensor.bin_size_m};
  npz.Add("bin_size_m", "<f8", {}, Bytes(bin_size));
  if (d.manifest.value("source", "") == "simulate") {
    std::vector<double> true_pose;
    for (const StampedPose& p : ReadTum((fs::path(dir) / "poses/sonar_true.tum").string())) {
      AppendPose(true_pose, p.pose);
    }
    true_pose.resize(slots * 7, 0.0);
    npz.Add("sonar_pose_true", "<f8", {d.sweeps, per_sweep, 7}, Bytes(true_pose));
    const std::vector<BeamLabels> labels = ReadDatasetLabels(dir, d);
    if (!labels.empty()) AddLabels(npz, labels, d, per_sweep, bins);
  }
  WriteFileAtomically(path, [&](std::ostream& out) {
    npz.Write(out, std::string("sonarbench ") + kVersion + ": " + dir);
  });
}

}  // namespace sonarbench::io
