// Walls from a batch's first echoes, top-down (walls.hpp).

#include "walls.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace sonarbench::mapping {
namespace {

// A first echo lies on its wall's line within the range jitter of the threshold crossing (about
// four bins); a wall is at least 15 echoes long (27° of a sweep at 1.8°), at most six are kept.
constexpr double kBand = kWallBand;
constexpr std::size_t kMinPoints = 15;
constexpr std::size_t kMaxWalls = 6;
// A wall is at least a metre long: a shorter straight run is an object standing in front of the
// walls (a crate's 0.6 m face), which hides what lies behind it only where it stands.
constexpr double kMinLength = 1.0;
// Once a wall is found, the echoes within a pulse and a half of it (its thick echoes, the floor
// where it meets the wall) no longer seed others; its ends reach half a metre past its echoes.
constexpr double kClaimed = 0.3;
constexpr double kExtend = 0.5;
// A line within 15° and 0.4 m of a wall found is that wall again.
const double kSameAngleCos = std::cos(15.0 * std::numbers::pi / 180.0);
constexpr double kSameOffset = 0.4;
// Candidate lines join echoes this many places apart in head-angle order, from at most 200 of
// them (every one of a sweep's); a dozen rounds find a sweep's walls and what stands before them.
constexpr std::array<std::size_t, 6> kStrides = {3, 5, 8, 12, 20, 30};
constexpr std::size_t kMaxStarts = 200;
constexpr std::size_t kMaxRounds = 12;

struct Candidate {
  std::size_t count = 0;
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
  Eigen::Vector2d normal = Eigen::Vector2d::UnitY();
};

// The line through two of the live points that holds most of them within kBand.
Candidate BestLine(std::span<const FirstEcho> points, const std::vector<std::size_t>& live) {
  Candidate best;
  const std::size_t n = live.size();
  const std::size_t step = (n + kMaxStarts - 1) / kMaxStarts;
  for (const std::size_t stride : kStrides) {
    for (std::size_t i = 0; i < n; i += step) {
      const Eigen::Vector2d& a = points[live[i]].point;
      const Eigen::Vector2d d = points[live[(i + stride) % n]].point - a;
      if (d.norm() < 0.2) continue;
      const Eigen::Vector2d normal = Eigen::Vector2d(-d.y(), d.x()).normalized();
      std::size_t count = 0;
      for (const std::size_t k : live) count += std::abs((points[k].point - a).dot(normal)) < kBand;
      if (count > best.count) best = {count, a, normal};
    }
  }
  return best;
}

// The least-squares line through `inliers`, over their extent.
WallLine Refit(std::span<const FirstEcho> points, const std::vector<std::size_t>& inliers) {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const std::size_t k : inliers) centre += points[k].point;
  centre /= static_cast<double>(inliers.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const std::size_t k : inliers)
    scatter += (points[k].point - centre) * (points[k].point - centre).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
  WallLine wall{centre, eigen.eigenvectors().col(1).normalized(), 0.0, 0.0};
  for (const std::size_t k : inliers) {
    const double t = (points[k].point - centre).dot(wall.direction);
    wall.from = std::min(wall.from, t);
    wall.to = std::max(wall.to, t);
  }
  return wall;
}

bool SameWall(const WallLine& a, const WallLine& b) {
  const Eigen::Vector2d normal(-b.direction.y(), b.direction.x());
  return std::abs(a.direction.dot(b.direction)) > kSameAngleCos &&
         std::abs((a.centre - b.centre).dot(normal)) < kSameOffset;
}

// Whether at least half the beams whose bearings cross `wall` hear it first rather than something
// beyond its thick echoes.
bool Bounds(std::span<const FirstEcho> echoes, const WallLine& wall) {
  std::size_t crossing = 0;
  std::size_t beyond = 0;
  for (const FirstEcho& e : echoes) {
    const Eigen::Vector2d ray = e.point - e.origin;
    const auto at = WallAhead(e.origin, ray.normalized(), std::span(&wall, 1));
    if (!at) continue;
    ++crossing;
    beyond += ray.norm() > *at + kClaimed;
  }
  return 2 * beyond <= crossing;
}

}  // namespace

std::vector<WallLine> FitWalls(std::span<const FirstEcho> points) {
  std::vector<WallLine> walls;
  std::vector<std::size_t> live(points.size());
  for (std::size_t k = 0; k < live.size(); ++k) live[k] = k;
  for (std::size_t round = 0;
       round < kMaxRounds && walls.size() < kMaxWalls && live.size() >= kMinPoints; ++round) {
    const Candidate best = BestLine(points, live);
    if (best.count < kMinPoints) break;
    std::vector<std::size_t> inliers;
    for (const std::size_t k : live) {
      if (std::abs((points[k].point - best.point).dot(best.normal)) < kBand) inliers.push_back(k);
    }
    WallLine wall = Refit(points, inliers);
    const bool long_enough = wall.to - wall.from >= kMinLength;
    wall.from -= kExtend;
    wall.to += kExtend;
    const Eigen::Vector2d normal(-wall.direction.y(), wall.direction.x());
    std::erase_if(live, [&](std::size_t k) {
      const Eigen::Vector2d p = points[k].point - wall.centre;
      const double t = p.dot(wall.direction);
      const bool inlier = std::abs((points[k].point - best.point).dot(best.normal)) < kBand;
      return inlier || (std::abs(p.dot(normal)) < kClaimed && t >= wall.from && t <= wall.to);
    });
    if (long_enough && Bounds(points, wall) &&
        std::none_of(walls.begin(), walls.end(),
                     [&](const WallLine& w) { return SameWall(wall, w); })) {
      walls.push_back(wall);
    }
  }
  return walls;
}

std::optional<double> WallAhead(const Eigen::Vector2d& origin, const Eigen::Vector2d& direction,
                                std::span<const WallLine> walls) {
  std::optional<double> nearest;
  for (const WallLine& wall : walls) {
    // origin + s·direction = centre + t·wall.direction, by Cramer's rule.
    const double det = direction.x() * wall.direction.y() - direction.y() * wall.direction.x();
    if (std::abs(det) < 1e-9) continue;  // parallel: never met
    const Eigen::Vector2d to_centre = wall.centre - origin;
    const double s =
        (to_centre.x() * wall.direction.y() - to_centre.y() * wall.direction.x()) / det;
    const double t = (to_centre.x() * direction.y() - to_centre.y() * direction.x()) / det;
    if (s > 0.0 && t >= wall.from && t <= wall.to && (!nearest || s < *nearest)) nearest = s;
  }
  return nearest;
}

}  // namespace sonarbench::mapping
