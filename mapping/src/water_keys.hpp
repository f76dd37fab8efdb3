#pragma once

#include <cstdint>

#include "sonarbench/mapping/mapper_config.hpp"

namespace sonarbench::mapping {

/// The z keys (OctoMap's, at one resolution) of the cells a WaterColumn holds: those whose box
/// reaches the water, the floor's and the surface's own cells included.
struct WaterKeys {
  std::uint64_t z_min = 0;
  std::uint64_t z_max = 0xffff;

  /// Whether every cell is held: no bound known.
  [[nodiscard]] bool all() const { return z_min == 0 && z_max == 0xffff; }
  /// Whether the cell of `packed` (PackKey) is held.
  [[nodiscard]] bool Holds(std::uint64_t packed) const {
    const std::uint64_t z = packed & 0xffff;
    return z >= z_min && z <= z_max;
  }
};

/// The keys of `water`'s cells at `resolution_m`: cell k spans z in [(k - 2^15) r, (k - 2^15 + 1)
/// r) and is held when its top reaches the floor and its bottom the surface.
[[nodiscard]] WaterKeys WaterKeysOf(const WaterColumn& water, double resolution_m);

}  // namespace sonarbench::mapping
