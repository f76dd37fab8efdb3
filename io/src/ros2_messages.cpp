#include "ros2_messages.hpp"

#include <cmath>
#include <cstring>
#include <map>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/text.hpp"

namespace sonarbench::io::ros2 {
namespace {

// CDR (XCDR1, little-endian): a 4-byte encapsulation header, then each primitive aligned to its
// size from the end of that header; strings and sequences are a u32 count first.
class CdrWriter {
 public:
  CdrWriter() : out_("\x00\x01\x00\x00", 4) {}
  template <typename T>
  void Put(T value) {
    Align(sizeof(T));
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));  // the machines sonarbench builds on are little-endian
    out_.append(bytes, sizeof(T));
  }
  void String(const std::string& s) {
    Put<std::uint32_t>(static_cast<std::uint32_t>(s.size() + 1));
    out_ += s;
    out_ += '\0';
  }
  template <typename T>
  void Sequence(const std::vector<T>& values) {
    Put<std::uint32_t>(static_cast<std::uint32_t>(values.size()));
    for (const T v : values) Put<T>(v);
  }
  void Header(const ros2::Header& h) {
    Put(h.sec);
    Put(h.nanosec);
    String(h.frame_id);
  }
  void Vector(const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) Put(v[i]);
  }
  void Pose(const Eigen::Isometry3d& pose) {  // translation, then the quaternion x y z w
    Vector(pose.translation());
    const Eigen::Quaterniond q(pose.linear());
    for (const double c : {q.x(), q.y(), q.z(), q.w()}) Put(c);
  }
  [[nodiscard]] const std::string& Bytes() const { return out_; }

 private:
  void Align(std::size_t n) {
    while ((out_.size() - 4) % n != 0) out_ += '\0';
  }
  std::string out_;
};

