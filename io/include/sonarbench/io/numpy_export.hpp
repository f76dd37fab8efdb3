#pragma once

#include <string>

namespace sonarbench::io {

/// Writes a dataset as a NumPy .npz file (docs/dataset-format.md, "For Python"), sweeps × beams
/// × bins: intensities (a shorter beam padded with zeros), valid (false where a short last
/// sweep ends), bin_count, time_s, head_angle_rad,
/// sonar_pose (reported; tx ty tz qx qy qz qw), bin_size_m, and for a simulated dataset
/// sonar_pose_true and its labels (label_shares in 255ths by label_paths, label_mesh indexing
/// mesh_names, 65535 for none, label_point_sonar_m). Replaces only an .npz sonarbench wrote, with
/// `force`. Throws InputError as ReadDataset does.
void WriteNpzFromDataset(const std::string& dir, const std::string& path, bool force);

}  // namespace sonarbench::io
