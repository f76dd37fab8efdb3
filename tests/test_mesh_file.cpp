#include <gtest/gtest.h>

#include <fstream>

#include "sonarbench/mapping/error.hpp"
#include "sonarbench/sim/mesh.hpp"
#include "sonarbench/sim/mesh_file.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

struct Box {
  Eigen::Vector3d lo, hi;
};

Box Bounds(const std::vector<Eigen::Vector3d>& vertices) {
  Box b{Eigen::Vector3d::Constant(1e9), Eigen::Vector3d::Constant(-1e9)};
  for (const auto& v : vertices) {
    b.lo = b.lo.cwiseMin(v);
    b.hi = b.hi.cwiseMax(v);
  }
  return b;
}

TriangleMesh AsMesh(const MeshFileData& data, const std::array<double, 3>& scale = {1, 1, 1},
                    const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity()) {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kFile;
  spec.file_vertices = data.vertices;
  spec.file_triangles = data.triangles;
  spec.scale = scale;
  spec.T_world_mesh = pose;
  return BuildMesh(spec, 0);
}

// The generator (scenes/meshes/make_meshes.py) writes exact dimensions; floats hold them to 1e-6.
constexpr double kTol = 1e-5;

TEST(MeshFile, EachFormatLoadsClosedWithItsDimensions) {
  const auto pipe = LoadMeshFile(test::SourcePath("scenes/meshes/pipe.stl"));
  const Box p = Bounds(pipe.vertices);
  EXPECT_NEAR(p.lo.y(), -3.0, kTol);
  EXPECT_NEAR(p.hi.y(), 3.0, kTol);
  EXPECT_NEAR(p.hi.x(), 0.15, kTol);  // a vertex at angle 0 sits at the full radius
  EXPECT_EQ(pipe.triangles.size(), 4u * 32u);

  // COLLADA in centimetres, z up: metres after loading, and not turned to y up.
  const auto crate = LoadMeshFile(test::SourcePath("scenes/meshes/crate.dae"));
  const Box c = Bounds(crate.vertices);
  EXPECT_NEAR(c.lo.x(), -0.3, kTol);
  EXPECT_NEAR(c.hi.y(), 0.2, kTol);
  EXPECT_NEAR(c.lo.z(), 0.0, kTol);
  EXPECT_NEAR(c.hi.z(), 0.4, kTol);

  const auto quay = LoadMeshFile(test::SourcePath("scenes/meshes/quay_wall.ply"));
  const Box q = Bounds(quay.vertices);
  EXPECT_NEAR(q.hi.z(), 4.0, kTol);
  EXPECT_NEAR(q.hi.y() - q.lo.y(), 20.0, kTol);
  EXPECT_NEAR(q.hi.x(), 1.5, kTol);

  const auto rock = LoadMeshFile(test::SourcePath("scenes/meshes/rock.obj"));
  EXPECT_EQ(rock.triangles.size(), 20u * 16u);  // an icosphere subdivided twice

  for (const auto* data : {&pipe, &crate, &quay, &rock}) {
    TriangleMesh mesh = AsMesh(*data);
    const MeshCheck check = CheckMesh(mesh, "mesh");
    EXPECT_EQ(check.boundary_edges, 0u);
    EXPECT_EQ(check.non_manifold_edges, 0u);
    EXPECT_EQ(check.zero_area_triangles, 0u);
  }
}

TEST(MeshFile, ScaleThenPoseAreApplied) {
  const auto crate = LoadMeshFile(test::SourcePath("scenes/meshes/crate.dae"));
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(1, 2, 3);
  pose.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const TriangleMesh mesh = AsMesh(crate, {2, 1, 1}, pose);
  std::vector<Eigen::Vector3d> v;
  for (const auto& f : mesh.vertices) v.push_back(f.cast<double>());
  const Box b = Bounds(v);
  // x scaled to ±0.6 m, then turned onto y; y's ±0.2 m turned onto x.
  EXPECT_NEAR(b.lo.y(), 2 - 0.6, kTol);
  EXPECT_NEAR(b.hi.y(), 2 + 0.6, kTol);
  EXPECT_NEAR(b.hi.x(), 1 + 0.2, kTol);
  EXPECT_NEAR(b.hi.z(), 3 + 0.4, kTol);
}

TEST(MeshPreflight, OpenTankHasItsFourTopEdgesOpen) {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kTank;
  spec.size_m = {4, 4, 1.5};
  TriangleMesh tank = BuildMesh(spec, 0);
  const MeshCheck check = CheckMesh(tank, "tank");
  // Each wall's quad is split by a diagonal, so its top rim is one edge: four rims in all.
  EXPECT_EQ(check.boundary_edges, 4u);
  EXPECT_EQ(check.non_manifold_edges, 0u);
}

TEST(MeshPreflight, RefusesNonFiniteVerticesAndDropsZeroAreaTriangles) {
  test::TempDir dir;
  const auto nan_obj = dir.path() / "nan.obj";
  std::ofstream(nan_obj) << "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n";
  const std::string nan_error = test::InputErrorOf([&] {
    TriangleMesh mesh = AsMesh(LoadMeshFile(nan_obj.string()));
    (void)CheckMesh(mesh, nan_obj.string());
  });
  EXPECT_NE(nan_error.find(nan_obj.string() + ": vertex 2 is not finite"), std::string::npos)
      << nan_error;

  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 1, 3}};  // the second is a line: zero area
  const MeshCheck check = CheckMesh(mesh, "m");
  EXPECT_EQ(check.zero_area_triangles, 1u);
  EXPECT_EQ(mesh.triangles.size(), 1u);
  EXPECT_EQ(check.boundary_edges, 3u);

  TriangleMesh only_degenerate;
  only_degenerate.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  only_degenerate.triangles = {{0, 1, 2}};
  EXPECT_NE(test::InputErrorOf([&] {
              (void)CheckMesh(only_degenerate, "flat");
            }).find("flat: no triangle with a non-zero area"),
            std::string::npos);
}

TEST(MeshFile, MissingOrUnreadableFilesNameTheFile) {
  test::TempDir dir;
  EXPECT_NE(test::InputErrorOf([] {
              (void)LoadMeshFile("/nonexistent/rock.obj");
            }).find("/nonexistent/rock.obj: no such mesh file"),
            std::string::npos);
  const auto garbage = dir.path() / "garbage.stl";
  std::ofstream(garbage) << "this is not a mesh\n";
  const std::string error = test::InputErrorOf([&] { (void)LoadMeshFile(garbage.string()); });
  EXPECT_NE(error.find(garbage.string() + ": "), std::string::npos) << error;
}

}  // namespace
}  // namespace sonarbench::sim
