#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "sonarbench/io/labels.hpp"
#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::io {

// The mapper's types these files hold.
using mapping::Beam;
using mapping::SensorGeometry;

/// A ROS 2 bag (MCAP storage, `ros2` profile, CDR messages) of sonar beams, as `sonarbench
/// export` writes it and `sonarbench import` reads it (docs/ros2.md):
///   /sonar/image        marine_acoustic_msgs/msg/ProjectedSonarImage, one beam a message, in
///                       frame `sonar` (x along head angle 0, z the head's axis)
///   /tf                 tf2_msgs/msg/TFMessage: map → base_link, the reported vehicle pose at
///                       each beam's time
///   /tf_static          base_link → sonar, the mounting
///   /ground_truth/pose  geometry_msgs/msg/PoseStamped: the true base_link pose (simulated data)
///   /sonar/labels/path  ProjectedSonarImage beside each beam, each bin's dominant echo path
///                       (io::EchoPath) for its value (simulated data with labels)
///   /sonar/labels/points sensor_msgs/msg/PointCloud2 beside each beam: its bins' direct
///                       returns in frame `sonar` (x, y, z, mesh, direct_share)
struct RosbagContent {
  SensorGeometry sensor;
  /// Beams with their reported T_world_sonar.
  std::vector<Beam> beams;
  /// Mounting T_vehicle_sonar (base_link → sonar).
  Eigen::Isometry3d T_vehicle_sonar = Eigen::Isometry3d::Identity();
  /// The true T_world_vehicle at each beam (simulated data), or empty.
  std::vector<Eigen::Isometry3d> true_vehicle;
  /// Each beam's labels (a simulated dataset's), or empty.
  std::vector<BeamLabels> labels;
  /// The speed of sound [m/s] that ranges were computed at.
  float sound_speed_m_s = 1500.0F;
};

inline constexpr const char* kSonarTopic = "/sonar/image";
inline constexpr const char* kGroundTruthTopic = "/ground_truth/pose";
inline constexpr const char* kLabelPathTopic = "/sonar/labels/path";
inline constexpr const char* kLabelPointsTopic = "/sonar/labels/points";

/// Writes `bag` as an MCAP file to `out`; its header names `library`.
void WriteRosbag(std::ostream& out, const RosbagContent& bag, const std::string& library);

struct RosbagReadOptions {
  /// The sensor the beams came from: its bin size is taken when it reproduces a message's float32
  /// ranges, and the messages' beam widths must match its own.
  SensorGeometry sensor;
  /// The ProjectedSonarImage topic; empty: the bag's only one.
  std::string topic;
  /// No transforms: every beam at the identity pose (a static sonar, as a .mat log is).
  bool static_sonar = false;
  /// Bytes the file and its decompressed chunks may take.
  std::uint64_t max_bytes = std::uint64_t{384} << 20;
};

struct RosbagBeams {
  std::vector<Beam> beams;
  std::string topic;
  std::string sonar_frame;
  /// The frame the poses are in (the root of the transform tree); empty when static_sonar.
  std::string world_frame;
  /// Beams whose bin count differs from the sensor's.
  std::size_t truncated_beams = 0;
  /// Beams dropped because the transforms do not cover their time.
  std::size_t beams_outside_tf = 0;
};

/// Reads the sonar beams of a ROS 2 MCAP bag: one ProjectedSonarImage a beam (one beam
/// direction in the frame's x-y plane, uint8 data, ranges the centres of equal bins from 0),
/// each posed by composing /tf_static and /tf (interpolated at the beam's stamp) from the image's
/// frame to the tree's root. Throws InputError naming the file, topic, message and field.
[[nodiscard]] RosbagBeams ReadRosbag(const std::string& path, const RosbagReadOptions& options);

}  // namespace sonarbench::io
