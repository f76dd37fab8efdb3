#include "sonarbench/io/rosbag.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "ros2_messages.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/mcap.hpp"
#include "sonarbench/io/text.hpp"

namespace sonarbench::io {
namespace {

constexpr const char* kWorldFrame = "map";
constexpr const char* kVehicleFrame = "base_link";
constexpr const char* kSonarFrame = "sonar";
// A ping's beam widths as float32 radians agree with the sensor's to this [rad].
constexpr double kWidthTolerance = 1e-4;

std::uint64_t Nanoseconds(double time_s) {
  if (!(time_s >= 0.0) || time_s > 2e9) {
    throw InputError("beam time " + Number(time_s) + " s: a ROS stamp needs 0..2e9 s");
  }
  return static_cast<std::uint64_t>(std::llround(time_s * 1e9));
}

ros2::Header Stamp(std::uint64_t ns, const std::string& frame) {
  return {static_cast<std::int32_t>(ns / 1000000000U), static_cast<std::uint32_t>(ns % 1000000000U),
          frame};
}

// rosbag2's record of the publisher's QoS, which `ros2 bag play` offers again: reliable, keep
// last, and transient local for the static transforms so late subscribers get them.
std::string QosProfile(bool transient_local) {
  return std::string("- history: 3\n  depth: 0\n  reliability: 1\n  durability: ") +
         (transient_local ? "1" : "2") +
         "\n  deadline:\n    sec: 2147483647\n    nsec: 4294967295\n  lifespan:\n"
         "    sec: 2147483647\n    nsec: 4294967295\n  liveliness: 1\n"
         "  liveliness_lease_duration:\n    sec: 2147483647\n    nsec: 4294967295\n"
         "  avoid_ros_namespace_conventions: false\n";
}

ros2::ProjectedSonarImage ImageMessage(const Beam& beam, const RosbagContent& bag,
                                       std::uint64_t ns) {
  ros2::ProjectedSonarImage m;
  m.header = Stamp(ns, kSonarFrame);
  m.sound_speed = bag.sound_speed_m_s;
  m.tx_beamwidths = {static_cast<float>(bag.sensor.beam_width_vertical_rad)};
  m.rx_beamwidths = {static_cast<float>(bag.sensor.beam_width_horizontal_rad)};
  m.beam_directions = {mapping::SonarRayDirection(beam.head_angle_rad, 0.0)};
  for (std::size_t k = 0; k < beam.intensities.size(); ++k) {
    m.ranges.push_back(static_cast<float>(beam.BinCentreRange(k)));
  }
  m.beam_count = 1;
  m.data = beam.intensities;
  return m;
}

// The beam with each bin's dominant path (io::EchoPath, the largest share) for its intensity.
Beam PathBeam(const Beam& beam, const BeamLabels& labels) {
  Beam path = beam;
  for (std::size_t k = 0; k < path.intensities.size() && k < labels.shares.size(); ++k) {
    path.intensities[k] = static_cast<std::uint8_t>(DominantPath(labels.shares[k]));
  }
  return path;
}

// The bins a scene mesh answers directly, as points in the sonar frame: x, y, z (float32), the
// mesh (uint16) and the direct share (uint8, 255ths).
ros2::PointCloud2 DirectPoints(const BeamLabels& labels, const ros2::Header& header) {
  ros2::PointCloud2 cloud;
  cloud.header = header;
  cloud.fields = {{"x", 0, ros2::PointField::kFloat32},
                  {"y", 4, ros2::PointField::kFloat32},
                  {"z", 8, ros2::PointField::kFloat32},
                  {"mesh", 12, ros2::PointField::kUint16},
                  {"direct_share", 14, ros2::PointField::kUint8}};
  cloud.point_step = 16;
  for (std::size_t k = 0; k < labels.mesh.size(); ++k) {
    if (labels.mesh[k] == kNoLabelMesh) continue;
    char point[16] = {};
    std::memcpy(point, labels.point_sonar_m[k].data(), 12);
    std::memcpy(point + 12, &labels.mesh[k], 2);
    point[14] = static_cast<char>(labels.shares[k][static_cast<std::size_t>(EchoPath::kDirect)]);
    cloud.data.insert(cloud.data.end(), point, point + 16);
    ++cloud.width;
  }
  return cloud;
}

}  // namespace

void WriteRosbag(std::ostream& out, const RosbagContent& bag, const std::string& library) {
  const bool labels = !bag.labels.empty();
  if (labels && bag.labels.size() != bag.beams.size()) {
    throw std::invalid_argument("WriteRosbag: " + std::to_string(bag.labels.size()) +
                                " beams' labels for " + std::to_string(bag.beams.size()) +
                                " beams");
  }
  McapWriter w(out, "ros2", library);
  const char* types[] = {ros2::kProjectedSonarImage, ros2::kTfMessage, ros2::kPoseStamped,
                         ros2::kPointCloud2};
  for (std::uint16_t id = 1; id <= (labels ? 4 : 3); ++id) {
    w.Add(McapSchema{id, types[id - 1], "ros2msg", ros2::Definition(types[id - 1])});
  }
  const bool truth = !bag.true_vehicle.empty();
  w.Add(McapChannel{1, 1, kSonarTopic, "cdr", {{"offered_qos_profiles", QosProfile(false)}}});
  w.Add(McapChannel{2, 2, "/tf", "cdr", {{"offered_qos_profiles", QosProfile(false)}}});
  w.Add(McapChannel{3, 2, "/tf_static", "cdr", {{"offered_qos_profiles", QosProfile(true)}}});
  if (truth) {
    w.Add(
        McapChannel{4, 3, kGroundTruthTopic, "cdr", {{"offered_qos_profiles", QosProfile(false)}}});
  }
  if (labels) {
    w.Add(McapChannel{5, 1, kLabelPathTopic, "cdr", {{"offered_qos_profiles", QosProfile(false)}}});
    w.Add(
        McapChannel{6, 4, kLabelPointsTopic, "cdr", {{"offered_qos_profiles", QosProfile(false)}}});
  }
  std::uint32_t sequence[7] = {};
  const auto write = [&](std::uint16_t channel, std::uint64_t ns, std::string data) {
    w.Write(McapMessage{channel, sequence[channel]++, ns, ns, std::move(data)});
  };
  const std::uint64_t first = bag.beams.empty() ? 0 : Nanoseconds(bag.beams.front().time_s);
  write(3, first,
        ros2::EncodeTfMessage({{Stamp(first, kVehicleFrame), kSonarFrame, bag.T_vehicle_sonar}}));
  const Eigen::Isometry3d sonar_vehicle = bag.T_vehicle_sonar.inverse();
  for (std::size_t b = 0; b < bag.beams.size(); ++b) {
    const Beam& beam = bag.beams[b];
    const std::uint64_t ns = Nanoseconds(beam.time_s);
    write(2, ns,
          ros2::EncodeTfMessage(
              {{Stamp(ns, kWorldFrame), kVehicleFrame, beam.T_world_sonar * sonar_vehicle}}));
    write(1, ns, ros2::Encode(ImageMessage(beam, bag, ns)));
    if (truth) write(4, ns, ros2::EncodePoseStamped(Stamp(ns, kWorldFrame), bag.true_vehicle[b]));
    if (labels) {
      write(5, ns, ros2::Encode(ImageMessage(PathBeam(beam, bag.labels[b]), bag, ns)));
      write(6, ns, ros2::Encode(DirectPoints(bag.labels[b], Stamp(ns, kSonarFrame))));
    }
  }
  w.Finish();
}

namespace {

// The transforms of /tf and /tf_static, by child frame.
class TransformTree {
 public:
  void Add(const ros2::TransformStamped& t, bool is_static, const std::string& where) {
    auto [it, added] = parent_.emplace(t.child_frame_id, t.header.frame_id);
    if (!added && it->second != t.header.frame_id) {
      throw InputError(where + "frame " + Quoted(t.child_frame_id) + " has two parents, " +
                       Quoted(it->second) + " and " + Quoted(t.header.frame_id));
    }
    if (is_static) {
      static_[t.child_frame_id] = t.transform;
    } else {
      dynamic_[t.child_frame_id].emplace_back(Seconds(t.header), t.transform);
    }
  }
  void Sort() {
    for (auto& [child, list] : dynamic_) {
      std::stable_sort(list.begin(), list.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
    }
  }
  [[nodiscard]] bool Has(const std::string& frame) const { return parent_.count(frame) != 0; }
  // T_root_frame at time `t` and the root's name; nullopt when a moving link has no transform
  // at or around `t`. A loop is refused naming `path`, the bag.
  std::optional<Eigen::Isometry3d> Lookup(std::string frame, double t, std::string& root,
                                          const std::string& path) const {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    for (int depth = 0; parent_.count(frame); ++depth) {
      if (depth == 64) {
        throw InputError(path + ": the transforms from " + Quoted(frame) +
                         " form a loop (expected a tree of frames on /tf and /tf_static)");
      }
      const auto s = static_.find(frame);
      std::optional<Eigen::Isometry3d> link;
      if (s != static_.end()) {
        link = s->second;
      } else {
        link = Interpolate(dynamic_.at(frame), t);
      }
      if (!link) return std::nullopt;
      pose = *link * pose;
      frame = parent_.at(frame);
    }
    root = frame;
    return pose;
  }
  static double Seconds(const ros2::Header& h) { return h.sec + h.nanosec * 1e-9; }

 private:
  using Timed = std::vector<std::pair<double, Eigen::Isometry3d>>;
  static std::optional<Eigen::Isometry3d> Interpolate(const Timed& list, double t) {
    const auto after = std::lower_bound(list.begin(), list.end(), t,
                                        [](const auto& e, double v) { return e.first < v; });
    if (after == list.end()) return std::nullopt;
    if (after->first == t) return after->second;
    if (after == list.begin()) return std::nullopt;
    const auto& [t0, a] = *(after - 1);
    const double s = (t - t0) / (after->first - t0);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = (1 - s) * a.translation() + s * after->second.translation();
    pose.linear() = Eigen::Quaterniond(a.linear())
                        .slerp(s, Eigen::Quaterniond(after->second.linear()))
                        .toRotationMatrix();
    return pose;
  }
  std::map<std::string, std::string> parent_;
  std::map<std::string, Eigen::Isometry3d> static_;
  std::map<std::string, Timed> dynamic_;
};

// Whether bins of `bin` metres have the centres `ranges` once rounded to float32, as written.
bool Reproduces(const std::vector<float>& ranges, double bin) {
  for (std::size_t k = 0; k < ranges.size(); ++k) {
    if (static_cast<float>((static_cast<double>(k) + 0.5) * bin) != ranges[k]) return false;
  }
  return true;
}

// The bin size whose centres are `ranges`: the sensor's, or the float32 nearest their spacing,
// when it reproduces them exactly (so a written bin size reads back as it was); else their
// spacing. nullopt when they are not the centres of equal bins from range 0.
std::optional<double> BinSize(const std::vector<float>& ranges, double sensor_bin) {
  const auto n = ranges.size();
  if (n == 0) return std::nullopt;
  if (Reproduces(ranges, sensor_bin)) return sensor_bin;
  const double d = ranges[n - 1] / (static_cast<double>(n) - 0.5);
  for (std::size_t k = 0; k < n; ++k) {
    if (!(d > 0.0) || std::abs(ranges[k] - (static_cast<double>(k) + 0.5) * d) > 1e-3 * d) {
      return std::nullopt;
    }
  }
  const double single = static_cast<float>(d);
  return Reproduces(ranges, single) ? single : d;
}

// The head angle in [0, 2π) of a beam direction: of the doubles next to atan2's answer, the
// nearest whose cosine and sine are the direction's x and y exactly (the angle a writer took
// them from), else atan2's answer.
double HeadAngle(const Eigen::Vector3d& d) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  double a = std::atan2(d.y(), d.x());
  if (a < 0.0) a += kTwoPi;
  if (a >= kTwoPi) a = 0.0;
  double down = a;
  double up = a;
  for (int step = 0; step <= 4; ++step) {
    for (const double c : {down, up}) {
      if (std::cos(c) == d.x() && std::sin(c) == d.y() && c >= 0.0 && c < kTwoPi) return c;
    }
    down = std::nextafter(down, -1.0);
    up = std::nextafter(up, 10.0);
  }
  return a;
}

void CheckWidth(const std::vector<float>& widths, double expected, const char* field,
                const std::string& where) {
  if (!widths.empty() && !(std::abs(widths[0] - expected) <= kWidthTolerance)) {
    throw InputError(where + "ping_info." + field + " is " +
                     std::to_string(widths[0] / mapping::kDegToRad) + "°; the sensor model's is " +
                     std::to_string(expected / mapping::kDegToRad) +
                     "° (pass --sensor with this sonar's model)");
  }
}

Beam ImageBeam(const ros2::ProjectedSonarImage& m, const RosbagReadOptions& options,
               const std::string& where) {
  if (m.beam_count != 1 || m.beam_directions.size() != 1) {
    throw InputError(where + "holds " + std::to_string(m.beam_directions.size()) +
                     " beam directions (beam_count " + std::to_string(m.beam_count) +
                     "); expected one beam a message, as a mechanical scanning sonar pings");
  }
  if (m.dtype != 0) {
    throw InputError(where + "image.dtype is " + std::to_string(m.dtype) +
                     "; expected 0 (DTYPE_UINT8, 8-bit intensities)");
  }
  if (m.ranges.size() > kMaxBinsPerBeam) {
    throw InputError(where + "image holds " + std::to_string(m.ranges.size()) +
                     " ranges; expected at most " + std::to_string(kMaxBinsPerBeam));
  }
  if (m.data.size() != m.ranges.size()) {
    throw InputError(where + "image.data holds " + std::to_string(m.data.size()) + " bytes for " +
                     std::to_string(m.ranges.size()) + " ranges; expected one byte a range");
  }
  const Eigen::Vector3d& d = m.beam_directions[0];
  if (!(d.head<2>().norm() > 0.0) || std::abs(d.z()) > 1e-6 * d.norm()) {
    throw InputError(where +
                     "beam_directions[0] must lie in the frame's x-y plane (the head's "
                     "rotation plane; z the head's axis)");
  }
  const std::optional<double> bin = BinSize(m.ranges, options.sensor.bin_size_m);
  if (!bin) {
    throw InputError(where +
                     "ranges must be the centres of equal bins from range 0: ranges[k] "
                     "= (k + 0.5) · bin size, bin size > 0");
  }
  CheckWidth(m.tx_beamwidths, options.sensor.beam_width_vertical_rad, "tx_beamwidths", where);
  CheckWidth(m.rx_beamwidths, options.sensor.beam_width_horizontal_rad, "rx_beamwidths", where);
  Beam beam;
  beam.time_s = TransformTree::Seconds(m.header);
  beam.head_angle_rad = HeadAngle(d);
  beam.bin_size_m = *bin;
  beam.intensities = m.data;
  return beam;
}

// The one ProjectedSonarImage channel (or the one named), with its CDR encoding checked.
const McapChannel& SonarChannel(const McapFile& file, const std::string& path,
                                const std::string& topic,
                                const std::map<std::uint16_t, std::string>& types) {
  std::vector<const McapChannel*> found;
  for (const McapChannel& c : file.channels) {
    const bool sonar =
        types.count(c.schema_id) && types.at(c.schema_id) == ros2::kProjectedSonarImage;
    // Unnamed, the sonar's topic is the one that is not the labels' (a simulated bag's).
    if (topic.empty() ? sonar && c.topic != kLabelPathTopic : c.topic == topic) {
      if (!sonar) {
        throw InputError(path + ": topic " + Quoted(topic) + " is not of type " +
                         ros2::kProjectedSonarImage);
      }
      found.push_back(&c);
    }
  }
  if (found.empty() && !topic.empty()) {
    std::string topics;
    for (const McapChannel& c : file.channels) {
      const bool sonar =
          types.count(c.schema_id) && types.at(c.schema_id) == ros2::kProjectedSonarImage;
      if (sonar) topics += (topics.empty() ? "" : ", ") + c.topic;
    }
    throw InputError(path + ": no topic named " + Quoted(topic) + "; the bag's " +
                     ros2::kProjectedSonarImage +
                     " topics: " + (topics.empty() ? std::string("none") : topics));
  }
  if (found.size() != 1) {
    std::string topics;
    for (const McapChannel* c : found) topics += " " + c->topic;
    throw InputError(path + ": " + std::to_string(found.size()) + " " + ros2::kProjectedSonarImage +
                     " topics" + (topic.empty() ? "" : " named " + Quoted(topic)) +
                     (found.empty() ? "" : " (" + topics.substr(1) + "); name one with --topic") +
                     "; expected one");
  }
  if (found[0]->message_encoding != "cdr") {
    throw InputError(path + ": topic " + found[0]->topic + " is encoded as " +
                     Quoted(found[0]->message_encoding) + "; expected cdr");
  }
  return *found[0];
}

// Poses each beam by the transforms from its frame to the tree's root; leaves out (and counts)
// the beams they do not cover.
void PoseBeams(RosbagBeams& out, TransformTree& tree, const std::string& path) {
  if (!tree.Has(out.sonar_frame)) {
    throw InputError(path + ": no /tf or /tf_static transform has the images' frame " +
                     Quoted(out.sonar_frame) +
                     " as its child; record the transforms, or pass --static to map the sonar as "
                     "static at the origin");
  }
  tree.Sort();
  std::vector<Beam> posed;
  for (Beam& beam : out.beams) {
    std::string root;
    const auto pose = tree.Lookup(out.sonar_frame, beam.time_s, root, path);
    if (!pose) continue;
    if (!out.world_frame.empty() && root != out.world_frame) {
      throw InputError(path + ": the transforms from " + Quoted(out.sonar_frame) + " reach " +
                       Quoted(out.world_frame) + " and later " + Quoted(root));
    }
    out.world_frame = root;
    beam.T_world_sonar = *pose;
    posed.push_back(std::move(beam));
  }
  out.beams_outside_tf = out.beams.size() - posed.size();
  if (posed.empty()) {
    throw InputError(path + ": the transforms to " + Quoted(out.sonar_frame) +
                     " cover the time of none of its " + std::to_string(out.beams.size()) +
                     " beams");
  }
  out.beams = std::move(posed);
}

RosbagBeams Counted(RosbagBeams out, const SensorGeometry& sensor) {
  for (const Beam& b : out.beams) {
    out.truncated_beams += b.intensities.size() != static_cast<std::size_t>(sensor.num_bins);
  }
  return out;
}

}  // namespace

RosbagBeams ReadRosbag(const std::string& path, const RosbagReadOptions& options) {
  const McapFile file = ReadMcap(path, options.max_bytes);
  std::map<std::uint16_t, std::string> types;
  for (const McapSchema& s : file.schemas) types[s.id] = s.name;
  const McapChannel& sonar = SonarChannel(file, path, options.topic, types);
  RosbagBeams out;
  out.topic = sonar.topic;
  TransformTree tree;
  std::map<std::uint16_t, bool> tf_channels;  // id → static
  for (const McapChannel& c : file.channels) {
    if ((c.topic == "/tf" || c.topic == "/tf_static") && types.count(c.schema_id) &&
        types.at(c.schema_id) == ros2::kTfMessage && c.message_encoding == "cdr") {
      tf_channels[c.id] = c.topic == "/tf_static";
    }
  }
  std::size_t count = 0;
  for (const McapMessage& m : file.messages) {
    const std::string where = path + ": message " + std::to_string(count++) + " (log time " +
                              std::to_string(m.log_time_ns) + " ns) on ";
    if (m.channel_id == sonar.id) {
      const auto image = ros2::DecodeProjectedSonarImage(m.data, where + sonar.topic + ": ");
      if (out.beams.empty()) out.sonar_frame = image.header.frame_id;
      if (image.header.frame_id != out.sonar_frame) {
        throw InputError(where + sonar.topic + ": frame " + Quoted(image.header.frame_id) +
                         "; the first image's is " + Quoted(out.sonar_frame));
      }
      out.beams.push_back(ImageBeam(image, options, where + sonar.topic + ": "));
    } else if (!options.static_sonar && tf_channels.count(m.channel_id)) {
      const bool is_static = tf_channels.at(m.channel_id);
      const std::string w = where + (is_static ? "/tf_static: " : "/tf: ");
      for (const auto& t : ros2::DecodeTfMessage(m.data, w)) tree.Add(t, is_static, w);
    }
  }
  if (out.beams.empty()) throw InputError(path + ": no message on " + sonar.topic);
  std::stable_sort(out.beams.begin(), out.beams.end(),
                   [](const Beam& a, const Beam& b) { return a.time_s < b.time_s; });
  if (options.static_sonar) return Counted(std::move(out), options.sensor);
  PoseBeams(out, tree, path);
  return Counted(std::move(out), options.sensor);
}

}  // namespace sonarbench::io
