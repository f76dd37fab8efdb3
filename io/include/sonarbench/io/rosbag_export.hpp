#pragma once

#include <cstddef>
#include <string>

#include "sonarbench/io/rosbag.hpp"

namespace sonarbench::io {

/// What `sonarbench export` writes of a dataset (docs/ros2.md): its beams with the reported
/// poses, the mounting (from the true vehicle and sonar poses of a simulated dataset; the
/// identity for a recorded log, whose vehicle frame is then the sonar's), and the true vehicle
/// poses when the dataset has them. Throws InputError as ReadDataset does, or when a
/// simulated dataset's mounting is not rigid.
[[nodiscard]] RosbagContent RosbagFromDataset(const std::string& dir);

/// Writes `bag` to `path` atomically. An existing `path` is replaced only with `force` and only
/// when it is an MCAP file sonarbench wrote (its header names sonarbench); anything else there is
/// refused by name, as are the dataset's own files.
void WriteRosbagFile(const RosbagContent& bag, const std::string& path, bool force);

}  // namespace sonarbench::io
