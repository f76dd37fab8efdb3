#include <gtest/gtest.h>

#include <numbers>

#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::mapping {
namespace {

constexpr double kQuarter = std::numbers::pi / 2;

// Roll about x, pitch about y, yaw about z, each right-handed, applied as R = Rz(yaw) Ry(pitch)
// Rx(roll): a quarter turn of each moves one axis onto the next.
TEST(PoseFromXyzRpy, EachAngleTurnsItsAxisRightHanded) {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  const auto turn = [](double roll, double pitch, double yaw) -> Eigen::Matrix3d {
    const Eigen::Isometry3d pose =
        PoseFromXyzRpy(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(roll, pitch, yaw));
    return pose.linear();
  };
  EXPECT_TRUE((turn(kQuarter, 0, 0) * y).isApprox(z, 1e-12));
  EXPECT_TRUE((turn(0, kQuarter, 0) * z).isApprox(x, 1e-12));
  EXPECT_TRUE((turn(0, 0, kQuarter) * x).isApprox(y, 1e-12));
  // Roll first, then yaw: y goes to z (roll) and stays; x stays (roll) and goes to y (yaw).
  EXPECT_TRUE((turn(kQuarter, 0, kQuarter) * y).isApprox(z, 1e-12));
  EXPECT_TRUE((turn(kQuarter, 0, kQuarter) * x).isApprox(y, 1e-12));
  const Eigen::Isometry3d still = PoseFromXyzRpy(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d::Zero());
  EXPECT_EQ(still.translation(), Eigen::Vector3d(1, 2, 3));
}

}  // namespace
}  // namespace sonarbench::mapping
