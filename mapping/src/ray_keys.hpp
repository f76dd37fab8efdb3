#pragma once

#include <octomap/OcTree.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "key_set.hpp"

namespace sonarbench::mapping {

/// The start of OctoMap's 3-D DDA (Amanatides & Woo) along the segment origin → end, with
/// OctoMap's float and double arithmetic: OcTree::computeRayKeys's set-up, step for step.
struct RayWalk {
  octomap::OcTreeKey origin_key;
  octomap::OcTreeKey end_key;
  /// Ray parameter [m] at the next cell face along x, y, z, and between faces.
  double t_max[3] = {0.0, 0.0, 0.0};
  double t_delta[3] = {0.0, 0.0, 0.0};
  /// -1, 0 or +1 cell along x, y, z.
  int step[3] = {0, 0, 0};
  /// Length of the segment [m], as OctoMap rounds it (float).
  double length = 0.0;
};

/// Sets up `walk` for the segment origin → end. Returns false if either point lies outside the
/// tree's key range. If both lie in one cell (origin_key == end_key) there is nothing to visit.
/// StartRayWalkFromKey is the same with the origin's key already in `walk.origin_key` (rays
/// from one origin compute it once).
inline bool StartRayWalkFromKey(const octomap::OcTree& tree, const octomap::point3d& origin,
                                const octomap::point3d& end, RayWalk& walk) {
  if (!tree.coordToKeyChecked(end, walk.end_key)) return false;
  if (walk.origin_key == walk.end_key) return true;
  octomap::point3d direction = end - origin;
  const float length = static_cast<float>(direction.norm());
  direction /= length;
  walk.length = length;
  const double resolution = tree.getResolution();
  for (unsigned i = 0; i < 3; ++i) {
    walk.step[i] = direction(i) > 0.0f ? 1 : (direction(i) < 0.0f ? -1 : 0);
    if (walk.step[i] != 0) {
      double border = tree.keyToCoord(walk.origin_key[i]);
      border += static_cast<float>(walk.step[i] * resolution * 0.5);
      walk.t_max[i] = (border - origin(i)) / direction(i);
      walk.t_delta[i] = resolution / std::fabs(direction(i));
    } else {
      walk.t_max[i] = std::numeric_limits<double>::max();
      walk.t_delta[i] = std::numeric_limits<double>::max();
    }
  }
  return true;
}
inline bool StartRayWalk(const octomap::OcTree& tree, const octomap::point3d& origin,
                         const octomap::point3d& end, RayWalk& walk) {
  return tree.coordToKeyChecked(origin, walk.origin_key) &&
         StartRayWalkFromKey(tree, origin, end, walk);
}

/// The axis (0, 1, 2) of the DDA's next step: the smallest t_max, ties as OctoMap breaks them.
[[nodiscard]] inline unsigned NextStepAxis(double tx, double ty, double tz) {
  return tx < ty ? (tx < tz ? 0u : 2u) : (ty < tz ? 1u : 2u);
}

/// One cell along x, y, z in a packed key (see PackKey).
inline constexpr std::uint64_t kPackedKeyUnit[3] = {std::uint64_t{1} << 32, std::uint64_t{1} << 16,
                                                    1};

/// Walks the cells of `walk` after StartRayWalk returned true for a segment whose ends lie in
/// different cells, in a cell numbering where one step along axis i adds `unit[i]` (modulo
/// 2^64): calls `visit(number)` for the origin's cell, `start`, and every cell after it before
/// the end point's cell, `end`, in order.
template <typename Visit>
void WalkRay(const RayWalk& walk, std::uint64_t start, std::uint64_t end,
             const std::uint64_t (&unit)[3], Visit&& visit) {
  std::uint64_t current = start;
  visit(current);
  std::uint64_t step[3];
  for (unsigned i = 0; i < 3; ++i) {
    step[i] = unit[i] * static_cast<std::uint64_t>(static_cast<std::int64_t>(walk.step[i]));
  }
  double t_max[3] = {walk.t_max[0], walk.t_max[1], walk.t_max[2]};
  while (true) {
    const unsigned dim = NextStepAxis(t_max[0], t_max[1], t_max[2]);
    current += step[dim];
    t_max[dim] += walk.t_delta[dim];
    if (current == end) return;
    // Numerical inaccuracy can step past the end cell without meeting it: stop at the length.
    if (std::min(std::min(t_max[0], t_max[1]), t_max[2]) > walk.length) return;
    visit(current);
  }
}

/// Calls `visit(packed_key)` (see PackKey) for every cell the segment origin → end crosses before
/// the end point's cell, in order: the same keys, in the same order, as OctoMap's
/// OcTree::computeRayKeys, without filling a KeyRay first and with the packed key stepped in
/// place. Returns false, visiting nothing, if either point lies outside the tree's key range.
template <typename Visit>
bool ForEachRayKey(const octomap::OcTree& tree, const octomap::point3d& origin,
                   const octomap::point3d& end, Visit&& visit) {
  RayWalk walk;
  if (!StartRayWalk(tree, origin, end, walk)) return false;
  if (walk.origin_key == walk.end_key) return true;
  WalkRay(walk, PackKey(walk.origin_key), PackKey(walk.end_key), kPackedKeyUnit, visit);
  return true;
}

}  // namespace sonarbench::mapping
