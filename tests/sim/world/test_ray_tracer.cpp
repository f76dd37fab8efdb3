#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "sim_fixtures.hpp"
#include "sonarbench/mapping/detection.hpp"
#include "sonarbench/sim/sonar/beam_synthesizer.hpp"
#include "sonarbench/sim/sonar/pulse_spreader.hpp"
#include "sonarbench/sim/sonar/range_spread.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/random.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

using mapping::kDegToRad;

// The straight return's occlusion ray: a wall 1 m ahead blocks a segment that reaches it, not
// one that stops 1 cm short, from either side.
TEST(RayTracer, OccludedOnlyBySurfacesWithinTheSegment) {
  const std::vector<TriangleMesh> meshes = Wall(1.0, 0.0);
  const RayTracer tracer(meshes);
  const Eigen::Vector3f x = Eigen::Vector3f::UnitX();
  EXPECT_FALSE(tracer.Occluded(Eigen::Vector3f::Zero(), x, 0.99f));
  EXPECT_TRUE(tracer.Occluded(Eigen::Vector3f::Zero(), x, 1.01f));
  EXPECT_FALSE(tracer.Occluded(Eigen::Vector3f(2.0f, 0, 0), -x, 0.99f));
  EXPECT_TRUE(tracer.Occluded(Eigen::Vector3f(2.0f, 0, 0), -x, 1.01f));
}

// The synthesis traces each beam's rays as one coherent stream: it must find what one query per
// ray finds. Rays in every direction from inside a tank (walls, floor, open top, and a box
// whose edges some rays graze): the same rays hit, the same meshes, the same distances to
// float rounding (1e-5 relative: a few ulps of the float tfar), the same normals.
TEST(RayTracer, BundleFindsWhatSingleRaysFind) {
  MeshSpec tank;
  tank.type = MeshSpec::Type::kTank;
  tank.size_m = {4.4, 4.4, 2.0};
  MeshSpec box;
  box.size_m = {0.5, 0.3, 0.4};
  box.T_world_mesh = mapping::PoseFromXyzRpy({1.0, 0.5, 0.3}, {0, 0, 0.4});
  const std::vector<TriangleMesh> meshes = {BuildMesh(tank, 1), BuildMesh(box, 1)};
  const RayTracer tracer(meshes);
  Rng rng(77);
  const Eigen::Vector3f origin(0.2f, -0.1f, 0.8f);
  std::vector<Eigen::Vector3f> directions(1000);
  for (auto& d : directions) {
    d = Eigen::Vector3f(static_cast<float>(rng.Normal()), static_cast<float>(rng.Normal()),
                        static_cast<float>(rng.Normal()))
            .normalized();
  }
  std::vector<std::optional<Hit>> bundle(directions.size());
  tracer.IntersectBundle(origin, directions, 3.0f, bundle);
  int hits = 0;
  for (std::size_t i = 0; i < directions.size(); ++i) {
    const auto single = tracer.Intersect(origin, directions[i], 3.0f);
    ASSERT_EQ(single.has_value(), bundle[i].has_value()) << "ray " << i;
    if (!single) continue;
    ++hits;
    EXPECT_EQ(single->mesh, bundle[i]->mesh) << "ray " << i;
    EXPECT_NEAR(single->distance, bundle[i]->distance, 1e-5f * single->distance) << "ray " << i;
    EXPECT_GT(std::abs(single->normal.dot(bundle[i]->normal)), 1.0f - 1e-5f) << "ray " << i;
  }
  EXPECT_GT(hits, 500);   // the walls and floor within 3 m of most directions
  EXPECT_LT(hits, 1000);  // the open top lets some out
  std::vector<std::optional<Hit>> short_hits(3);
  EXPECT_THROW(tracer.IntersectBundle(origin, directions, 3.0f, short_hits), std::invalid_argument);
}

