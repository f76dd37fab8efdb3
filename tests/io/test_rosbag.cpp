#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "ros2_messages.hpp"
#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/mcap.hpp"
#include "sonarbench/io/rosbag.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

using mapping::Beam;

// A vehicle moving along x and turning, the sonar mounted ahead of it and pitched down, with
// beams of three lengths (the last one truncated) at head angles all around.
io::RosbagContent MovingBag() {
  io::RosbagContent bag;
  bag.T_vehicle_sonar = mapping::PoseFromXyzRpy({0.4, 0.0, -0.2}, {0.0, 0.3, 0.0});
  for (int b = 0; b < 30; ++b) {
    Beam beam;
    beam.time_s = 3.0 + b / 23.5;
    beam.head_angle_rad = std::fmod(b * 0.7, 2 * std::numbers::pi);
    beam.bin_size_m = bag.sensor.bin_size_m;
    beam.intensities.resize(b == 29 ? 120 : 399);
    for (std::size_t k = 0; k < beam.intensities.size(); ++k) {
      beam.intensities[k] = static_cast<std::uint8_t>((k * 7 + b * 13) % 256);
    }
    const Eigen::Isometry3d vehicle =
        mapping::PoseFromXyzRpy({0.1 * b, 0.02 * b, 1.0}, {0.0, 0.0, 0.05 * b});
    beam.T_world_sonar = vehicle * bag.T_vehicle_sonar;
    bag.true_vehicle.push_back(vehicle);
    bag.beams.push_back(beam);
  }
  return bag;
}

std::string Written(const io::RosbagContent& bag, const test::TempDir& dir,
                    const std::string& name = "bag.mcap") {
  std::ostringstream out;
  io::WriteRosbag(out, bag, "sonarbench test");
  return test::WriteFile(dir, name, out.str());
}

// Each beam read back as written: intensities and bin size exactly, the head angle's direction
// exactly, the time to the nanosecond a ROS stamp holds, the pose to rounding.
TEST(Rosbag, ReadsBackWhatItWrote) {
  const test::TempDir dir;
  const io::RosbagContent bag = MovingBag();
  const io::RosbagBeams read = io::ReadRosbag(Written(bag, dir), {});
  ASSERT_EQ(read.beams.size(), bag.beams.size());
  EXPECT_EQ(read.topic, io::kSonarTopic);
  EXPECT_EQ(read.sonar_frame, "sonar");
  EXPECT_EQ(read.world_frame, "map");
  EXPECT_EQ(read.truncated_beams, 1U);
  EXPECT_EQ(read.beams_outside_tf, 0U);
  for (std::size_t b = 0; b < bag.beams.size(); ++b) {
    const Beam& a = bag.beams[b];
    const Beam& r = read.beams[b];
    EXPECT_EQ(r.intensities, a.intensities);
    EXPECT_EQ(r.bin_size_m, a.bin_size_m);
    EXPECT_EQ(std::cos(r.head_angle_rad), std::cos(a.head_angle_rad));
    EXPECT_EQ(std::sin(r.head_angle_rad), std::sin(a.head_angle_rad));
    EXPECT_NEAR(r.head_angle_rad, a.head_angle_rad, 1e-15);
    EXPECT_NEAR(r.time_s, a.time_s, 0.5e-9);
    EXPECT_TRUE(r.T_world_sonar.isApprox(a.T_world_sonar, 1e-12)) << "beam " << b;
  }
}

TEST(Rosbag, ABinSizeTheRangesCarryAsFloat32ReadsBackExactly) {
  const test::TempDir dir;
  io::RosbagContent bag = MovingBag();
  for (Beam& beam : bag.beams) beam.bin_size_m = static_cast<float>(0.0125313);
  const io::RosbagBeams read = io::ReadRosbag(Written(bag, dir), {});
  EXPECT_EQ(read.beams[0].bin_size_m, bag.beams[0].bin_size_m);
}

