#include "sonarbench/io/dataset.hpp"

#include <openssl/evp.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/mapping_yaml.hpp"
#include "sonarbench/io/text.hpp"
#include "sonarbench/io/yaml_reader.hpp"

namespace sonarbench::io {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the beam file layout is little-endian; add byte swapping for this platform");

constexpr char kBeamMagic[8] = {'S', 'B', 'B', 'E', 'A', 'M', 'S', '1'};

template <typename T>
void Put(std::ostream& out, T value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof value);
}

template <typename T>
bool Get(std::istream& in, T& value) {
  return static_cast<bool>(in.read(reinterpret_cast<char*>(&value), sizeof value));
}

class Sha256Context {
 public:
  Sha256Context() : ctx_(EVP_MD_CTX_new(), &EVP_MD_CTX_free) {
    if (!ctx_ || EVP_DigestInit_ex(ctx_.get(), EVP_sha256(), nullptr) != 1)
      throw std::runtime_error("OpenSSL: SHA-256 unavailable");
  }
  void Update(const void* data, std::size_t size) {
    if (EVP_DigestUpdate(ctx_.get(), data, size) != 1)
      throw std::runtime_error("OpenSSL: SHA-256 update failed");
  }
  std::string HexDigest() {
    std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
    unsigned size = 0;
    if (EVP_DigestFinal_ex(ctx_.get(), digest.data(), &size) != 1)
      throw std::runtime_error("OpenSSL: SHA-256 final failed");
    std::string hex;
    char byte[3];
    for (unsigned i = 0; i < size; ++i) {
      std::snprintf(byte, sizeof byte, "%02x", digest[i]);
      hex += byte;
    }
    return hex;
  }

 private:
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx_;
};

}  // namespace

std::string SweepFile(const std::string& folder, std::size_t sweep, const std::string& extension) {
  char name[32];
  std::snprintf(name, sizeof name, "sweep_%04zu.", sweep);
  return folder + "/" + name + extension;
}

void WriteBeamFile(std::ostream& out, std::span<const Beam> beams) {
  out.write(kBeamMagic, sizeof kBeamMagic);
  Put<std::uint32_t>(out, static_cast<std::uint32_t>(beams.size()));
  for (const Beam& beam : beams) {
    Put<double>(out, beam.time_s);
    Put<double>(out, beam.head_angle_rad);
    Put<double>(out, beam.bin_size_m);
    Put<std::uint32_t>(out, static_cast<std::uint32_t>(beam.intensities.size()));
    out.write(reinterpret_cast<const char*>(beam.intensities.data()),
              static_cast<std::streamsize>(beam.intensities.size()));
  }
}

std::vector<Beam> ReadBeamFile(std::istream& in, const std::string& name) {
  char magic[8];
  if (!in.read(magic, sizeof magic) || std::memcmp(magic, kBeamMagic, sizeof magic) != 0) {
    throw InputError(name + ": not a sonarbench beam file (expected the magic 'SBBEAMS1')");
  }
  std::uint32_t count = 0;
  if (!Get(in, count)) throw InputError(name + ": truncated before the beam count");
  std::vector<Beam> beams;
  for (std::uint32_t b = 0; b < count; ++b) {
    Beam beam;
    std::uint32_t bins = 0;
    if (!Get(in, beam.time_s) || !Get(in, beam.head_angle_rad) || !Get(in, beam.bin_size_m) ||
        !Get(in, bins)) {
      throw InputError(name + ": truncated in the header of beam " + std::to_string(b) + " of " +
                       std::to_string(count));
    }
    if (!std::isfinite(beam.time_s) || !std::isfinite(beam.head_angle_rad) ||
        !(beam.bin_size_m > 0) || !std::isfinite(beam.bin_size_m) || bins > kMaxBinsPerBeam) {
      throw InputError(name + ": beam " + std::to_string(b) +
                       ": expected a finite time and head angle, a positive bin size and at "
                       "most " +
                       std::to_string(kMaxBinsPerBeam) + " bins");
    }
    beam.intensities.resize(bins);
    if (!in.read(reinterpret_cast<char*>(beam.intensities.data()), bins)) {
      throw InputError(name + ": truncated in the bins of beam " + std::to_string(b));
    }
    beams.push_back(std::move(beam));
  }
  if (in.peek() != std::char_traits<char>::eof()) {
    throw InputError(name + ": bytes after the last of its " + std::to_string(count) + " beams");
  }
  return beams;
}

std::string TumLine(double time_s, const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d& t = pose.translation();
  char line[256];
  std::snprintf(line, sizeof line, "%.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", time_s, t.x(),
                t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  return line;
}

// A poses file or a sweep's beam file: 10^6 lines or beams of a few hundred bytes.
constexpr std::uint64_t kMaxDatasetFileBytes = std::uint64_t{1} << 30;

std::vector<StampedPose> ReadTum(const std::string& path) {
  (void)CheckInputFile(path, kMaxDatasetFileBytes);  // a FIFO or device never opened
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot be read");
  std::vector<StampedPose> poses;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double v[8];
    for (double& x : v) fields >> x;
    std::string rest;
    if (!fields || (fields >> rest) ||
        !std::all_of(std::begin(v), std::end(v), [](double x) { return std::isfinite(x); })) {
      throw InputError(path + ":" + std::to_string(number) +
                       ": expected 8 finite numbers 'time tx ty tz qx qy qz qw', got " +
                       Quoted(line));
    }
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-6) {
      throw InputError(path + ":" + std::to_string(number) + ": the quaternion's norm is " +
                       Number(q.norm()) + ", expected 1");
    }
    StampedPose p;
    p.time_s = v[0];
    p.pose.linear() = q.normalized().toRotationMatrix();
    p.pose.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    poses.push_back(p);
  }
  return poses;
}

