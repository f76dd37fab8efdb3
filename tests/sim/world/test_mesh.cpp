#include <gtest/gtest.h>

#include "sonarbench/base/error.hpp"
#include "sonarbench/sim/eval/ground_truth.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/world/mesh.hpp"

namespace sonarbench::sim {
namespace {

using Eigen::Vector3d;

TEST(BuildSceneMeshes, FillingAnOpenMeshIsRefused) {
  Scene scene;
  scene.file = "s.yaml";
  scene.materials.push_back({});
  MeshSpec tank;
  tank.name = "tank";
  tank.type = MeshSpec::Type::kTank;
  tank.size_m = {4, 4, 1.5};
  tank.fill = true;
  scene.meshes.push_back(tank);
  try {
    (void)BuildSceneMeshes(scene);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.yaml: mesh 'tank': 'fill' needs a closed mesh, but it "
                                         "has 4 open"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace sonarbench::sim
