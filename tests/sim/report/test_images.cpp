#include <gtest/gtest.h>
#include <omp.h>

#include <numbers>
#include <opencv2/core.hpp>
#include <vector>

#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/report/images.hpp"

namespace sonarbench::sim {
namespace {

// A sweep of 200 beams, 1.8 deg apart, of 120 bins of 2 cm whose intensities vary with both.
std::vector<mapping::Beam> Sweep() {
  std::vector<mapping::Beam> sweep(200);
  for (std::size_t b = 0; b < sweep.size(); ++b) {
    sweep[b].head_angle_rad = static_cast<double>(b) * 1.8 * std::numbers::pi / 180.0;
    sweep[b].bin_size_m = 0.02;
    for (std::size_t k = 0; k < 120; ++k)
      sweep[b].intensities.push_back(static_cast<std::uint8_t>((7 * k + 13 * b) % 256));
  }
  return sweep;
}

TEST(RenderFanImage, TheSameImageOnOneThreadAsOnTwo) {
  const std::vector<mapping::Beam> sweep = Sweep();
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const cv::Mat one = RenderFanImage(sweep, 0.01, "fan");
  omp_set_num_threads(2);
  const cv::Mat two = RenderFanImage(sweep, 0.01, "fan");
  omp_set_num_threads(threads);
  ASSERT_EQ(one.size(), two.size());
  ASSERT_EQ(one.type(), two.type());
  EXPECT_EQ(cv::norm(one, two, cv::NORM_INF), 0.0);
  // Not blank: the fan spans 2.4 m at 1 cm a pixel, and its colours vary.
  EXPECT_GT(one.rows, 480);
  cv::Scalar mean, spread;
  cv::meanStdDev(one, mean, spread);
  EXPECT_GT(spread[0] + spread[1] + spread[2], 10.0);
}

// A beam's head angle is a direction: given in [0, 2π), in [-π, π), or a turn or two on, the
// same sweep draws the same fan (the nearest beam found by the angle between, wrapped).
TEST(RenderFanImage, TheSameImageWhicheverTurnTheHeadAnglesAreGivenIn) {
  const std::vector<mapping::Beam> sweep = Sweep();
  const cv::Mat reference = RenderFanImage(sweep, 0.01, "fan");
  for (const double turns : {-1.0, 1.0, 2.0, 3.0}) {
    std::vector<mapping::Beam> turned = sweep;
    for (mapping::Beam& beam : turned) {
      // [-π, π) for turns = -1: only the upper half is moved.
      if (turns >= 0.0 || beam.head_angle_rad >= std::numbers::pi)
        beam.head_angle_rad += turns * 2.0 * std::numbers::pi;
    }
    const cv::Mat image = RenderFanImage(turned, 0.01, "fan");
    ASSERT_EQ(image.size(), reference.size());
    EXPECT_EQ(cv::norm(image, reference, cv::NORM_INF), 0.0) << turns << " turns";
  }
}

// Beams heard at one head angle (a head that paused) are one direction: the fan shows the
// earliest of them, as a scan of the sweep in order would pick it.
TEST(RenderFanImage, BeamsAtOneAngleShowTheEarliest) {
  std::vector<mapping::Beam> paused, single;
  for (int b = 0; b < 100; ++b) {
    mapping::Beam beam;
    beam.head_angle_rad = b * 3.6 * std::numbers::pi / 180.0;
    beam.bin_size_m = 0.02;
    beam.intensities.assign(60, 200);
    single.push_back(beam);
    paused.push_back(beam);
    beam.intensities.assign(60, 50);  // heard later at the same angle
    paused.push_back(beam);
  }
  const cv::Mat expected = RenderFanImage(single, 0.01, "fan");
  const cv::Mat fan = RenderFanImage(paused, 0.01, "fan");
  ASSERT_EQ(fan.size(), expected.size());
  EXPECT_EQ(cv::norm(fan, expected, cv::NORM_INF), 0.0);
}

// Pixels of one colour (BGR) in an image.
int CountColour(const cv::Mat& image, const cv::Vec3b& colour) {
  int count = 0;
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) count += image.at<cv::Vec3b>(r, c) == colour ? 1 : 0;
  }
  return count;
}

