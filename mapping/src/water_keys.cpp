#include "water_keys.hpp"

#include <algorithm>
#include <cmath>

namespace sonarbench::mapping {

WaterKeys WaterKeysOf(const WaterColumn& water, double resolution_m) {
  constexpr double kCentre = 32768.0;  // the key of the cell whose bottom is z = 0
  constexpr double kRounding = 1e-9;   // a plane on a cell face, up to the division's rounding
  WaterKeys keys;
  if (std::isfinite(water.floor_z_m)) {
    const double k = std::ceil(water.floor_z_m / resolution_m - kRounding) + kCentre - 1.0;
    keys.z_min = static_cast<std::uint64_t>(std::clamp(k, 0.0, 65535.0));
  }
  if (std::isfinite(water.surface_z_m)) {
    const double k = std::floor(water.surface_z_m / resolution_m + kRounding) + kCentre;
    keys.z_max = static_cast<std::uint64_t>(std::clamp(k, 0.0, 65535.0));
  }
  return keys;
}

}  // namespace sonarbench::mapping
