#pragma once

#include <octomap/OcTree.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "sonarbench/mapping/key_set.hpp"

namespace sonarbench::mapping {

/// Calls `visit(packed_key)` (see PackKey) for every cell the segment origin → end crosses before
/// the end point's cell, in order: the same keys, in the same order, as OctoMap's
/// OcTree::computeRayKeys (Amanatides & Woo's 3-D DDA, with OctoMap's float and double
/// arithmetic step for step), without filling a KeyRay first and with the packed key stepped in
/// place. Returns false, visiting nothing, if either point lies outside the tree's key range.
template <typename Visit>
bool ForEachRayKey(const octomap::OcTree& tree, const octomap::point3d& origin,
                   const octomap::point3d& end, Visit&& visit) {
  octomap::OcTreeKey key_origin;
  octomap::OcTreeKey key_end;
  if (!tree.coordToKeyChecked(origin, key_origin) || !tree.coordToKeyChecked(end, key_end)) {
    return false;
  }
  if (key_origin == key_end) return true;
  std::uint64_t current = PackKey(key_origin);
  const std::uint64_t last = PackKey(key_end);
  visit(current);

  octomap::point3d direction = end - origin;
  const float length = static_cast<float>(direction.norm());
  direction /= length;
  const double resolution = tree.getResolution();
  double t_max[3];
  double t_delta[3];
  std::uint64_t packed_step[3];  // ± one cell along x, y, z in the packed key (wraps like key_type)
  constexpr std::uint64_t kUnit[3] = {std::uint64_t{1} << 32, std::uint64_t{1} << 16, 1};
  for (unsigned i = 0; i < 3; ++i) {
    const int step = direction(i) > 0.0f ? 1 : (direction(i) < 0.0f ? -1 : 0);
    packed_step[i] = step >= 0 ? kUnit[i] * static_cast<std::uint64_t>(step) : -kUnit[i];
    if (step != 0) {
      double border = tree.keyToCoord(key_origin[i]);
      border += static_cast<float>(step * resolution * 0.5);
      t_max[i] = (border - origin(i)) / direction(i);
      t_delta[i] = resolution / std::fabs(direction(i));
    } else {
      t_max[i] = std::numeric_limits<double>::max();
      t_delta[i] = std::numeric_limits<double>::max();
    }
  }
  while (true) {
    const unsigned dim =
        t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0u : 2u) : (t_max[1] < t_max[2] ? 1u : 2u);
    current += packed_step[dim];
    t_max[dim] += t_delta[dim];
    if (current == last) return true;
    // Numerical inaccuracy can step past the end cell without meeting it: stop at the length.
    if (std::min(std::min(t_max[0], t_max[1]), t_max[2]) > length) return true;
    visit(current);
  }
}

}  // namespace sonarbench::mapping
