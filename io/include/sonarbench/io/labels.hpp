#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sonarbench/io/dataset.hpp"

namespace sonarbench::io {

/// The paths a range bin's echo energy arrives by, in the label file's order
/// (docs/dataset-format.md, truth/labels_NNNN.bin).
enum class EchoPath : std::uint8_t {
  kDirect,
  kMultipath,
  kSidelobe,
  kSecondTrip,
  kReverberation,
  kVehicle,
  kNoise
};
inline constexpr std::size_t kEchoPaths = 7;
inline constexpr std::array<std::string_view, kEchoPaths> kEchoPathNames = {
    "direct", "multipath", "sidelobe", "second_trip", "reverberation", "vehicle", "noise"};

/// A bin no scene mesh answers directly.
inline constexpr std::uint16_t kNoLabelMesh = 0xFFFF;

/// One beam's labels as a label file holds them, per bin: each path's share of the bin's power
/// in 255ths (summing to 255), the scene mesh with the most direct energy (its index in the
/// manifest's `meshes`, or kNoLabelMesh), and, where there is one, the point of that mesh's
/// strongest direct return in the sonar frame [m] (NaN elsewhere).
struct BeamLabels {
  std::vector<std::array<std::uint8_t, kEchoPaths>> shares;
  std::vector<std::uint16_t> mesh;
  std::vector<Eigen::Vector3f> point_sonar_m;
};

/// The path with the most of a bin's power or shares (the first among equals); noise where the
/// bin holds none.
template <typename T>
[[nodiscard]] EchoPath DominantPath(const std::array<T, kEchoPaths>& power) {
  const auto most = std::max_element(power.begin(), power.end());
  return *most > T{0} ? static_cast<EchoPath>(most - power.begin()) : EchoPath::kNoise;
}

/// Sweep `sweep`'s label file in a dataset: "truth/labels_0012.bin".
[[nodiscard]] std::string LabelFile(std::size_t sweep);

/// Each path's share of `energy` in 255ths into `shares`, rounded so that they sum to 255
/// (largest remainders); all noise when `energy` sums to nothing. Inline, writing in place: the
/// dataset writer calls it for every bin, and a 7-byte array returned is shuffled through memory.
inline void ShareInto(std::span<const float, kEchoPaths> energy,
                      std::span<std::uint8_t, kEchoPaths> shares) {
  // A path without power (zero, negative or NaN) counts as 0: share and remainder 0. Branchless
  // over the paths, so the compiler forms them side by side.
  std::array<double, kEchoPaths> power{};
  double total = 0.0;
  std::size_t paths = 0;
  for (std::size_t p = 0; p < kEchoPaths; ++p) {
    power[p] = energy[p] > 0.0F ? static_cast<double>(energy[p]) : 0.0;
    total += power[p];
    paths += power[p] > 0.0 ? 1 : 0;
  }
  if (paths < 2 || !(total > 0.0)) {  // one path, or none (all noise): written at once
    std::size_t last = static_cast<std::size_t>(EchoPath::kNoise);
    for (std::size_t p = 0; p < kEchoPaths; ++p) last = power[p] > 0.0 ? p : last;
    for (std::size_t p = 0; p < kEchoPaths; ++p) shares[p] = p == last ? 255 : 0;
    return;
  }
  std::array<int, kEchoPaths> whole{};
  std::array<double, kEchoPaths> rest{};
  int given = 0;
  for (std::size_t p = 0; p < kEchoPaths; ++p) {
    const double exact = std::min(255.0, 255.0 * power[p] / total);
    whole[p] = static_cast<int>(exact);  // exact ≥ 0: truncation is the floor
    rest[p] = exact - whole[p];
    given += whole[p];
  }
  // The largest remainders take what rounding down left, one each (fewer than kEchoPaths, as
  // each path lost less than one), the earlier path on a tie.
  for (; given < 255; ++given) {
    std::size_t most = 0;
    for (std::size_t p = 1; p < kEchoPaths; ++p) {
      if (rest[p] > rest[most]) most = p;
    }
    ++whole[most];
    rest[most] = -1.0;
  }
  for (std::size_t p = 0; p < kEchoPaths; ++p) shares[p] = static_cast<std::uint8_t>(whole[p]);
}

/// ShareInto's shares, returned.
[[nodiscard]] inline std::array<std::uint8_t, kEchoPaths> ShareOf(
    std::span<const float, kEchoPaths> energy) {
  std::array<std::uint8_t, kEchoPaths> shares{};
  ShareInto(energy, shares);
  return shares;
}

/// One sweep's label file as bytes: a zstd frame of the little-endian layout of
/// docs/dataset-format.md ("SBLABEL1", beam count, path count, then per beam its bins).
[[nodiscard]] std::string EncodeLabelFile(std::span<const BeamLabels> beams);
/// Writes one sweep's labels (EncodeLabelFile) atomically.
void WriteLabelFile(const std::string& path, std::span<const BeamLabels> beams);
/// A dataset's labels, beam by beam (every sweep's label file in turn), when its manifest lists
/// them (a simulated dataset); none otherwise. Throws InputError as ReadLabelFile does, or when
/// they do not hold one beam for each of `dataset`'s.
[[nodiscard]] std::vector<BeamLabels> ReadDatasetLabels(const std::string& dir,
                                                        const Dataset& dataset);

/// Reads a label file; throws InputError naming `path` on a bad frame, magic or size, before
/// allocating more than the frame says it holds (refused over `max_bytes`, and over 1 GiB).
[[nodiscard]] std::vector<BeamLabels> ReadLabelFile(const std::string& path,
                                                    std::uint64_t max_bytes = std::uint64_t{1}
                                                                              << 30);

}  // namespace sonarbench::io
