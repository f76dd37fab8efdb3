#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sonarbench/mapping/beam.hpp"

namespace sonarbench::io {

// The mapper's types these files hold.
using mapping::Beam;

/// Reads a real MSIS log saved by the CRAS lab's tools as a MATLAB v5 (or v7.3) `.mat` file:
/// one variable `parsedData`, a struct array with one element per ping and the fields `time` [s],
/// `angle` [deg], `step_dist` [m] and `intensities` (0..255, any numeric class). The vehicle was
/// static for these logs, so every beam gets the identity pose (the sonar at the world origin).
///
/// Throws InputError naming the file, the beam index and the field when the file is missing or
/// not a .mat, the variable or a field is absent, a value has the wrong shape or class, or an
/// intensity is not an integer in 0..255. A beam whose bin count differs from the log's usual
/// count (the last, truncated ping of a log) is kept as it is; `truncated_beams` counts them.
/// A file over `max_bytes`, or a v5 file whose compressed elements inflate past it with the
/// file's own bytes, is refused before the allocation; so is a FIFO, device or directory.
struct MatLog {
  std::vector<Beam> beams;
  std::size_t truncated_beams = 0;
};
[[nodiscard]] MatLog ReadMatLog(const std::string& path,
                                std::uint64_t max_bytes = std::uint64_t{384} << 20);

}  // namespace sonarbench::io
