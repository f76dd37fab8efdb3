#pragma once

#include <Eigen/Core>
#include <span>
#include <string>

#include "sonarbench/sim/eval/scene_score.hpp"

namespace sonarbench::sim {

/// Whether this build embeds three.js, and which version ("" when it does not).
[[nodiscard]] std::string_view View3dThreeVersion();

/// report.html's 3D view of a map: a section that draws, with three.js embedded in the page (it
/// opens offline), the occupied cells of `cells` (edge `resolution_m` [m], world frame) coloured
/// by the classes of map_top.png against `score` (on a surface, the detector's ghost, off surface;
/// the observable surface missed as smaller cubes; all occupied in white when `score` is null),
/// the score's surfaces as translucent meshes and the sonar's path `sonar_path_m`, with orbit,
/// pan and zoom, a toggle per class, a legend and a 1 m grid. Without three.js in the build the
/// section says so. The same inputs give the same bytes.
[[nodiscard]] std::string View3dHtml(const MapCells& cells, double resolution_m,
                                     const SceneScore* score,
                                     std::span<const Eigen::Vector3d> sonar_path_m);

}  // namespace sonarbench::sim
