#include "sonarbench/io/labels.hpp"

#include <zstd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <numeric>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"

namespace sonarbench::io {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the label file layout is little-endian; add byte swapping for this platform");

constexpr char kLabelMagic[8] = {'S', 'B', 'L', 'A', 'B', 'E', 'L', '1'};
constexpr unsigned long long kMaxLabelBytes = 1ULL << 30;
constexpr int kZstdLevel = 1;  // 9: files 2-5% smaller, 6-7 times slower (docs/benchmarks.md)
// The paths stored, noise last and left out: 255 less the others.
constexpr std::size_t kStoredPaths = kEchoPaths - 1;
static_assert(static_cast<std::size_t>(EchoPath::kNoise) == kStoredPaths);

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

// A thread's zstd context and buffers, kept from one label file to the next: made afresh, their
// memory is mapped and zeroed for every file.
struct Compressor {
  std::unique_ptr<ZSTD_CCtx, decltype(&ZSTD_freeCCtx)> cctx{ZSTD_createCCtx(), ZSTD_freeCCtx};
  std::string chunk = std::string(ZSTD_CStreamOutSize(), '\0');
  std::string raw;
};

// A label file's bytes: put, then compressed a beam at a time (not the sweep's bytes at once)
// into one frame whose header holds the whole size, as the reader expects.
class FrameWriter {
 public:
  explicit FrameWriter(std::size_t total) : c_(ThreadCompressor()) {
    Check(ZSTD_CCtx_reset(c_.cctx.get(), ZSTD_reset_session_and_parameters));
    Check(ZSTD_CCtx_setParameter(c_.cctx.get(), ZSTD_c_compressionLevel, kZstdLevel));
    Check(ZSTD_CCtx_setPledgedSrcSize(c_.cctx.get(), total));
    c_.raw.clear();
  }
  // Room for `size` more bytes, filled by the Put calls that follow.
  void Reserve(std::size_t size) {
    const std::size_t before = c_.raw.size();
    c_.raw.resize(before + size);
    at_ = c_.raw.data() + before;
  }
  void Put(const void* bytes, std::size_t size) {
    if (size == 0) return;  // an empty beam's data() may be null, which memcpy must not see
    std::memcpy(at_, bytes, size);
    at_ += size;
  }
  void PutU32(std::size_t value) {
    const auto v = static_cast<std::uint32_t>(value);
    Put(&v, sizeof v);
  }
  // The next `size` bytes of the room reserved, to fill in place.
  std::uint8_t* Claim(std::size_t size) {
    auto* bytes = reinterpret_cast<std::uint8_t*>(at_);
    at_ += size;
    return bytes;
  }
  // Compresses what was put; `end` closes the frame.
  void Flush(bool end) {
    const ZSTD_EndDirective mode = end ? ZSTD_e_end : ZSTD_e_continue;
    ZSTD_inBuffer in{c_.raw.data(), c_.raw.size(), 0};
    std::size_t left = 0;
    do {
      ZSTD_outBuffer out{c_.chunk.data(), c_.chunk.size(), 0};
      left = Check(ZSTD_compressStream2(c_.cctx.get(), &out, &in, mode));
      frame_.append(c_.chunk.data(), out.pos);
    } while (end ? left != 0 : in.pos < in.size);
    c_.raw.clear();
  }
  [[nodiscard]] std::string& Frame() { return frame_; }

 private:
  static std::size_t Check(std::size_t code) {
    if (ZSTD_isError(code)) {
      throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(code));
    }
    return code;
  }
  static Compressor& ThreadCompressor() {
    thread_local Compressor compressor;
    return compressor;
  }
  Compressor& c_;
  std::string frame_;
  char* at_ = nullptr;
};

// The bins of `beam` with a mesh, hence a point.
void PointBins(const BeamLabels& beam, std::vector<std::uint32_t>& bins) {
  bins.clear();
  for (std::size_t k = 0; k < beam.mesh.size(); ++k) {
    if (beam.mesh[k] != kNoLabelMesh) bins.push_back(static_cast<std::uint32_t>(k));
  }
}