// The sonar's channel (1, schema 1) and a transforms' channel (2, schema 2) on `tf_topic`.
void AddSonarAndTf(io::McapWriter& w, const std::string& tf_topic) {
  w.Add(io::McapSchema{1, io::ros2::kProjectedSonarImage, "ros2msg",
                       io::ros2::Definition(io::ros2::kProjectedSonarImage)});
  w.Add(io::McapSchema{2, io::ros2::kTfMessage, "ros2msg",
                       io::ros2::Definition(io::ros2::kTfMessage)});
  w.Add(io::McapChannel{1, 1, "/sonar", "cdr", {}});
  w.Add(io::McapChannel{2, 2, tf_topic, "cdr", {}});
}

// A beam of one bin (intensity 7) at `sec` in frame "head", looking along its x axis.
io::ros2::ProjectedSonarImage OneBinImage(std::int32_t sec, double bin_size_m) {
  io::ros2::ProjectedSonarImage image;
  image.header = {sec, 0, "head"};
  image.beam_directions = {{1, 0, 0}};
  image.ranges = {static_cast<float>(0.5 * bin_size_m)};
  image.beam_count = 1;
  image.data = {7};
  return image;
}

// A beam between two transforms gets the interpolated pose: a third of the way in time, a third
// of the way along the path and the turn; beams outside the transforms' span are left out and
// counted.
TEST(Rosbag, InterpolatesTransformsAndLeavesOutBeamsTheyDoNotCover) {
  const test::TempDir dir;
  io::RosbagContent bag = MovingBag();
  std::ostringstream out;
  {
    io::McapWriter w(out, "ros2", "test");
    AddSonarAndTf(w, "/tf");
    const auto tf = [&](std::int32_t sec, double x, double yaw) {
      io::ros2::TransformStamped t;
      t.header.sec = sec;
      t.header.frame_id = "odom";
      t.child_frame_id = "head";
      t.transform = mapping::PoseFromXyzRpy({x, 0, 0}, {0, 0, yaw});
      w.Write({2, 0, 0, 0, io::ros2::EncodeTfMessage({t})});
    };
    tf(10, 1.0, 0.0);
    tf(13, 4.0, 0.6);
    for (const std::int32_t sec : {9, 11, 14}) {
      w.Write({1, 0, 0, 0, io::ros2::Encode(OneBinImage(sec, bag.sensor.bin_size_m))});
    }
    w.Finish();
  }
  const io::RosbagBeams read = io::ReadRosbag(test::WriteFile(dir, "tf.mcap", out.str()), {});
  ASSERT_EQ(read.beams.size(), 1U);
  EXPECT_EQ(read.beams_outside_tf, 2U);
  EXPECT_EQ(read.world_frame, "odom");
  EXPECT_EQ(read.sonar_frame, "head");
  const Eigen::Isometry3d expected = mapping::PoseFromXyzRpy({2.0, 0, 0}, {0, 0, 0.2});
  EXPECT_TRUE(read.beams[0].T_world_sonar.isApprox(expected, 1e-12));
}

// Transforms that make a loop (head's parent a, a's parent head) are refused naming the bag.
TEST(Rosbag, ATransformLoopIsRefusedNamingTheBag) {
  const test::TempDir dir;
  std::ostringstream out;
  {
    io::McapWriter w(out, "ros2", "test");
    AddSonarAndTf(w, "/tf_static");
    std::vector<io::ros2::TransformStamped> links(2);
    links[0].header.frame_id = "a";
    links[0].child_frame_id = "head";
    links[1].header.frame_id = "head";
    links[1].child_frame_id = "a";
    w.Write({2, 0, 0, 0, io::ros2::EncodeTfMessage(links)});
    w.Write({1, 0, 0, 0, io::ros2::Encode(OneBinImage(10, mapping::SensorGeometry{}.bin_size_m))});
    w.Finish();
  }
  const std::string path = test::WriteFile(dir, "loop.mcap", out.str());
  const std::string error = test::InputErrorOf([&] { (void)io::ReadRosbag(path, {}); });
  EXPECT_EQ(error.rfind(path + ": the transforms from ", 0), 0U) << error;
  EXPECT_NE(error.find("form a loop"), std::string::npos) << error;
}