class CdrReader {
 public:
  CdrReader(std::string_view in, const std::string& where) : in_(in), where_(where) {
    if (in_.size() < 4 || in_[0] != 0 || in_[1] != 1) {
      Fail("expected CDR little-endian encapsulation (0x00 0x01) at the start");
    }
  }
  template <typename T>
  T Get(const char* field) {
    Align(sizeof(T));
    Need(sizeof(T), field);
    T value;
    std::memcpy(&value, in_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  std::string String(const char* field) {
    const auto n = Get<std::uint32_t>(field);
    Need(n, field);
    if (n == 0 || in_[at_ + n - 1] != '\0') Fail(std::string(field) + ": a string without its NUL");
    std::string s(in_.substr(at_, n - 1));
    at_ += n;
    if (!IsUtf8(s)) Fail(std::string(field) + ": " + Quoted(s) + " is not UTF-8");
    return s;
  }
  // A sequence's count, refused when that many elements of at least `element_size` bytes cannot
  // fit in what is left (before anything is allocated for them).
  std::size_t Count(std::size_t element_size, const char* field) {
    const auto n = Get<std::uint32_t>(field);
    if (element_size * n > in_.size() - std::min(at_, in_.size())) {
      Fail(std::string(field) + ": " + std::to_string(n) + " elements do not fit in the message");
    }
    return n;
  }
  template <typename T>
  std::vector<T> Sequence(const char* field) {
    std::vector<T> values(Count(sizeof(T), field));
    for (T& v : values) v = Get<T>(field);
    return values;
  }
  ros2::Header Header() {
    ros2::Header h;
    h.sec = Get<std::int32_t>("header.stamp.sec");
    h.nanosec = Get<std::uint32_t>("header.stamp.nanosec");
    if (h.nanosec >= 1000000000U) Fail("header.stamp.nanosec: expected less than 10^9");
    h.frame_id = String("header.frame_id");
    return h;
  }
  Eigen::Vector3d Vector(const char* field) {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = Finite(Get<double>(field), field);
    return v;
  }
  Eigen::Isometry3d Pose(const char* field) {
    const Eigen::Vector3d t = Vector(field);
    double q[4];
    for (double& c : q) c = Finite(Get<double>(field), field);
    const Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
    if (std::abs(rotation.norm() - 1.0) > 1e-3)
      Fail(std::string(field) + ": a quaternion of norm " + std::to_string(rotation.norm()) +
           "; expected 1");
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = rotation.normalized().toRotationMatrix();
    pose.translation() = t;
    return pose;
  }
  double Finite(double v, const char* field) const {
    if (!std::isfinite(v)) Fail(std::string(field) + ": expected a finite number");
    return v;
  }
  [[noreturn]] void Fail(const std::string& what) const { throw InputError(where_ + what); }

 private:
  void Align(std::size_t n) {
    while ((at_ - 4) % n != 0) ++at_;
  }
  void Need(std::size_t n, const char* field) const {
    if (at_ > in_.size() || n > in_.size() - at_) {
      Fail(std::string(field) + ": the message ends before it (truncated?)");
    }
  }
  std::string_view in_;
  std::size_t at_ = 4;
  const std::string& where_;
};

const std::map<std::string, std::string>& Definitions() {
  static const std::map<std::string, std::string> d = {
      {"std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n"},
      {"builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"},
      {"geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Quaternion", "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"},
      {"geometry_msgs/Pose",
       "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n"},
      {"geometry_msgs/Transform",
       "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n"},
      {"geometry_msgs/TransformStamped",
       "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n"},
      {"marine_acoustic_msgs/PingInfo",
       "float32 frequency\nfloat32 sound_speed\nfloat32[] tx_beamwidths\n"
       "float32[] rx_beamwidths\n"},
      {"marine_acoustic_msgs/SonarImageData",
       "bool is_bigendian\nuint32 DTYPE_UINT8=0\nuint32 DTYPE_INT8=1\nuint32 DTYPE_UINT16=2\n"
       "uint32 DTYPE_INT16=3\nuint32 DTYPE_UINT32=4\nuint32 DTYPE_INT32=5\n"
       "uint32 DTYPE_UINT64=6\nuint32 DTYPE_INT64=7\nuint32 DTYPE_FLOAT32=8\n"
       "uint32 DTYPE_FLOAT64=9\nuint32 dtype\nuint32 beam_count\nuint8[] data\n"},
      {kProjectedSonarImage,
       "std_msgs/Header header\nmarine_acoustic_msgs/PingInfo ping_info\n"
       "geometry_msgs/Vector3[] beam_directions\nfloat32[] ranges\n"
       "marine_acoustic_msgs/SonarImageData image\n"},
      {kTfMessage, "geometry_msgs/TransformStamped[] transforms\n"},
      {kPoseStamped, "std_msgs/Header header\ngeometry_msgs/Pose pose\n"},
      {"sensor_msgs/PointField",
       "uint8 INT8 = 1\nuint8 UINT8 = 2\nuint8 INT16 = 3\nuint8 UINT16 = 4\nuint8 INT32 = 5\n"
       "uint8 UINT32 = 6\nuint8 FLOAT32 = 7\nuint8 FLOAT64 = 8\nstring name\nuint32 offset\n"
       "uint8 datatype\nuint32 count\n"},
      {kPointCloud2,
       "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n"
       "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n"},
  };
  return d;
}

}  // namespace

std::string Definition(const std::string& type) {
  static const std::map<std::string, std::vector<std::string>> dependencies = {
      {kProjectedSonarImage,
       {"std_msgs/Header", "builtin_interfaces/Time", "marine_acoustic_msgs/PingInfo",
        "geometry_msgs/Vector3", "marine_acoustic_msgs/SonarImageData"}},
      {kTfMessage,
       {"geometry_msgs/TransformStamped", "std_msgs/Header", "builtin_interfaces/Time",
        "geometry_msgs/Transform", "geometry_msgs/Vector3", "geometry_msgs/Quaternion"}},
      {kPoseStamped,
       {"std_msgs/Header", "builtin_interfaces/Time", "geometry_msgs/Pose", "geometry_msgs/Point",
        "geometry_msgs/Quaternion"}},
      {kPointCloud2, {"std_msgs/Header", "builtin_interfaces/Time", "sensor_msgs/PointField"}},
  };
  std::string text = Definitions().at(type);
  for (const std::string& dep : dependencies.at(type)) {
    text += std::string(80, '=') + "\nMSG: " + dep + "\n" + Definitions().at(dep);
  }
  return text;
}

std::string Encode(const ProjectedSonarImage& m) {
  CdrWriter w;
  w.Header(m.header);
  w.Put(m.frequency);
  w.Put(m.sound_speed);
  w.Sequence(m.tx_beamwidths);
  w.Sequence(m.rx_beamwidths);
  w.Put<std::uint32_t>(static_cast<std::uint32_t>(m.beam_directions.size()));
  for (const Eigen::Vector3d& d : m.beam_directions) w.Vector(d);
  w.Sequence(m.ranges);
  w.Put<std::uint8_t>(m.is_bigendian ? 1 : 0);
  w.Put(m.dtype);
  w.Put(m.beam_count);
  w.Sequence(m.data);
  return w.Bytes();
}

std::string Encode(const PointCloud2& m) {
  CdrWriter w;
  w.Header(m.header);
  w.Put(m.height);
  w.Put(m.width);
  w.Put<std::uint32_t>(static_cast<std::uint32_t>(m.fields.size()));
  for (const PointField& f : m.fields) {
    w.String(f.name);
    w.Put(f.offset);
    w.Put(f.datatype);
    w.Put(f.count);
  }
  w.Put<std::uint8_t>(0);  // is_bigendian
  w.Put(m.point_step);
  w.Put<std::uint32_t>(m.point_step * m.width);  // row_step
  w.Sequence(m.data);
  w.Put<std::uint8_t>(1);  // is_dense: every point finite
  return w.Bytes();
}

std::string EncodeTfMessage(const std::vector<TransformStamped>& transforms) {
  CdrWriter w;
  w.Put<std::uint32_t>(static_cast<std::uint32_t>(transforms.size()));
  for (const TransformStamped& t : transforms) {
    w.Header(t.header);
    w.String(t.child_frame_id);
    w.Pose(t.transform);
  }
  return w.Bytes();
}

std::string EncodePoseStamped(const Header& header, const Eigen::Isometry3d& pose) {
  CdrWriter w;
  w.Header(header);
  w.Pose(pose);
  return w.Bytes();
}

ProjectedSonarImage DecodeProjectedSonarImage(std::string_view cdr, const std::string& where) {
  CdrReader r(cdr, where);
  ProjectedSonarImage m;
  m.header = r.Header();
  m.frequency = r.Get<float>("ping_info.frequency");
  m.sound_speed = r.Get<float>("ping_info.sound_speed");
  m.tx_beamwidths = r.Sequence<float>("ping_info.tx_beamwidths");
  m.rx_beamwidths = r.Sequence<float>("ping_info.rx_beamwidths");
  m.beam_directions.resize(r.Count(24, "beam_directions"));
  for (Eigen::Vector3d& d : m.beam_directions) d = r.Vector("beam_directions");
  m.ranges = r.Sequence<float>("ranges");
  m.is_bigendian = r.Get<std::uint8_t>("image.is_bigendian") != 0;
  m.dtype = r.Get<std::uint32_t>("image.dtype");
  m.beam_count = r.Get<std::uint32_t>("image.beam_count");
  m.data = r.Sequence<std::uint8_t>("image.data");
  return m;
}

std::vector<TransformStamped> DecodeTfMessage(std::string_view cdr, const std::string& where) {
  CdrReader r(cdr, where);
  std::vector<TransformStamped> transforms(r.Count(72, "transforms"));
  for (TransformStamped& t : transforms) {
    t.header = r.Header();
    t.child_frame_id = r.String("child_frame_id");
    t.transform = r.Pose("transform");
  }
  return transforms;
}

}  // namespace sonarbench::io::ros2
