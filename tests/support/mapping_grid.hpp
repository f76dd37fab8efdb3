#pragma once

namespace sonarbench::test {

/// The voxel edge [m] the mapping tests build their maps at.
inline constexpr double kResolution = 0.05;

}  // namespace sonarbench::test