// One bag a case: an image message that breaks one rule of what a sonar beam is.
TEST(Rosbag, RefusesImagesThatAreNotOneMechanicalScanningBeam) {
  const test::TempDir dir;
  const auto bag_of = [&](const io::ros2::ProjectedSonarImage& image) {
    std::ostringstream out;
    io::McapWriter w(out, "ros2", "test");
    w.Add(io::McapSchema{1, io::ros2::kProjectedSonarImage, "ros2msg", "x"});
    w.Add(io::McapChannel{1, 1, "/sonar", "cdr", {}});
    w.Write({1, 0, 0, 0, io::ros2::Encode(image)});
    w.Finish();
    return test::WriteFile(dir, "case.mcap", out.str());
  };
  io::ros2::ProjectedSonarImage good;
  good.header = {1, 0, "sonar"};
  good.beam_directions = {{0, 1, 0}};
  const double bin = mapping::SensorGeometry{}.bin_size_m;
  good.ranges = {static_cast<float>(0.5 * bin), static_cast<float>(1.5 * bin)};
  good.beam_count = 1;
  good.data = {1, 2};
  io::RosbagReadOptions options;
  options.static_sonar = true;
  const io::RosbagBeams read = io::ReadRosbag(bag_of(good), options);
  ASSERT_EQ(read.beams.size(), 1U);
  EXPECT_EQ(read.beams[0].head_angle_rad, std::numbers::pi / 2);
  EXPECT_TRUE(read.beams[0].T_world_sonar.isApprox(Eigen::Isometry3d::Identity()));

  const auto refused = [&](io::ros2::ProjectedSonarImage image, const std::string& part,
                           const io::RosbagReadOptions& with) {
    EXPECT_TRUE(test::ThrowsInputErrorWith([&] { (void)io::ReadRosbag(bag_of(image), with); },
                                           {"case.mcap", "/sonar", part}))
        << part;
  };
  auto image = good;
  image.beam_directions.push_back({1, 0, 0});
  image.beam_count = 2;
  refused(image, "one beam a message", options);
  image = good;
  image.dtype = 2;
  refused(image, "DTYPE_UINT8", options);
  image = good;
  image.data.pop_back();
  refused(image, "one byte a range", options);
  image = good;
  image.beam_directions = {{1, 0, 0.5}};
  refused(image, "x-y plane", options);
  image = good;
  image.ranges = {0.2F, 0.3F};
  refused(image, "centres of equal bins", options);
  image = good;
  image.rx_beamwidths = {0.2F};
  refused(image, "rx_beamwidths", options);
  image = good;
  image.header.frame_id = "son\xC3(ar";  // a manifest could not hold it
  refused(image, "header.frame_id: 'son\\xc3(ar' is not UTF-8", options);
  // A sequence count that says more bytes than the message holds.
  const std::string cdr = io::ros2::Encode(good);
  EXPECT_TRUE(test::ThrowsInputErrorWith(
      [&] { (void)io::ros2::DecodeProjectedSonarImage(cdr.substr(0, cdr.size() - 1), "m: "); },
      {"m: ", "image.data", "do not fit"}));
  EXPECT_TRUE(
      test::ThrowsInputErrorWith([&] { (void)io::ReadRosbag(bag_of(good), {}); },
                                 {"no /tf or /tf_static transform", "'sonar'", "--static"}));
}

TEST(Rosbag, ASecondSonarTopicMustBeNamed) {
  const test::TempDir dir;
  std::ostringstream out;
  io::McapWriter w(out, "ros2", "test");
  w.Add(io::McapSchema{1, io::ros2::kProjectedSonarImage, "ros2msg", "x"});
  w.Add(io::McapChannel{1, 1, "/left", "cdr", {}});
  w.Add(io::McapChannel{2, 1, "/right", "cdr", {}});
  w.Finish();
  const std::string path = test::WriteFile(dir, "two.mcap", out.str());
  EXPECT_TRUE(test::ThrowsInputErrorWith([&] { (void)io::ReadRosbag(path, {}); },
                                         {"two.mcap", "/left /right", "--topic"}));
  io::RosbagReadOptions options;
  options.topic = "/right";
  EXPECT_TRUE(test::ThrowsInputErrorWith([&] { (void)io::ReadRosbag(path, options); },
                                         {"two.mcap", "no message on /right"}));
}

}  // namespace
}  // namespace sonarbench