// Three occupied columns from above: one on the truth (green), two off it (red); given as the
// detector's ghosts, the second is drawn magenta instead, the first and the third unchanged.
TEST(RenderMapView, TheDetectorsGhostsAreDrawnApartFromTheOtherFalsePositives) {
  const auto key = [](int x) {
    return octomap::OcTreeKey(static_cast<octomap::key_type>(32768 + x), 32768, 32768);
  };
  MapCells map;
  for (int x : {0, 10, 20}) map.occupied.insert(key(x));
  mapping::KeySet truth;
  truth.insert(key(0));
  MapView top;
  top.resolution_m = 0.05;
  top.title = "test";
  mapping::KeySet ghosts;
  ghosts.insert(key(20));
  const cv::Vec3b red(0, 0, 230);
  const cv::Vec3b magenta(230, 0, 230);
  const cv::Vec3b green(0, 210, 0);
  const cv::Mat plain = RenderMapView(map, truth, truth, top);
  const cv::Mat split = RenderMapView(map, truth, truth, top, ghosts);
  EXPECT_EQ(CountColour(plain, magenta), 0);
  EXPECT_GT(CountColour(split, magenta), 0);
  // One cell's square of pixels moves from red to magenta (the legend adds a swatch of each).
  const int cell = CountColour(plain, red) - CountColour(split, red);
  EXPECT_GT(cell, 0);
  EXPECT_EQ(CountColour(split, magenta) - cell, CountColour(split, red) - cell);
  EXPECT_EQ(CountColour(split, green), CountColour(plain, green));
}

// The sonar is marked where it was (a cross, yellow, listed in the legend); the scale bar goes
// beside the map with the legend: the map's own pixels stay the cells' colours.
TEST(RenderMapView, TheSonarIsMarkedAndTheScaleBarCoversNoCell) {
  const auto key = [](int x, int y) {
    return octomap::OcTreeKey(static_cast<octomap::key_type>(32768 + x),
                              static_cast<octomap::key_type>(32768 + y), 32768);
  };
  MapCells map;
  // A map filling its whole frame: every cell occupied, 40 x 40.
  for (int x = 0; x < 40; ++x) {
    for (int y = 0; y < 40; ++y) map.occupied.insert(key(x, y));
  }
  MapView top;
  top.resolution_m = 0.05;
  top.title = "test";
  const cv::Mat bare = RenderMapView(map, {}, {}, top);
  const cv::Vec3b white(255, 255, 255), yellow(0, 220, 255);
  EXPECT_EQ(CountColour(bare, yellow), 0);
  top.sonar.push_back(key(20, 20));
  const cv::Mat marked = RenderMapView(map, {}, {}, top);
  EXPECT_GT(CountColour(marked, yellow), 16);  // the cross and the legend's swatch
  // The map is 800 pixels square at 20 per cell: every pixel but the cross's stays white
  // (occupied), none black (a scale bar's) inside it.
  int black = 0;
  for (int r = 0; r < 800; ++r) {
    for (int c = 0; c < 800; ++c) {
      black += bare.at<cv::Vec3b>(46 + r, 78 + c) == cv::Vec3b(0, 0, 0);  // figure's frame
    }
  }
  EXPECT_EQ(black, 0);
  EXPECT_GT(CountColour(bare, white), 800 * 800 - 1);
}

// The legend lies below the axes (a row a series), so it covers no point; a point's label is
// drawn beside it in the series' colour.
TEST(RenderLinePlot, TheLegendIsBelowTheAxesAndPointsCarryTheirLabels) {
  const PlotSeries a{"a", {200, 80, 0}, {0.1, 0.9}, {0.9, 0.9}};
  PlotSeries b{"b", {30, 30, 220}, {0.5}, {0.5}};
  const cv::Mat one = RenderLinePlot("t", "x", "y", {a}, false, 0.0, 1.0, std::pair{0.0, 1.0});
  const cv::Mat two = RenderLinePlot("t", "x", "y", {a, b}, false, 0.0, 1.0, std::pair{0.0, 1.0});
  EXPECT_EQ(two.rows - one.rows, 18);
  const auto inked = [](const cv::Mat& image) {
    return image.rows * image.cols - CountColour(image, cv::Vec3b(255, 255, 255));
  };
  b.labels = {"110"};
  const cv::Mat labelled =
      RenderLinePlot("t", "x", "y", {a, b}, false, 0.0, 1.0, std::pair{0.0, 1.0});
  EXPECT_GT(inked(labelled), inked(two) + 20);
}

}  // namespace
}  // namespace sonarbench::sim
