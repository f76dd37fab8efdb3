#include "dataset_resume.hpp"

#include <nlohmann/json.hpp>
#include <optional>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/io/dataset.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/labels.hpp"

namespace sonarbench::sim {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::optional<json> ReadRecord(const fs::path& file) {
  std::error_code error;
  if (!fs::is_regular_file(fs::symlink_status(file, error))) return std::nullopt;
  try {
    json record = json::parse(ReadFileBytes(file.string(), kMaxJsonBytes));
    if (record.is_object()) return record;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

// Whether `file` (under `root`) is a regular file whose sha256 is `sha256`.
bool HasHash(const fs::path& root, const std::string& file, const std::string& sha256) {
  std::error_code error;
  if (sha256.empty() || !fs::is_regular_file(fs::symlink_status(root / file, error))) return false;
  try {
    return io::Sha256OfFile((root / file).string()) == sha256;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

std::string SweepRecordFile(std::size_t sweep) {
  return io::SweepFile(kSweepRecordFolder, sweep, "json");
}

std::vector<std::string> SweepFiles(std::size_t sweep, bool simulated, bool labels) {
  std::vector<std::string> files = {io::SweepFile("beams", sweep, "bin"),
                                    io::SweepFile("images", sweep, "png")};
  if (simulated) files.push_back(io::SweepFile("truth", sweep, "csv"));
  if (labels) files.push_back(io::LabelFile(sweep));
  return files;
}

ResumeRecords::ResumeRecords(fs::path root, std::string config)
    : root_(std::move(root)), config_(std::move(config)) {
  const auto manifest = ReadRecord(root_ / "manifest.json");
  if (!manifest || manifest->value("config_sha256", "") != config_ ||
      !manifest->contains("files") || !(*manifest)["files"].is_array()) {
    return;
  }
  for (const json& entry : (*manifest)["files"]) {
    if (entry.is_object() && entry.value("path", json()).is_string() &&
        entry.value("sha256", json()).is_string()) {
      manifest_[entry["path"].get<std::string>()] = entry["sha256"].get<std::string>();
    }
  }
}

bool ResumeRecords::ManifestComplete() {
  if (manifest_.empty()) return false;
  for (const auto& [file, sha256] : manifest_) {
    if (!HasHash(root_, file, sha256)) {
      std::error_code ignored;
      fs::remove(root_ / "manifest.json", ignored);
      return false;
    }
  }
  return true;
}

std::map<std::string, std::string> ResumeRecords::SweepHashes(std::size_t sweep) const {
  std::map<std::string, std::string> hashes;
  const auto record = ReadRecord(root_ / SweepRecordFile(sweep));
  if (!record || record->value("config_sha256", "") != config_ || !record->contains("files") ||
      !(*record)["files"].is_object()) {
    return hashes;
  }
  for (const auto& [file, sha256] : (*record)["files"].items()) {
    if (sha256.is_string()) hashes[file] = sha256.get<std::string>();
  }
  return hashes;
}

bool ResumeRecords::Vouched(std::size_t sweep, const std::vector<std::string>& files) const {
  const std::map<std::string, std::string> recorded = SweepHashes(sweep);
  for (const std::string& file : files) {
    const auto in_record = recorded.find(file);
    const auto in_manifest = manifest_.find(file);
    const bool vouched =
        (in_record != recorded.end() && HasHash(root_, file, in_record->second)) ||
        (in_manifest != manifest_.end() && HasHash(root_, file, in_manifest->second));
    if (!vouched) return false;
  }
  return true;
}

void ResumeRecords::Record(std::size_t sweep, const std::vector<std::string>& files) const {
  json hashes = json::object();
  for (const std::string& file : files) hashes[file] = io::Sha256OfFile((root_ / file).string());
  const json record = {{"config_sha256", config_}, {"files", hashes}};
  std::error_code error;
  fs::create_directories(root_ / kSweepRecordFolder, error);
  WriteFileAtomically((root_ / SweepRecordFile(sweep)).string(),
                      [&](std::ostream& out) { out << record.dump(2) << "\n"; });
}

void ResumeRecords::RemoveAll(std::size_t sweeps) const {
  std::error_code ignored;
  for (std::size_t s = 0; s < sweeps; ++s) fs::remove(root_ / SweepRecordFile(s), ignored);
  fs::remove(root_ / kSweepRecordFolder, ignored);  // when empty
}

}  // namespace sonarbench::sim
