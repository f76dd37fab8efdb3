#include "sonarbench/io/labels.hpp"

#include <zstd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <numeric>

#include "sonarbench/mapping/atomic_file.hpp"
#include "sonarbench/mapping/error.hpp"

namespace sonarbench::io {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the label file layout is little-endian; add byte swapping for this platform");

constexpr char kLabelMagic[8] = {'S', 'B', 'L', 'A', 'B', 'E', 'L', '1'};
constexpr unsigned long long kMaxLabelBytes = 1ULL << 30;
constexpr int kZstdLevel = 9;
// The paths stored, noise last and left out: 255 less the others.
constexpr std::size_t kStoredPaths = kEchoPaths - 1;
static_assert(static_cast<std::size_t>(EchoPath::kNoise) == kStoredPaths);

template <typename T>
void Put(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

// Reads the decompressed payload front to back, refusing to read past its end.
class Payload {
 public:
  Payload(const std::string& bytes, const std::string& path) : bytes_(bytes), path_(path) {}

  template <typename T>
  T Get(const char* what) {
    if (at_ + sizeof(T) > bytes_.size()) {
      throw InputError(path_ + ": truncated in " + what + " (byte " + std::to_string(at_) + ")");
    }
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof value);
    at_ += sizeof value;
    return value;
  }
  // Refuses `count` items of `size` bytes that the payload cannot hold.
  void Expect(std::size_t count, std::size_t size, const char* what) const {
    if (count > (bytes_.size() - at_) / size) {
      throw InputError(path_ + ": " + std::to_string(count) + " " + what +
                       " do not fit in the file's remaining " +
                       std::to_string(bytes_.size() - at_) + " bytes");
    }
  }
  [[nodiscard]] bool AtEnd() const { return at_ == bytes_.size(); }

 private:
  const std::string& bytes_;
  const std::string& path_;
  std::size_t at_ = 0;
};

std::string Encode(std::span<const BeamLabels> beams) {
  std::string raw(kLabelMagic, sizeof kLabelMagic);
  Put<std::uint32_t>(raw, static_cast<std::uint32_t>(beams.size()));
  Put<std::uint32_t>(raw, static_cast<std::uint32_t>(kEchoPaths));
  for (const BeamLabels& beam : beams) {
    const std::size_t bins = beam.shares.size();
    Put<std::uint32_t>(raw, static_cast<std::uint32_t>(bins));
    for (std::size_t p = 0; p < kStoredPaths; ++p) {
      for (std::size_t k = 0; k < bins; ++k) raw.push_back(static_cast<char>(beam.shares[k][p]));
    }
    for (std::size_t k = 0; k < bins; ++k) Put<std::uint16_t>(raw, beam.mesh[k]);
    std::vector<std::uint32_t> points;
    for (std::size_t k = 0; k < bins; ++k) {
      if (beam.mesh[k] != kNoLabelMesh) points.push_back(static_cast<std::uint32_t>(k));
    }
    Put<std::uint32_t>(raw, static_cast<std::uint32_t>(points.size()));
    for (const std::uint32_t k : points) Put<std::uint32_t>(raw, k);
    for (int i = 0; i < 3; ++i) {
      for (const std::uint32_t k : points) Put<float>(raw, beam.point_sonar_m[k][i]);
    }
  }
  std::string frame(ZSTD_compressBound(raw.size()), '\0');
  const std::size_t n =
      ZSTD_compress(frame.data(), frame.size(), raw.data(), raw.size(), kZstdLevel);
  if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
  frame.resize(n);
  return frame;
}

std::string Decompress(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open file");
  const std::string frame((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const unsigned long long size = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN) {
    throw InputError(path + ": not a label file (expected one zstd frame that states its size)");
  }
  if (size > kMaxLabelBytes) {
    throw InputError(path + ": its frame holds " + std::to_string(size) +
                     " bytes; at most 1 GiB is read");
  }
  std::string raw(static_cast<std::size_t>(size), '\0');
  const std::size_t n = ZSTD_decompress(raw.data(), raw.size(), frame.data(), frame.size());
  if (ZSTD_isError(n) || n != raw.size()) {
    throw InputError(path + ": its zstd frame does not decompress to the size it states");
  }
  return raw;
}

BeamLabels ReadBeam(Payload& in, const std::string& path, std::size_t b) {
  const std::string where = "beam " + std::to_string(b);
  const auto bins = in.Get<std::uint32_t>("a beam's bin count");
  in.Expect(bins, kStoredPaths + sizeof(std::uint16_t), "bins");
  BeamLabels beam;
  beam.shares.resize(bins);
  beam.mesh.resize(bins);
  beam.point_sonar_m.assign(bins, Eigen::Vector3f::Constant(std::nanf("")));
  for (std::size_t p = 0; p < kStoredPaths; ++p) {
    for (std::size_t k = 0; k < bins; ++k) beam.shares[k][p] = in.Get<std::uint8_t>("shares");
  }
  for (std::size_t k = 0; k < bins; ++k) {
    const unsigned sum = std::accumulate(beam.shares[k].begin(), beam.shares[k].end(), 0U);
    if (sum > 255) {
      throw InputError(path + ": " + where + ", bin " + std::to_string(k) + ": shares sum to " +
                       std::to_string(sum) + ", expected at most 255");
    }
    beam.shares[k][kStoredPaths] = static_cast<std::uint8_t>(255 - sum);
  }
  for (std::size_t k = 0; k < bins; ++k) beam.mesh[k] = in.Get<std::uint16_t>("meshes");
  const auto points = in.Get<std::uint32_t>("the point count");
  in.Expect(points, 4 + 3 * sizeof(float), "points");
  std::vector<std::uint32_t> at(points);
  for (std::uint32_t& k : at) {
    k = in.Get<std::uint32_t>("a point's bin");
    if (k >= bins || beam.mesh[k] == kNoLabelMesh) {
      throw InputError(path + ": " + where + ": a point at bin " + std::to_string(k) +
                       ", which has no mesh");
    }
  }
  for (int i = 0; i < 3; ++i) {
    for (const std::uint32_t k : at) beam.point_sonar_m[k][i] = in.Get<float>("a point");
  }
  return beam;
}

}  // namespace

std::string LabelFile(std::size_t sweep) {
  std::string digits = std::to_string(sweep);
  if (digits.size() < 4) digits.insert(0, 4 - digits.size(), '0');
  return "truth/labels_" + digits + ".bin";
}

std::array<std::uint8_t, kEchoPaths> ShareOf(std::span<const float, kEchoPaths> energy) {
  std::array<std::uint8_t, kEchoPaths> shares{};
  double total = 0.0;
  for (const float e : energy) total += std::max<double>(e, 0.0);
  if (!(total > 0.0)) {
    shares[static_cast<std::size_t>(EchoPath::kNoise)] = 255;
    return shares;
  }
  std::array<double, kEchoPaths> rest{};
  int given = 0;
  for (std::size_t p = 0; p < kEchoPaths; ++p) {
    const double exact = 255.0 * std::max<double>(energy[p], 0.0) / total;
    shares[p] = static_cast<std::uint8_t>(std::min(255.0, std::floor(exact)));
    rest[p] = exact - shares[p];
    given += shares[p];
  }
  // The largest remainders (the earlier path on a tie) take what rounding down left.
  std::array<std::size_t, kEchoPaths> order{};
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return rest[a] > rest[b]; });
  for (std::size_t i = 0; given < 255; ++i, ++given) ++shares[order[i % kEchoPaths]];
  return shares;
}

