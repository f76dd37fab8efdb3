// Maps one sweep of synthetic beams that each see a wall 2 m away, with the installed library,
// and checks the map: exits 0 when the wall's cells are occupied and the water before it free,
// and the first beam's own cells (beam_cells.hpp) agree.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "sonarbench/mapping/beam_cells.hpp"
#include "sonarbench/mapping/mapper.hpp"

int main() {
  using sonarbench::mapping::Beam;
  const sonarbench::mapping::SensorGeometry sensor;  // the SHAD's Micron
  const double wall_m = 2.0;
  std::vector<Beam> sweep;
  for (int b = 0; b < sensor.BeamsPerSweep(); ++b) {
    Beam beam;
    beam.head_angle_rad = b * sensor.step_angle_rad;
    beam.bin_size_m = sensor.bin_size_m;
    beam.intensities.assign(static_cast<std::size_t>(sensor.num_bins), 10);
    const auto wall_bin = static_cast<std::size_t>(wall_m / sensor.bin_size_m);
    for (std::size_t k = wall_bin; k < wall_bin + 4; ++k) beam.intensities[k] = 200;
    sweep.push_back(beam);
  }
  sonarbench::mapping::Mapper mapper({}, sensor);
  const auto stats = mapper.Integrate(sweep);
  const octomap::OcTree& tree = mapper.tree();
  // The echo's range is the detection's, within a cell of the wall: one of the cells on the x
  // axis within a cell and a half of it is occupied.
  bool wall = false;
  for (const double x : {wall_m - 0.075, wall_m - 0.025, wall_m + 0.025, wall_m + 0.075}) {
    const octomap::OcTreeNode* cell = tree.search(x, 0.01, 0.01);
    wall = wall || (cell != nullptr && tree.isNodeOccupied(cell));
  }
  const octomap::OcTreeNode* water = tree.search(1.0, 0.01, 0.01);
  const bool free = water != nullptr && !tree.isNodeOccupied(water);
  // The first beam alone, as the mapper's exact integration sees it: its wall cell on the shell.
  const double obstacle[] = {wall_m};
  const auto keys = sonarbench::mapping::ExactBeamKeys(tree, sensor, sweep.front(), obstacle, 0.0);
  const bool beam_cells = keys.occupied.contains(tree.coordToKey(wall_m + 0.01, 0.01, 0.01)) &&
                          keys.free.contains(tree.coordToKey(1.0, 0.01, 0.01));
  const bool ok = wall && free && beam_cells && stats.beams_with_obstacle == sweep.size();
  std::printf("%zu beams, %zu with an obstacle; wall %s, water %s, beam cells %s: %s\n",
              stats.beams, stats.beams_with_obstacle, wall ? "occupied" : "not occupied",
              free ? "free" : "not free", beam_cells ? "agree" : "disagree", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