// Rays from anywhere in the tank, traced as one incoherent stream, and their occlusion tests as
// another: the same answers as one query per ray (distances to float rounding, as above).
TEST(RayTracer, StreamsFindWhatSingleRaysFind) {
  MeshSpec tank;
  tank.type = MeshSpec::Type::kTank;
  tank.size_m = {4.4, 4.4, 2.0};
  const std::vector<TriangleMesh> meshes = {BuildMesh(tank, 1)};
  const RayTracer tracer(meshes);
  Rng rng(78);
  std::vector<Ray> rays(1000);
  for (Ray& ray : rays) {
    ray.origin = Eigen::Vector3f(static_cast<float>(4.0 * rng.Uniform() - 2.0),
                                 static_cast<float>(4.0 * rng.Uniform() - 2.0),
                                 static_cast<float>(1.8 * rng.Uniform() + 0.1));
    ray.direction =
        Eigen::Vector3f(static_cast<float>(rng.Normal()), static_cast<float>(rng.Normal()),
                        static_cast<float>(rng.Normal()))
            .normalized();
    ray.max_distance = static_cast<float>(3.0 * rng.Uniform());
  }
  std::vector<std::optional<Hit>> hits(rays.size());
  tracer.IntersectStream(rays, hits);
  std::vector<bool> occluded;
  tracer.OccludedStream(rays, occluded);
  ASSERT_EQ(occluded.size(), rays.size());
  int found = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Ray& ray = rays[i];
    const auto single = tracer.Intersect(ray.origin, ray.direction, ray.max_distance);
    ASSERT_EQ(single.has_value(), hits[i].has_value()) << "ray " << i;
    EXPECT_EQ(tracer.Occluded(ray.origin, ray.direction, ray.max_distance), occluded[i])
        << "ray " << i;
    if (!single) continue;
    ++found;
    EXPECT_EQ(single->mesh, hits[i]->mesh) << "ray " << i;
    EXPECT_NEAR(single->distance, hits[i]->distance, 1e-5f * single->distance) << "ray " << i;
    EXPECT_GT(std::abs(single->normal.dot(hits[i]->normal)), 1.0f - 1e-5f) << "ray " << i;
  }
  EXPECT_GT(found, 200);  // segments up to 3 m long inside a 4.4 m tank: many reach a wall,
  EXPECT_LT(found, 900);  // many do not
  EXPECT_THROW(tracer.IntersectStream(rays, std::span(hits).first(3)), std::invalid_argument);
}

// While recording, a tracer logs each query it answers, in order, with its rays; before and
// after, nothing.
TEST(RayTracer, RecordsEveryQueryWithItsRaysWhileRecording) {
  const std::vector<TriangleMesh> meshes = Wall(2.0, 0.0);
  const RayTracer tracer(meshes);
  const Eigen::Vector3f origin(0.0f, 0.5f, 0.0f);
  const std::vector<Eigen::Vector3f> directions = {Eigen::Vector3f::UnitX(),
                                                   Eigen::Vector3f(0.6f, 0.8f, 0.0f)};
  const std::vector<Ray> rays = {{origin, Eigen::Vector3f::UnitX(), 3.0f},
                                 {origin, -Eigen::Vector3f::UnitX(), 1.0f},
                                 {origin, Eigen::Vector3f::UnitY(), 2.0f}};
  std::vector<std::optional<Hit>> hits(rays.size());
  std::vector<bool> occluded;
  RayQueryLog log;
  (void)tracer.Intersect(origin, Eigen::Vector3f::UnitX(), 3.0f);
  tracer.Record(&log);
  tracer.IntersectBundle(origin, directions, 4.0f, std::span(hits).first(2));
  tracer.IntersectStream(rays, hits);
  tracer.OccludedStream(std::span(rays).first(2), occluded);
  (void)tracer.Intersect(origin, Eigen::Vector3f::UnitZ(), 5.0f);
  (void)tracer.Occluded(origin, Eigen::Vector3f::UnitX(), 6.0f);
  tracer.Record(nullptr);
  tracer.IntersectStream(rays, hits);

  using Query = RayQueryLog::Query;
  ASSERT_EQ(log.entries.size(), 5u);
  const std::vector<Query> queries = {Query::kBundle, Query::kStream, Query::kOccludedStream,
                                      Query::kSingle, Query::kSingleOccluded};
  const std::vector<std::size_t> sizes = {2, 3, 2, 1, 1};
  for (std::size_t e = 0; e < log.entries.size(); ++e) {
    EXPECT_EQ(log.entries[e].query, queries[e]) << "entry " << e;
    EXPECT_EQ(log.entries[e].rays.size(), sizes[e]) << "entry " << e;
  }
  EXPECT_EQ(log.RayCount(), 9u);
  const auto same = [](const Ray& a, const Ray& b) {
    return a.origin == b.origin && a.direction == b.direction && a.max_distance == b.max_distance;
  };
  EXPECT_TRUE(same(log.entries[0].rays[1], {origin, directions[1], 4.0f}));
  for (std::size_t i = 0; i < rays.size(); ++i) EXPECT_TRUE(same(log.entries[1].rays[i], rays[i]));
  EXPECT_TRUE(same(log.entries[2].rays[1], rays[1]));
  EXPECT_TRUE(same(log.entries[3].rays[0], {origin, Eigen::Vector3f::UnitZ(), 5.0f}));
  EXPECT_TRUE(same(log.entries[4].rays[0], {origin, Eigen::Vector3f::UnitX(), 6.0f}));
}

}  // namespace
}  // namespace sonarbench::sim
