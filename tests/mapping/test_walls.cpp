#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "rectangle_tank.hpp"
#include "walls.hpp"

namespace sonarbench::mapping {
namespace {

FirstEcho At(const Eigen::Vector2d& point) { return {Eigen::Vector2d::Zero(), point}; }

std::vector<FirstEcho> RectanglePoints() {
  std::vector<FirstEcho> points;
  for (int b = 0; b < 200; ++b) {
    const double theta = b * 1.8 * std::numbers::pi / 180.0;
    points.push_back(
        At(test::RectangleWallRange(theta) * Eigen::Vector2d(std::cos(theta), std::sin(theta))));
  }
  return points;
}

// Walls are placed within a range bin of the Micron (12.5 mm): a corner's echoes on the next wall
// that fall within a wall's band tilt its fit by a few millimetres.
constexpr double kBin = 0.0125;

// A rectangle's first echoes give its four walls, each once; every bearing then meets the wall it
// was heard on, at its range.
TEST(FitWalls, ARectanglesEchoesGiveItsFourWalls) {
  const std::vector<FirstEcho> points = RectanglePoints();
  const std::vector<WallLine> walls = FitWalls(points);
  ASSERT_EQ(walls.size(), 4u);
  int along_x = 0;
  for (const WallLine& wall : walls) {
    const bool x_wall = std::abs(wall.direction.y()) > std::cos(kBin);
    along_x += x_wall ? 0 : 1;
    const double offset = x_wall ? wall.centre.x() : wall.centre.y();
    EXPECT_TRUE(x_wall ? (std::abs(offset + 1.0) < kBin || std::abs(offset - 3.0) < kBin)
                       : std::abs(std::abs(offset) - 1.5) < kBin)
        << wall.centre.transpose() << " along " << wall.direction.transpose();
  }
  EXPECT_EQ(along_x, 2);
  // A batch of ten sweeps (2000 echoes) is fitted from 200 starts: the same four walls.
  std::vector<FirstEcho> ten;
  for (int sweep = 0; sweep < 10; ++sweep) ten.insert(ten.end(), points.begin(), points.end());
  EXPECT_EQ(FitWalls(ten).size(), 4u);
  for (int b = 0; b < 200; ++b) {
    const double theta = b * 1.8 * std::numbers::pi / 180.0;
    const auto range = WallAhead(Eigen::Vector2d::Zero(),
                                 Eigen::Vector2d(std::cos(theta), std::sin(theta)), walls);
    ASSERT_TRUE(range.has_value()) << b;
    EXPECT_NEAR(*range, test::RectangleWallRange(theta), kBin) << b;
  }
}

// A gap in a wall's echoes (a sector heard only through it) is bridged up to half a metre past
// the echoes on either side: the wall is still met there. Echoes scattered off any line, or too few
// in a line, make no wall.
TEST(FitWalls, AWallIsMetAcrossAGapInItsEchoesAndNoiseMakesNone) {
  std::vector<FirstEcho> points = RectanglePoints();
  std::vector<FirstEcho> gapped;
  for (std::size_t b = 0; b < points.size(); ++b) {
    if (b < 6 || b > 14) gapped.push_back(points[b]);  // none at 10.8° to 25.2°
  }
  const std::vector<WallLine> walls = FitWalls(gapped);
  const double theta = 18.0 * std::numbers::pi / 180.0;
  const auto range =
      WallAhead(Eigen::Vector2d::Zero(), Eigen::Vector2d(std::cos(theta), std::sin(theta)), walls);
  ASSERT_TRUE(range.has_value());
  EXPECT_NEAR(*range, test::RectangleWallRange(theta), kBin);
  // Half a metre past its last echo (y = 3 tan 9°) the x = 3 wall ends: at 24° only y = 1.5 is met.
  const double past = 24.0 * std::numbers::pi / 180.0;
  const auto beyond =
      WallAhead(Eigen::Vector2d::Zero(), Eigen::Vector2d(std::cos(past), std::sin(past)), walls);
  ASSERT_TRUE(beyond.has_value());
  EXPECT_NEAR(*beyond, 1.5 / std::sin(past), kBin);

  std::vector<FirstEcho> scattered;
  for (int k = 0; k < 200; ++k) {  // on a spiral: no three within 5 cm of a line through two
    const double a = 0.7 * k;
    scattered.push_back(At((1.0 + 0.02 * k) * Eigen::Vector2d(std::cos(a), std::sin(a))));
  }
  EXPECT_TRUE(FitWalls(scattered).empty());
  EXPECT_TRUE(FitWalls(std::span(points).first(14)).empty());  // 14 echoes on one wall
}

// An object is not a wall: a crate's face heard over 27° at 0.7 m (0.34 m long) is too short, and a
// railing heard by every third beam of the tank's north half, the others passing it to the wall
// 1.2 m behind, does not bound what the beams hear. Neither is met; the tank's walls still are.
TEST(FitWalls, AnObjectInFrontOfTheWallsIsNoWall) {
  std::vector<FirstEcho> crate = RectanglePoints();
  const double face = 50.0 * std::numbers::pi / 180.0;
  for (int b = 20; b <= 35; ++b) {  // 36° to 63°: a face 0.7 m out, square to 50°
    const double theta = b * 1.8 * std::numbers::pi / 180.0;
    crate[static_cast<std::size_t>(b)] =
        At(0.7 / std::cos(theta - face) * Eigen::Vector2d(std::cos(theta), std::sin(theta)));
  }
  for (const WallLine& wall : FitWalls(crate)) {
    const Eigen::Vector2d normal(-wall.direction.y(), wall.direction.x());
    EXPECT_GT(std::abs(std::abs(wall.centre.dot(normal)) - 0.7), 0.2) << wall.centre.transpose();
  }

  std::vector<FirstEcho> railing = RectanglePoints();
  for (int b = 3; b < 98; b += 3) {  // 5.4° to 174.6°, the railing along y = 0.3
    const double theta = b * 1.8 * std::numbers::pi / 180.0;
    railing[static_cast<std::size_t>(b)] =
        At(0.3 / std::sin(theta) * Eigen::Vector2d(std::cos(theta), std::sin(theta)));
  }
  const std::vector<WallLine> walls = FitWalls(railing);
  const double north = 90.0 * std::numbers::pi / 180.0;
  const auto range = WallAhead(Eigen::Vector2d::Zero(), Eigen::Vector2d(0.0, 1.0), walls);
  ASSERT_TRUE(range.has_value());
  EXPECT_NEAR(*range, test::RectangleWallRange(north), kBin);
}

}  // namespace
}  // namespace sonarbench::mapping
