#pragma once

#include <cstddef>

namespace sonarbench::mapping {

/// Per-batch counts, for reports and benchmarks.
struct BatchStats {
  std::size_t beams = 0;
  std::size_t beams_with_obstacle = 0;
  std::size_t ray_casts = 0;
  /// Cell visits by all rays, repeats included.
  std::size_t cell_visits = 0;
  /// Exact mode: of the cells examined (cell_visits), those its bounds did not decide, which
  /// were decided by clipping the cell's faces.
  std::size_t clipped_cells = 0;
  /// Distinct free cells of each beam, summed over the beams: what goes into the key sets.
  std::size_t beam_free_cells = 0;
  /// Distinct cells updated free / occupied.
  std::size_t free_cells = 0;
  std::size_t occupied_cells = 0;
  /// Wall time [s] of the stages: ray casting into the threads' sets, splitting the sets' cells
  /// into octants, and per octant merging (occupied winning), sorting and applying the updates.
  double cast_s = 0.0;
  double split_s = 0.0;
  double update_s = 0.0;

  BatchStats& operator+=(const BatchStats& o) {
    beams += o.beams;
    beams_with_obstacle += o.beams_with_obstacle;
    ray_casts += o.ray_casts;
    cell_visits += o.cell_visits;
    clipped_cells += o.clipped_cells;
    beam_free_cells += o.beam_free_cells;
    free_cells += o.free_cells;
    occupied_cells += o.occupied_cells;
    cast_s += o.cast_s;
    split_s += o.split_s;
    update_s += o.update_s;
    return *this;
  }
};

}  // namespace sonarbench::mapping
