#include "figure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace sonarbench::sim::figure {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kTextScale = 0.45;
constexpr int kTitleHeight = 46, kBottom = 52, kLeft = 78, kGap = 16;
const cv::Scalar kBlack(0, 0, 0), kWhite(255, 255, 255);

int TextWidth(const std::string& text, double scale) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, scale, 1, &baseline).width;
}

// Puts `text` with its left end at x, moved left as needed to stay inside `image`.
void Text(cv::Mat& image, const std::string& text, int x, int y, double scale = kTextScale,
          const cv::Scalar& colour = kBlack) {
  x = std::clamp(x, 2, std::max(2, image.cols - TextWidth(text, scale) - 2));
  cv::putText(image, text, {x, y}, kFont, scale, colour, 1, cv::LINE_AA);
}

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", std::abs(value) < 1e-12 ? 0.0 : value);
  return text;
}

// The axis's ticks: its own, or round ones.
std::vector<std::pair<double, std::string>> Ticks(const Axis& axis, int count) {
  if (!axis.ticks.empty()) return axis.ticks;
  std::vector<std::pair<double, std::string>> ticks;
  for (double t : RoundTicks(axis.at_start, axis.at_end, count)) ticks.emplace_back(t, Number(t));
  return ticks;
}

// Where `value` falls along an axis `pixels` long: 0 at its start, `pixels` at its end.
int Along(const Axis& axis, double value, int pixels) {
  const double span = axis.at_end - axis.at_start;
  if (span == 0.0) return 0;
  return static_cast<int>(std::lround((value - axis.at_start) / span * pixels));
}

}  // namespace

std::vector<double> RoundTicks(double a, double b, int count) {
  const double lo = std::min(a, b), hi = std::max(a, b);
  std::vector<double> ticks;
  if (!(hi > lo) || count < 1) return ticks;
  const double raw = (hi - lo) / count;
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  const double step = raw / decade < 1.5   ? decade
                      : raw / decade < 3.5 ? 2.0 * decade
                      : raw / decade < 7.5 ? 5.0 * decade
                                           : 10.0 * decade;
  for (double t = std::ceil(lo / step - 1e-9) * step; t <= hi + 1e-9 * step; t += step) {
    ticks.push_back(std::abs(t) < 1e-9 * step ? 0.0 : t);
  }
  return ticks;
}

cv::Mat Framed(const cv::Mat& panel, const std::string& title, const Axis& x, const Axis& y,
               const cv::Mat& side) {
  const int side_width = side.empty() ? 0 : side.cols + kGap;
  const int width = kLeft + panel.cols + kGap + side_width;
  const int height = kTitleHeight + std::max(panel.rows, side.empty() ? 0 : side.rows) + kBottom;
  cv::Mat image(height, width, CV_8UC3, kWhite);
  panel.copyTo(image(cv::Rect(kLeft, kTitleHeight, panel.cols, panel.rows)));
  if (!side.empty()) {
    side.copyTo(image(cv::Rect(kLeft + panel.cols + kGap, kTitleHeight, side.cols, side.rows)));
  }
  const int bottom = kTitleHeight + panel.rows;
  cv::rectangle(image, {kLeft - 1, kTitleHeight - 1}, {kLeft + panel.cols, bottom}, kBlack, 1);
  for (const auto& [value, text] : Ticks(x, std::max(2, panel.cols / 90))) {
    const int u = kLeft + Along(x, value, panel.cols);
    if (u < kLeft - 1 || u > kLeft + panel.cols) continue;
    cv::line(image, {u, bottom}, {u, bottom + 5}, kBlack, 1);
    Text(image, text, u - TextWidth(text, kTextScale) / 2, bottom + 19);
  }
  for (const auto& [value, text] : Ticks(y, std::max(2, panel.rows / 70))) {
    const int v = bottom - Along(y, value, panel.rows);
    if (v < kTitleHeight - 1 || v > bottom) continue;
    cv::line(image, {kLeft - 6, v}, {kLeft - 1, v}, kBlack, 1);
    Text(image, text, kLeft - 9 - TextWidth(text, kTextScale), v + 5);
  }
  Text(image, x.label, kLeft + (panel.cols - TextWidth(x.label, 0.5)) / 2, bottom + 42, 0.5);
  Text(image, title, kLeft, 18, 0.55);
  Text(image, y.label, 4, kTitleHeight - 8, kTextScale);
  return image;
}

