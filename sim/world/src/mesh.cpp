#include "sonarbench/sim/world/mesh.hpp"

#include <cmath>
#include <map>
#include <numbers>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/text.hpp"
#include "sonarbench/sim/world/random.hpp"

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

// A height field's vertices and triangles: sand waves of `amplitude_m` and `wavelength_m` plus
// seeded roughness, on a grid of `cell_m` over the spec's size, placed by the spec's pose.
void AddHeightField(TriangleMesh& mesh, const MeshSpec& spec, std::uint64_t seed) {
  const Eigen::Isometry3d& T = spec.T_world_mesh;
  const double hx = 0.5 * spec.size_m[0];
  const double hy = 0.5 * spec.size_m[1];
  // CheckBudgets refuses far fewer cells; this keeps the int conversions defined.
  if (!(spec.size_m[0] / spec.height_field.cell_m < 1e7 &&
        spec.size_m[1] / spec.height_field.cell_m < 1e7)) {
    throw InputError("mesh '" + spec.name + "': 'cell_m' " + io::Number(spec.height_field.cell_m) +
                     " makes over 1e7 cells a side (expected a coarser grid)");
  }
  const int nx =
      std::max(1, static_cast<int>(std::lround(spec.size_m[0] / spec.height_field.cell_m)));
  const int ny =
      std::max(1, static_cast<int>(std::lround(spec.size_m[1] / spec.height_field.cell_m)));
  const double k = 2.0 * std::numbers::pi / spec.height_field.wavelength_m;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      const double x = -hx + spec.size_m[0] * i / nx;
      const double y = -hy + spec.size_m[1] * j / ny;
      Rng rng(DeriveSeed(seed, static_cast<std::uint64_t>(j) * (nx + 1) + i));
      const double z = spec.height_field.amplitude_m * std::sin(k * x) * std::cos(k * y) +
                       spec.height_field.roughness_m * rng.Normal();
      mesh.vertices.push_back((T * Eigen::Vector3d(x, y, z)).cast<float>());
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
      AddHeightField(mesh, spec, seed);
      break;
    }
    case MeshSpec::Type::kFile:
      for (const Eigen::Vector3d& v : spec.file.vertices) {
        mesh.vertices.push_back(
            p(spec.file.scale[0] * v.x(), spec.file.scale[1] * v.y(), spec.file.scale[2] * v.z())
                .cast<float>());
      }
      mesh.triangles = spec.file.triangles;
      break;
  }
  return mesh;
}

MeshCheck CheckMesh(TriangleMesh& mesh, const std::string& where) {
  MeshCheck check;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f& v = mesh.vertices[i];
    if (!v.allFinite()) {
      throw InputError(where + ": vertex " + std::to_string(i) + " is not finite (" +
                       io::Number(v.x()) + ", " + io::Number(v.y()) + ", " + io::Number(v.z()) +
                       "); the truth cannot be computed from it");
    }
  }
  // Zero-area triangles have no surface: no echo, no truth cell. They are dropped and counted.
  std::vector<std::array<std::uint32_t, 3>> kept;
  kept.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[t[2]].cast<double>();
    if (0.5 * (b - a).cross(c - a).norm() < kMinTriangleAreaM2) {
      ++check.zero_area_triangles;
    } else {
      kept.push_back(t);
    }
  }
  mesh.triangles = std::move(kept);
  if (mesh.triangles.empty()) throw InputError(where + ": no triangle with a non-zero area");
  // Edges between vertices welded by position: one triangle on an edge is a hole's border, more
  // than two a non-manifold seam.
  std::map<std::array<float, 3>, std::uint32_t> weld;
  std::vector<std::uint32_t> id(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f& v = mesh.vertices[i];
    id[i] = weld.emplace(std::array<float, 3>{v.x(), v.y(), v.z()},
                         static_cast<std::uint32_t>(weld.size()))
                .first->second;
  }
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (const auto& t : mesh.triangles) {
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = id[t[e]];
      const std::uint32_t b = id[t[(e + 1) % 3]];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  }
  for (const auto& [edge, count] : edges) {
    if (count == 1) ++check.boundary_edges;
    if (count > 2) ++check.non_manifold_edges;
  }
  return check;
}

namespace {

// BuildSceneMeshes of `specs` (the scene's meshes or its vehicle's parts), their seeds from
// `seed_base` on.
std::vector<TriangleMesh> BuildMeshes(const Scene& scene, const std::vector<MeshSpec>& specs,
                                      std::uint64_t seed_base) {
  std::vector<TriangleMesh> meshes;
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const MeshSpec& spec = specs[i];
    meshes.push_back(BuildMesh(spec, DeriveSeed(scene.seed, seed_base + i)));
    meshes.back().name = spec.name;
    const std::string where =
        scene.file + ": mesh '" + spec.name + "'" +
        (spec.file.path.empty() ? std::string() : " (" + spec.file.path + ")");
    TriangleMesh& mesh = meshes.back();
    mesh.check = CheckMesh(mesh, where);
    mesh.fill = spec.fill;
    mesh.truth = spec.truth;
    if (spec.fill && (mesh.check.boundary_edges > 0 || mesh.check.non_manifold_edges > 0)) {
      throw InputError(where + ": 'fill' needs a closed mesh, but it has " +
                       std::to_string(mesh.check.boundary_edges) + " open and " +
                       std::to_string(mesh.check.non_manifold_edges) +
                       " non-manifold edges: its inside is not defined");
    }
  }
  return meshes;
}

}  // namespace

std::vector<TriangleMesh> BuildSceneMeshes(const Scene& scene) {
  CheckBudgets(scene, scene.budgets);
  return BuildMeshes(scene, scene.meshes, 0x6d657368ULL);  // "mesh"
}

std::vector<TriangleMesh> BuildVehicleMeshes(const Scene& scene) {
  return BuildMeshes(scene, scene.vehicle, 0x76656869636c65ULL);  // "vehicle"
}

}  // namespace sonarbench::sim
