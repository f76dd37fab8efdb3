#include <gtest/gtest.h>

#include "sonarbench/base/error.hpp"
#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/world/mesh.hpp"

namespace sonarbench::sim {
namespace {

using Eigen::Vector3d;

TEST(TriangleBoxOverlap, AnalyticCases) {
  const Vector3d centre(0, 0, 0);
  const Vector3d half(0.5, 0.5, 0.5);
  // Inside, crossing, far away.
  EXPECT_TRUE(TriangleBoxOverlap(centre, half, {-0.1, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}));
  EXPECT_TRUE(TriangleBoxOverlap(centre, half, {-5, -5, 0}, {5, -5, 0}, {0, 5, 0}));
  EXPECT_FALSE(TriangleBoxOverlap(centre, half, {2, 2, 2}, {3, 2, 2}, {2, 3, 2}));
  // Touching a face counts.
  EXPECT_TRUE(TriangleBoxOverlap(centre, half, {0.5, -1, -1}, {0.5, 1, -1}, {0.5, 0, 1}));
  EXPECT_FALSE(TriangleBoxOverlap(centre, half, {0.5001, -1, -1}, {0.5001, 1, -1}, {0.5001, 0, 1}));
  // Bounding boxes overlap but the triangle passes beside the corner: only an edge cross-product
  // axis separates them. The plane x + y = 1.2 misses the box (its corner has x + y = 1).
  EXPECT_FALSE(TriangleBoxOverlap(centre, half, {1.2, 0, -1}, {0, 1.2, -1}, {0.6, 0.6, 1}));
  EXPECT_TRUE(TriangleBoxOverlap(centre, half, {0.9, 0, -1}, {0, 0.9, -1}, {0.45, 0.45, 1}));
}

TEST(PointTriangleDistance, AnalyticCases) {
  const Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_DOUBLE_EQ(PointTriangleDistance({0.2, 0.2, 0.5}, a, b, c), 0.5);  // above the face
  EXPECT_DOUBLE_EQ(PointTriangleDistance({-3, -4, 0}, a, b, c), 5.0);      // nearest a vertex
  EXPECT_DOUBLE_EQ(PointTriangleDistance({0.5, -2, 0}, a, b, c), 2.0);     // nearest an edge
  EXPECT_NEAR(PointTriangleDistance({1, 1, 0}, a, b, c), std::sqrt(0.5), 1e-12);  // hypotenuse
}

}  // namespace
}  // namespace sonarbench::sim