// A beam's bytes in the file.
std::size_t BeamBytes(std::size_t bins, std::size_t points) {
  return 8 + bins * (kStoredPaths + 2) + points * 16;
}

}  // namespace

std::string EncodeLabelFile(std::span<const BeamLabels> beams) {
  std::vector<std::uint32_t> points;
  std::size_t total = sizeof kLabelMagic + 8;
  for (const BeamLabels& beam : beams) {
    const auto with_mesh = std::count_if(beam.mesh.begin(), beam.mesh.end(),
                                         [](std::uint16_t m) { return m != kNoLabelMesh; });
    total += BeamBytes(beam.shares.size(), static_cast<std::size_t>(with_mesh));
  }
  FrameWriter out(total);
  out.Reserve(sizeof kLabelMagic + 8);
  out.Put(kLabelMagic, sizeof kLabelMagic);
  out.PutU32(beams.size());
  out.PutU32(kEchoPaths);
  for (const BeamLabels& beam : beams) {
    const std::size_t bins = beam.shares.size();
    PointBins(beam, points);
    out.Reserve(BeamBytes(bins, points.size()));
    out.PutU32(bins);
    std::uint8_t* const planes = out.Claim(kStoredPaths * bins);
    const std::array<std::uint8_t, kEchoPaths>* const shares = beam.shares.data();
    for (std::size_t p = 0; p < kStoredPaths; ++p) {
      for (std::size_t k = 0; k < bins; ++k) planes[p * bins + k] = shares[k][p];
    }
    out.Put(beam.mesh.data(), bins * sizeof(std::uint16_t));
    out.PutU32(points.size());
    out.Put(points.data(), points.size() * sizeof(std::uint32_t));
    std::uint8_t* const coordinates = out.Claim(3 * sizeof(float) * points.size());
    const Eigen::Vector3f* const point = beam.point_sonar_m.data();
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t j = 0; j < points.size(); ++j) {
        std::memcpy(coordinates + (i * points.size() + j) * sizeof(float), &point[points[j]][i],
                    sizeof(float));
      }
    }
    out.Flush(false);
  }
  out.Flush(true);
  return std::move(out.Frame());
}

namespace {

std::string Decompress(const std::string& path, std::uint64_t max_bytes) {
  // A frame is at most a little larger than what it holds.
  const std::string frame = ReadFileBytes(path, max_bytes + 4096);
  const unsigned long long size = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN) {
    throw InputError(path + ": not a label file (expected one zstd frame that states its size)");
  }
  if (size > max_bytes) {
    throw InputError(path + ": its frame states " + ByteCount(size) +
                     " uncompressed; expected at most " + ByteCount(max_bytes) +
                     " for the beams it labels");
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

void WriteLabelFile(const std::string& path, std::span<const BeamLabels> beams) {
  const std::string frame = EncodeLabelFile(beams);
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
  const std::size_t per_sweep = static_cast<std::size_t>(dataset.sensor.BeamsPerSweep());
  for (std::size_t s = 0; s < dataset.sweeps; ++s) {
    // What the sweep's beams can take: a generous 64 bytes a bin (a bin stores at most 21).
    std::uint64_t max_bytes = 4096;
    for (std::size_t b = s * per_sweep; b < std::min(dataset.beams.size(), (s + 1) * per_sweep);
         ++b) {
      max_bytes += 64 + 64 * std::uint64_t{dataset.beams[b].intensities.size()};
    }
    std::vector<BeamLabels> sweep = ReadLabelFile(dir + "/" + LabelFile(s), max_bytes);
    std::move(sweep.begin(), sweep.end(), std::back_inserter(beams));
  }
  if (beams.size() != dataset.beams.size()) {
    throw InputError(dir + ": the label files hold " + std::to_string(beams.size()) +
                     " beams, expected one for each of the " +
                     std::to_string(dataset.beams.size()));
  }
  return beams;
}

std::vector<BeamLabels> ReadLabelFile(const std::string& path, std::uint64_t max_bytes) {
  const std::string raw = Decompress(path, std::min<std::uint64_t>(max_bytes, kMaxLabelBytes));
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