cv::Mat IntensityBar(int height) {
  constexpr int kBarWidth = 18, kWidth = 64, kTop = 24;
  const int bar_height = std::max(64, std::min(height, 400) - kTop - 8);
  cv::Mat gray(bar_height, kBarWidth, CV_8UC1);
  for (int r = 0; r < bar_height; ++r) {
    gray.row(r).setTo(255 - r * 255 / std::max(1, bar_height - 1));
  }
  cv::Mat colour;
  cv::applyColorMap(gray, colour, cv::COLORMAP_INFERNO);
  cv::Mat image(kTop + bar_height + 8, kWidth, CV_8UC3, kWhite);
  colour.copyTo(image(cv::Rect(0, kTop, kBarWidth, bar_height)));
  cv::rectangle(image, {0, kTop}, {kBarWidth - 1, kTop + bar_height - 1}, kBlack, 1);
  for (int value : {0, 64, 128, 192, 255}) {
    const int v = kTop + (255 - value) * (bar_height - 1) / 255;
    cv::line(image, {kBarWidth, v}, {kBarWidth + 4, v}, kBlack, 1);
    Text(image, std::to_string(value), kBarWidth + 7, v + 5, 0.4);
  }
  Text(image, "intensity", 0, 14, 0.4);
  return image;
}

cv::Mat Legend(const std::vector<std::pair<cv::Vec3b, std::string>>& entries) {
  int width = 0;
  for (const auto& [colour, label] : entries) width = std::max(width, TextWidth(label, 0.42));
  cv::Mat image(static_cast<int>(entries.size()) * 22 + 4, width + 30, CV_8UC3, kWhite);
  int y = 4;
  for (const auto& [colour, label] : entries) {
    cv::rectangle(image, {0, y}, {15, y + 15}, cv::Scalar(colour[0], colour[1], colour[2]),
                  cv::FILLED);
    cv::rectangle(image, {0, y}, {15, y + 15}, kBlack, 1);
    Text(image, label, 22, y + 13, 0.42);
    y += 22;
  }
  return image;
}

void AppendScaleBar(cv::Mat& side, double metres_per_pixel) {
  if (!(metres_per_pixel > 0.0)) return;
  const int width = std::max(side.cols, 160);
  const double most = (width - 24) * metres_per_pixel;
  const double decade = std::pow(10.0, std::floor(std::log10(most)));
  const double length = most >= 5.0 * decade   ? 5.0 * decade
                        : most >= 2.0 * decade ? 2.0 * decade
                                               : decade;
  const int pixels = std::max(1, static_cast<int>(std::lround(length / metres_per_pixel)));
  cv::Mat grown(side.rows + 48, width, CV_8UC3, kWhite);
  if (!side.empty()) side.copyTo(grown(cv::Rect(0, 0, side.cols, side.rows)));
  const int y = side.rows + 36;
  cv::line(grown, {4, y}, {4 + pixels, y}, kBlack, 3);
  cv::line(grown, {4, y - 6}, {4, y + 4}, kBlack, 1);
  cv::line(grown, {4 + pixels, y - 6}, {4 + pixels, y + 4}, kBlack, 1);
  Text(grown, Number(length) + " m", 4, y - 10, 0.42);
  side = grown;
}

void DrawScaleBar(cv::Mat& panel, double metres_per_pixel) {
  if (!(metres_per_pixel > 0.0) || panel.cols < 40) return;
  // The largest 1, 2 or 5 × 10^k metres within a fifth of the panel.
  const double most = panel.cols * metres_per_pixel / 5.0;
  const double decade = std::pow(10.0, std::floor(std::log10(most)));
  const double length = most >= 5.0 * decade   ? 5.0 * decade
                        : most >= 2.0 * decade ? 2.0 * decade
                                               : decade;
  const int pixels = std::max(1, static_cast<int>(std::lround(length / metres_per_pixel)));
  const cv::Point start(12, panel.rows - 14);
  const cv::Point end(12 + pixels, panel.rows - 14);
  cv::rectangle(panel, start + cv::Point(-4, -20), end + cv::Point(4, 6), kBlack, cv::FILLED);
  cv::line(panel, start, end, kWhite, 3);
  Text(panel, Number(length) + " m", start.x, start.y - 6, 0.42, kWhite);
}

}  // namespace sonarbench::sim::figure
