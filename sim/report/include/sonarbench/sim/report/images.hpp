#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/sim/eval/score.hpp"

namespace sonarbench::sim {

/// `image` as PNG file bytes.
[[nodiscard]] std::vector<unsigned char> EncodePng(const cv::Mat& image);
/// Writes `image` as a PNG file, atomically.
void WritePng(const std::string& path, const cv::Mat& image);

/// Renders one sweep as a polar image: one row per beam (in time order, 2 pixels or more), one
/// column per range bin (2 pixels; range grows to the right), intensity on the inferno colour
/// map; framed with `title`, range [m] below, the head angle ticked where it passes a multiple
/// of 45 deg (a dashed line where it passes 0) and the intensity colour bar.
[[nodiscard]] cv::Mat RenderPolarImage(std::span<const mapping::Beam> sweep,
                                       const std::string& title);
/// RenderPolarImage, written as a PNG file atomically.
void WritePolarImage(const std::string& path, std::span<const mapping::Beam> sweep,
                     const std::string& title);

/// Renders one sweep as a top-down Cartesian fan: the sonar at the centre, x (head angle 0,
/// marked) to the right, y up, `pixel_m` per pixel (larger when the reach would need more than
/// 4097 pixels a side); each pixel shows the bin at its range on the
/// beam nearest its bearing. Framed with `title`, axes in metres, a scale bar and the colour bar.
[[nodiscard]] cv::Mat RenderFanImage(std::span<const mapping::Beam> sweep, double pixel_m,
                                     const std::string& title);
/// RenderFanImage, written as a PNG file atomically.
void WriteFanImage(const std::string& path, std::span<const mapping::Beam> sweep, double pixel_m,
                   const std::string& title);

/// Which cells a map image shows: every column seen from above (x right, y up), or a slab of
/// cells around one y key seen from the side (x right, z up).
struct MapView {
  enum class Kind { kTop, kSide };
  Kind kind = Kind::kTop;
  /// kSide: the slab holds the cells whose y key is within slab_half_cells of slab_key.
  std::uint16_t slab_key = 0;
  int slab_half_cells = 1;
  /// The cells' edge [m], for the axes and the scale bar (0: axes in cells).
  double resolution_m = 0.0;
  std::string title;
  /// The cells the sonar was in, in time order: a cross marks the first, dots the rest.
  std::vector<octomap::OcTreeKey> sonar;
};

/// Renders the map against the truth, whole pixels per cell with the longer side at least 800
/// pixels: green where a pixel's cells hold a true positive, magenta where a false positive is
/// one of `detector_ghosts` (and none is true), red where only other false positives, blue where
/// observable truth the map missed, grey where only free cells, black unknown. With an empty
/// `truth` (a real log), occupied cells are white; the sonar's cells in yellow. Framed with the
/// view's title, axes in metres, and beside the map a legend of the colours shown and a scale bar.
[[nodiscard]] cv::Mat RenderMapView(const MapCells& map, const mapping::KeySet& truth,
                                    const mapping::KeySet& observable, const MapView& view,
                                    const mapping::KeySet& detector_ghosts = {});

/// One line of a plot: its legend name, colour (BGR), points and, optionally, a short label
/// beside each point (a threshold, a rule).
struct PlotSeries {
  std::string name;
  cv::Scalar colour;
  std::vector<double> x;
  std::vector<double> y;
  std::vector<std::string> labels = {};
};
/// Renders a plot with axes, ticks at the x values of the series (log2 scale when `log2_x`; over
/// 16 x values on a linear scale, or when `x_range` sets a continuous axis, about ten round
/// ticks), a marker at each point of a series of up to 64 (with its label), joined by a line only
/// when its x values increase, five y ticks from `y_min` to the data's maximum (or `y_max` when it
/// is set), a title (made smaller until it fits), axis labels and the legend below the axes,
/// where it covers no data.
[[nodiscard]] cv::Mat RenderLinePlot(
    const std::string& title, const std::string& x_label, const std::string& y_label,
    const std::vector<PlotSeries>& series, bool log2_x, double y_min,
    std::optional<double> y_max = std::nullopt,
    std::optional<std::pair<double, double>> x_range = std::nullopt);

}  // namespace sonarbench::sim
