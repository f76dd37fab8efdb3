#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string_view>

#include "sonarbench/io/labels.hpp"

namespace sonarbench::sim {

/// The paths a range bin's echo energy arrives by (io::EchoPath). Direct: from a scene surface,
/// heard in the beam's main lobe; multipath: after one or more mirror bounces; sidelobe: a
/// direct echo heard through the sidelobes or back lobe; second trip and reverberation: the
/// tank's answers to the echoes (docs/physics.md); vehicle: the vehicle's parts and the head's
/// own self-reflection; noise: the receiver's, what is left.
using io::EchoPath;
using io::kEchoPathNames;
using io::kEchoPaths;

/// No scene mesh answers the bin directly.
inline constexpr std::uint32_t kNoMesh = std::numeric_limits<std::uint32_t>::max();

/// One range bin's truth: its power before the converter split by path (linear, the units of the
/// receiver's power, in float; their sum is the bin's power), the scene mesh with the most direct
/// energy in it, and that mesh's strongest direct return starting from a pulse length (whole
/// bins) before the bin to the bin's end: its point in the sonar frame [m] (kNoMesh and NaN
/// without one), at elevation asin(z / |p|) in the beam.
struct BinLabel {
  std::array<float, kEchoPaths> energy{};
  std::uint32_t mesh = kNoMesh;
  Eigen::Vector3f point_sonar_m =
      Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
};

}  // namespace sonarbench::sim
