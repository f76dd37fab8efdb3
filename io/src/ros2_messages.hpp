#pragma once

// The ROS 2 messages a sonar bag carries, as plain structs, with their CDR encoding (XCDR1,
// little-endian, as rosbag2 stores them) and their `ros2msg` definitions for MCAP schemas.

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace sonarbench::io::ros2 {

struct Header {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  std::string frame_id;
};

/// marine_acoustic_msgs/msg/ProjectedSonarImage, the fields sonarbench uses named as there.
struct ProjectedSonarImage {
  Header header;
  float frequency = 0.0F;
  float sound_speed = 0.0F;
  std::vector<float> tx_beamwidths;  // rad
  std::vector<float> rx_beamwidths;  // rad
  std::vector<Eigen::Vector3d> beam_directions;
  std::vector<float> ranges;  // bin centres [m]
  bool is_bigendian = false;
  std::uint32_t dtype = 0;  // 0: DTYPE_UINT8
  std::uint32_t beam_count = 0;
  std::vector<std::uint8_t> data;
};

/// geometry_msgs/msg/TransformStamped.
struct TransformStamped {
  Header header;
  std::string child_frame_id;
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
};

/// sensor_msgs/msg/PointField.
struct PointField {
  static constexpr std::uint8_t kUint8 = 2;
  static constexpr std::uint8_t kUint16 = 4;
  static constexpr std::uint8_t kFloat32 = 7;
  std::string name;
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;
  std::uint32_t count = 1;
};

/// sensor_msgs/msg/PointCloud2: one row of `width` points.
struct PointCloud2 {
  Header header;
  std::uint32_t height = 1;
  std::uint32_t width = 0;
  std::vector<PointField> fields;
  std::uint32_t point_step = 0;
  std::vector<std::uint8_t> data;
};

[[nodiscard]] std::string Encode(const ProjectedSonarImage& m);
[[nodiscard]] std::string Encode(const PointCloud2& m);
[[nodiscard]] std::string EncodeTfMessage(const std::vector<TransformStamped>& transforms);
/// geometry_msgs/msg/PoseStamped.
[[nodiscard]] std::string EncodePoseStamped(const Header& header, const Eigen::Isometry3d& pose);

/// Decoders; throw InputError(`where` + what was expected) on a malformed message.
[[nodiscard]] ProjectedSonarImage DecodeProjectedSonarImage(std::string_view cdr,
                                                            const std::string& where);
[[nodiscard]] std::vector<TransformStamped> DecodeTfMessage(std::string_view cdr,
                                                            const std::string& where);

inline constexpr const char* kProjectedSonarImage = "marine_acoustic_msgs/msg/ProjectedSonarImage";
inline constexpr const char* kTfMessage = "tf2_msgs/msg/TFMessage";
inline constexpr const char* kPoseStamped = "geometry_msgs/msg/PoseStamped";
inline constexpr const char* kPointCloud2 = "sensor_msgs/msg/PointCloud2";
/// The `ros2msg` definition of `type` (one of the four above) with its dependencies.
[[nodiscard]] std::string Definition(const std::string& type);

}  // namespace sonarbench::io::ros2
