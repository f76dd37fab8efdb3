#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sonarbench/sim/world/budget.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/scene.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

// A static scene at 0.1 m resolution holding `meshes` (a YAML list) of material m.
Scene SmallScene(const test::TempDir& dir, const std::string& meshes) {
  const std::string path = test::WriteFile(
      dir, "scene.yaml",
      "name: budget\nsensor_model: " + test::SourcePath("sensor-models/shad-micron.yaml") +
          "\nsweeps: 1\nmaterials: [{name: m, reflectivity: 0.5}]\nmeshes: " + meshes +
          "\ntrajectory: {type: static, position_m: [0, 0, 0]}\nmapping: {resolution_m: 0.1}\n");
  return LoadScene(path);
}

TEST(Budgets, EstimatesAreTheMeshesTrianglesAreasAndVolumes) {
  test::TempDir dir;
  const Scene scene = SmallScene(
      dir,
      "[{name: box, type: box, size_m: [2, 3, 4], fill: true, material: m},"
      " {name: bed, type: height_field, size_m: [10, 20, 0], cell_m: 0.5, material: m}]");
  const SceneEstimate e = EstimateScene(scene);
  // Box: 12 triangles; height field: 2 per cell of a 20 x 40 grid.
  EXPECT_DOUBLE_EQ(e.triangles, 12 + 2 * 20 * 40);
  // Box surface 2(6 + 12 + 8) m² and volume 24 m³; the bed 200 m²; cells of 0.1 m.
  EXPECT_NEAR(e.truth_cells, (52 + 200) / 0.01 + 24 / 0.001, 1e-6);
  // A static sonar sweeps the zone of its range sphere within ±17.5° of elevation.
  const double r = scene.sensor.geometry.MaxRangeM();
  EXPECT_NEAR(
      e.map_cells,
      4.0 / 3.0 * std::numbers::pi * r * r * r * std::sin(17.5 * std::numbers::pi / 180) / 1e-3,
      1e-6 * e.map_cells);
}

TEST(Budgets, ARefusalNamesTheKeyTheEstimateTheLimitAndTheOption) {
  test::TempDir dir;
  Scene fine = SmallScene(
      dir, "[{name: bed, type: height_field, size_m: [10, 20, 0], cell_m: 0.001, material: m}]");
  // 2 · 10⁴ · 2·10⁴ = 4·10⁸ triangles.
  std::string error = test::InputErrorOf([&] { (void)BuildSceneMeshes(fine); });
  for (const char* part : {"scene.yaml: mesh 'bed' 'cell_m'", "an estimated 4e+08 triangles",
                           "more than the 2e+07", "--max-triangles raises the limit"}) {
    EXPECT_NE(error.find(part), std::string::npos) << part << " in " << error;
  }
  fine.budgets.max_triangles = 1e9;
  EXPECT_NO_THROW(CheckBudgets(fine, fine.budgets));
  // A cell size whose count overflows any integer is refused, not wrapped.
  const Scene tiny = SmallScene(
      dir, "[{name: bed, type: height_field, size_m: [10, 20, 0], cell_m: 1e-300, material: m}]");
  error = test::InputErrorOf([&] { (void)BuildSceneMeshes(tiny); });
  EXPECT_NE(error.find("an estimated unbounded number of triangles"), std::string::npos) << error;
  // A filled box 2 km a side: 8·10⁹ m³ in 10⁻³ m³ cells.
  const Scene block = SmallScene(
      dir, "[{name: block, type: box, size_m: [2000, 2000, 2000], fill: true, material: m}]");
  error = test::InputErrorOf([&] { (void)BuildSceneMeshes(block); });
  EXPECT_NE(error.find("mesh 'block' 'fill' at 'mapping.resolution_m' 0.1: its ground truth takes "
                       "an estimated 8e+12 cells"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("--max-cells"), std::string::npos) << error;
}

TEST(Budgets, AScaledMeshFileIsWeighedAtItsScale) {
  test::TempDir dir;
  const std::string rock = test::SourcePath("scenes/meshes/rock.obj");
  const Scene one = SmallScene(dir, "[{name: r, type: file, file: " + rock + ", material: m}]");
  const Scene big = SmallScene(
      dir, "[{name: r, type: file, file: " + rock + ", scale: [1e3, 1e3, 1e3], material: m}]");
  // Area grows with the square of the scale.
  EXPECT_NEAR(EstimateScene(big).truth_cells, 1e6 * EstimateScene(one).truth_cells,
              1e-6 * EstimateScene(big).truth_cells);
  EXPECT_NE(test::InputErrorOf([&] { (void)BuildSceneMeshes(big); }).find("mesh 'r' 'scale'"),
            std::string::npos);
}

TEST(Budgets, ShippedScenesUseUnderAHundredthOfTheDefaults) {
  const Budgets defaults;
  for (const char* name : {"cras-tank", "cras-tank-nav-drift", "cras-tank-sparse-rays",
                           "harbour-wall", "rocks-slope", "seabed", "tank-crate"}) {
    const SceneEstimate e =
        EstimateScene(LoadScene(test::SourcePath("scenes/" + std::string(name) + ".yaml")));
    EXPECT_LT(e.triangles, defaults.max_triangles / 100) << name;
    EXPECT_LT(e.truth_cells, defaults.max_cells / 100) << name;
    EXPECT_LT(e.map_cells, defaults.max_cells / 50) << name;
  }
}

}  // namespace
}  // namespace sonarbench::sim
