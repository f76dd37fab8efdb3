#pragma once

#include <Eigen/Core>
#include <numbers>
#include <optional>
#include <span>
#include <vector>

namespace sonarbench::mapping {

/// How far [m] a wall's first echoes lie from its line.
inline constexpr double kWallBand = 0.05;

/// How far [rad] a beam's fan (its 35° plane) may lean from vertical and still fit and refuse by
/// walls: 20°, so that its edge stays within 37.5° of horizontal (docs/mapper.md).
inline constexpr double kMaxWallFanTilt = 20.0 * std::numbers::pi / 180.0;

/// A vertical wall seen from above: the line through `centre` along the unit `direction` (world
/// x-y [m]), over [from, to] of its length from `centre` (its points' extent, widened).
struct WallLine {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();
  double from = 0.0;
  double to = 0.0;
};

/// A beam's first echo, top-down in the world frame [m]: where the sonar was and where it heard it.
struct FirstEcho {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
};

/// The walls a batch's first echoes outline, top-down (docs/mapper.md, "Nothing heard through a
/// wall"): straight runs of at least 15 of `echoes` (in head-angle order) within 5 cm of a line,
/// a metre long, which at least half the beams whose bearings cross them hear first (an object's
/// face is crossed mostly by beams that pass beside it); the largest first, each wall once, at
/// most six. Deterministic.
[[nodiscard]] std::vector<WallLine> FitWalls(std::span<const FirstEcho> echoes);

/// How far [m] from `origin` along the unit `direction` (both top-down) the nearest of `walls`
/// lies, if any lies ahead.
[[nodiscard]] std::optional<double> WallAhead(const Eigen::Vector2d& origin,
                                              const Eigen::Vector2d& direction,
                                              std::span<const WallLine> walls);

}  // namespace sonarbench::mapping