std::string Sha256(const std::string& bytes) {
  Sha256Context ctx;
  ctx.Update(bytes.data(), bytes.size());
  return ctx.HexDigest();
}

std::string Sha256OfFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot be read");
  Sha256Context ctx;
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    ctx.Update(buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  return ctx.HexDigest();
}

nlohmann::json SensorGeometryJson(const SensorGeometry& g) {
  return {{"beam_width_horizontal_deg", g.beam_width_horizontal_rad / mapping::kDegToRad},
          {"beam_width_vertical_deg", g.beam_width_vertical_rad / mapping::kDegToRad},
          {"num_bins", g.num_bins},
          {"bin_size_m", g.bin_size_m},
          {"step_angle_deg", g.step_angle_rad / mapping::kDegToRad},
          {"beams_per_second", g.beams_per_second},
          {"self_reflection_range_m", g.self_reflection_range_m}};
}

namespace {

// Checks that every file the manifest lists lies inside `root`, exists and has its sha256.
void CheckListedFiles(const std::filesystem::path& root, const std::string& dir,
                      const std::string& manifest_path, const nlohmann::json& manifest) {
  namespace fs = std::filesystem;
  if (!manifest.is_object() || !manifest.contains("files") || !manifest["files"].is_array()) {
    throw InputError(manifest_path + ": key 'files': expected a list of {path, sha256, bytes}");
  }
  const auto& files = manifest["files"];
  for (const auto& entry : files) {
    if (!entry.is_object() || !entry.contains("path") || !entry.contains("sha256") ||
        !entry["path"].is_string() || !entry["sha256"].is_string()) {
      throw InputError(manifest_path + ": key 'files': expected entries {path, sha256, bytes}");
    }
    const std::string relative = entry["path"];
    if (relative.find("..") != std::string::npos || fs::path(relative).is_absolute()) {
      throw InputError(manifest_path + ": file '" + relative + "': expected a path inside " + dir);
    }
    const std::string path = (root / relative).string();
    if (!fs::is_regular_file(path)) throw InputError(path + ": listed in the manifest, missing");
    if (Sha256OfFile(path) != entry["sha256"].get<std::string>()) {
      throw InputError(path +
                       ": its sha256 differs from the manifest's: the file changed or is "
                       "damaged");
    }
  }
}

// Sets each beam's pose from poses/sonar.tum, one per beam, stamped as the beam is.
void ReadPoses(const std::filesystem::path& root, std::vector<Beam>& beams) {
  const std::string poses_path = (root / "poses/sonar.tum").string();
  const std::vector<StampedPose> poses = ReadTum(poses_path);
  if (poses.size() != beams.size()) {
    throw InputError(poses_path + ": " + std::to_string(poses.size()) +
                     " poses, expected one per "
                     "beam (" +
                     std::to_string(beams.size()) + ")");
  }
  for (std::size_t b = 0; b < poses.size(); ++b) {
    if (std::abs(poses[b].time_s - beams[b].time_s) > 1e-6) {
      throw InputError(poses_path + ": pose " + std::to_string(b) + " is stamped " +
                       Number(poses[b].time_s) + " s, its beam " + Number(beams[b].time_s) + " s");
    }
    beams[b].T_world_sonar = poses[b].pose;
  }
}

}  // namespace

Dataset ReadDataset(const std::string& dir) {
  namespace fs = std::filesystem;
  const fs::path root(dir);
  const std::string manifest_path = (root / "manifest.json").string();
  if (!fs::is_regular_file(manifest_path)) {
    throw InputError(dir +
                     ": not a sonarbench dataset (no manifest.json; an interrupted "
                     "`sonarbench simulate` leaves none until it completes: rerun it)");
  }
  Dataset dataset;
  const std::string text = ReadFileBytes(manifest_path, kMaxJsonBytes);
  try {
    dataset.manifest = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // a syntax error, or a number past a double
    throw InputError(manifest_path + ": not valid JSON: " + e.what());
  }
  // JSON is YAML: the strict reader checks the keys the mapper needs, with line and column.
  YamlReader reader = YamlReader::FromString(text, manifest_path);
  std::string format;
  int schema = 0;
  int sweeps = 0;
  reader.Required("format", format, OneOf({kDatasetFormat}));
  reader.Required("schema_version", schema, IntInRange(1, kDatasetSchemaVersion));
  reader.Required("sweeps", sweeps, IntInRange(0, 10000000));
  YamlReader sensor = reader.Child("sensor");
  dataset.sensor = ReadSensorGeometry(sensor);
  reader.ThrowIfErrors();
  dataset.sweeps = static_cast<std::size_t>(sweeps);

  CheckListedFiles(root, dir, manifest_path, dataset.manifest);

  for (std::size_t s = 0; s < dataset.sweeps; ++s) {
    const std::string path = (root / SweepFile("beams", s, "bin")).string();
    if (std::filesystem::exists(path)) (void)CheckInputFile(path, kMaxDatasetFileBytes);
    std::ifstream in(path, std::ios::binary);
    if (!in)
      throw InputError(path + ": missing (the manifest counts " + std::to_string(dataset.sweeps) +
                       " sweeps)");
    for (Beam& beam : ReadBeamFile(in, path)) dataset.beams.push_back(std::move(beam));
  }
  ReadPoses(root, dataset.beams);
  return dataset;
}

}  // namespace sonarbench::io
