#include "sonarbench/sim/mesh.hpp"

#include <cmath>
#include <numbers>

#include "sonarbench/sim/random.hpp"

namespace sonarbench::sim {
namespace {

// Appends the quad a-b-c-d (in order around its edge) as two triangles.
void AddQuad(TriangleMesh& mesh, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
             const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
  for (const auto* v : {&a, &b, &c, &d}) mesh.vertices.push_back(v->cast<float>());
  mesh.triangles.push_back({base, base + 1, base + 2});
  mesh.triangles.push_back({base, base + 2, base + 3});
}

}  // namespace

TriangleMesh BuildMesh(const MeshSpec& spec, std::uint64_t seed) {
  TriangleMesh mesh;
  mesh.material = spec.material;
  const Eigen::Isometry3d& T = spec.T_world_mesh;
  const double hx = 0.5 * spec.size_m[0];
  const double hy = 0.5 * spec.size_m[1];
  const double sz = spec.size_m[2];
  auto p = [&](double x, double y, double z) -> Eigen::Vector3d {
    return T * Eigen::Vector3d(x, y, z);
  };
  switch (spec.type) {
    case MeshSpec::Type::kPlane:
      AddQuad(mesh, p(-hx, -hy, 0), p(hx, -hy, 0), p(hx, hy, 0), p(-hx, hy, 0));
      break;
    case MeshSpec::Type::kTank:  // floor and four walls, open at the top
      AddQuad(mesh, p(-hx, -hy, 0), p(hx, -hy, 0), p(hx, hy, 0), p(-hx, hy, 0));
      AddQuad(mesh, p(-hx, -hy, 0), p(hx, -hy, 0), p(hx, -hy, sz), p(-hx, -hy, sz));
      AddQuad(mesh, p(hx, -hy, 0), p(hx, hy, 0), p(hx, hy, sz), p(hx, -hy, sz));
      AddQuad(mesh, p(hx, hy, 0), p(-hx, hy, 0), p(-hx, hy, sz), p(hx, hy, sz));
      AddQuad(mesh, p(-hx, hy, 0), p(-hx, -hy, 0), p(-hx, -hy, sz), p(-hx, hy, sz));
      break;
    case MeshSpec::Type::kBox: {
      const double hz = 0.5 * sz;
      AddQuad(mesh, p(-hx, -hy, -hz), p(-hx, hy, -hz), p(hx, hy, -hz), p(hx, -hy, -hz));
      AddQuad(mesh, p(-hx, -hy, hz), p(hx, -hy, hz), p(hx, hy, hz), p(-hx, hy, hz));
      AddQuad(mesh, p(-hx, -hy, -hz), p(hx, -hy, -hz), p(hx, -hy, hz), p(-hx, -hy, hz));
      AddQuad(mesh, p(hx, -hy, -hz), p(hx, hy, -hz), p(hx, hy, hz), p(hx, -hy, hz));
      AddQuad(mesh, p(hx, hy, -hz), p(-hx, hy, -hz), p(-hx, hy, hz), p(hx, hy, hz));
      AddQuad(mesh, p(-hx, hy, -hz), p(-hx, -hy, -hz), p(-hx, -hy, hz), p(-hx, hy, hz));
      break;
    }
    case MeshSpec::Type::kHeightField: {
      const int nx = std::max(1, static_cast<int>(std::lround(spec.size_m[0] / spec.cell_m)));
      const int ny = std::max(1, static_cast<int>(std::lround(spec.size_m[1] / spec.cell_m)));
      const double k = 2.0 * std::numbers::pi / spec.wavelength_m;
      for (int j = 0; j <= ny; ++j) {
        for (int i = 0; i <= nx; ++i) {
          const double x = -hx + spec.size_m[0] * i / nx;
          const double y = -hy + spec.size_m[1] * j / ny;
          Rng rng(DeriveSeed(seed, static_cast<std::uint64_t>(j) * (nx + 1) + i));
          const double z = spec.amplitude_m * std::sin(k * x) * std::cos(k * y) +
                           spec.roughness_m * rng.Normal();
          mesh.vertices.push_back(p(x, y, z).cast<float>());
        }
      }
      const auto row = static_cast<std::uint32_t>(nx + 1);
      for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(ny); ++j) {
        for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(nx); ++i) {
          const std::uint32_t v = j * row + i;
          mesh.triangles.push_back({v, v + 1, v + row + 1});
          mesh.triangles.push_back({v, v + row + 1, v + row});
        }
      }
      break;
    }
  }
  return mesh;
}

std::vector<TriangleMesh> BuildSceneMeshes(const Scene& scene) {
  std::vector<TriangleMesh> meshes;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    meshes.push_back(BuildMesh(scene.meshes[i], DeriveSeed(scene.seed, 0x6d657368ULL + i)));
  }
  return meshes;
}

}  // namespace sonarbench::sim