void WriteLabelFile(const std::string& path, std::span<const BeamLabels> beams) {
  const std::string frame = Encode(beams);
  WriteFileAtomically(path, [&](std::ostream& out) {
    out.write(frame.data(), static_cast<std::streamsize>(frame.size()));
  });
}

std::vector<BeamLabels> ReadDatasetLabels(const std::string& dir, const Dataset& dataset) {
  std::vector<BeamLabels> beams;
  const nlohmann::json& files = dataset.manifest["files"];
  if (std::none_of(files.begin(), files.end(),
                   [](const nlohmann::json& f) { return f.value("path", "") == LabelFile(0); })) {
    return beams;
  }
  for (std::size_t s = 0; s < dataset.sweeps; ++s) {
    std::vector<BeamLabels> sweep = ReadLabelFile(dir + "/" + LabelFile(s));
    std::move(sweep.begin(), sweep.end(), std::back_inserter(beams));
  }
  if (beams.size() != dataset.beams.size()) {
    throw InputError(dir + ": the label files hold " + std::to_string(beams.size()) +
                     " beams, expected one for each of the " +
                     std::to_string(dataset.beams.size()));
  }
  return beams;
}

std::vector<BeamLabels> ReadLabelFile(const std::string& path) {
  const std::string raw = Decompress(path);
  Payload in(raw, path);
  char magic[8];
  for (char& c : magic) c = in.Get<char>("the magic");
  if (std::memcmp(magic, kLabelMagic, sizeof magic) != 0) {
    throw InputError(path + ": not a sonarbench label file (expected the magic 'SBLABEL1')");
  }
  const auto count = in.Get<std::uint32_t>("the beam count");
  const auto paths = in.Get<std::uint32_t>("the path count");
  if (paths != kEchoPaths) {
    throw InputError(path + ": " + std::to_string(paths) + " paths, expected " +
                     std::to_string(kEchoPaths));
  }
  in.Expect(count, 4 + 4, "beams");
  std::vector<BeamLabels> beams;
  beams.reserve(count);
  for (std::uint32_t b = 0; b < count; ++b) beams.push_back(ReadBeam(in, path, b));
  if (!in.AtEnd()) throw InputError(path + ": bytes after the last beam");
  return beams;
}

}  // namespace sonarbench::io
