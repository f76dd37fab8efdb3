#pragma once

#include <opencv2/core.hpp>
#include <span>
#include <string>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/sim/score.hpp"

namespace sonarbench::sim {

/// Writes `image` as a PNG file, atomically.
void WritePng(const std::string& path, const cv::Mat& image);

/// Renders one sweep as a polar image: one row per beam (in time order), one column per range
/// bin (range grows to the right), intensity on a perceptual colour map.
[[nodiscard]] cv::Mat RenderPolarImage(std::span<const mapping::Beam> sweep);
/// RenderPolarImage, written as a PNG file atomically.
void WritePolarImage(const std::string& path, std::span<const mapping::Beam> sweep);

/// Renders one sweep as a top-down Cartesian fan: the sonar at the centre, x to the right, y up,
/// `pixel_m` per pixel; each pixel shows the bin at its range on the beam nearest its bearing.
[[nodiscard]] cv::Mat RenderFanImage(std::span<const mapping::Beam> sweep, double pixel_m);
/// RenderFanImage, written as a PNG file atomically.
void WriteFanImage(const std::string& path, std::span<const mapping::Beam> sweep, double pixel_m);

/// Writes a top-down view of the map against the truth, one pixel per cell column (x right,
/// y up): green where a column holds a true-positive cell, red where it holds only false
/// positives, blue where it holds observable truth the map missed, grey where only free cells.
/// With an empty `truth` (a real log), occupied columns are white.
void WriteTopDownImage(const std::string& path, const MapCells& map, const mapping::KeySet& truth,
                       const mapping::KeySet& observable);

}  // namespace sonarbench::sim
