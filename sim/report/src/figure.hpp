#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

// What turns a raster (a sweep, a fan, a map view) into a figure a person reads on its own: a
// title, axes with units and round ticks, a scale bar, a colour bar or a legend.
namespace sonarbench::sim::figure {

/// One axis of a panel: the values at its two ends (the left and right edges of the panel, or
/// its bottom and top), its label with the unit, and, if not empty, its ticks (value, text) in
/// place of round ones.
struct Axis {
  double at_start = 0.0;
  double at_end = 1.0;
  std::string label;
  std::vector<std::pair<double, std::string>> ticks;
};

/// About `count` round values (1, 2 or 5 × 10^k apart) within [min(a, b), max(a, b)].
[[nodiscard]] std::vector<double> RoundTicks(double a, double b, int count);

/// `panel` framed: `title` above, `x` below and `y` on the left with ticks and labels, `side` (a
/// colour bar or a legend; may be empty) to the right. Every text lies inside the image.
[[nodiscard]] cv::Mat Framed(const cv::Mat& panel, const std::string& title, const Axis& x,
                             const Axis& y, const cv::Mat& side = {});

/// The intensity colour map (inferno) from 0 at the bottom to 255 at the top, `height` pixels,
/// with ticks and the label "intensity".
[[nodiscard]] cv::Mat IntensityBar(int height);

/// A swatch and a label per entry, one entry a line.
[[nodiscard]] cv::Mat Legend(const std::vector<std::pair<cv::Vec3b, std::string>>& entries);

/// Draws a bar of a round length (about a fifth of the panel's width) with its length in metres
/// in the panel's lower left corner; `metres_per_pixel` is the panel's scale.
void DrawScaleBar(cv::Mat& panel, double metres_per_pixel);
/// Adds below `side` (a legend) a scale bar for a map of `metres_per_pixel` (none when 0): the
/// largest 1, 2 or 5 × 10^k metres that fits its width.
void AppendScaleBar(cv::Mat& side, double metres_per_pixel);

}  // namespace sonarbench::sim::figure
