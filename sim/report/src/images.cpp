#include "sonarbench/sim/report/images.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "figure.hpp"
#include "sonarbench/base/atomic_file.hpp"

namespace sonarbench::sim {
void WritePng(const std::string& path, const cv::Mat& image) {
  const std::vector<uchar> bytes = EncodePng(image);
  WriteFileAtomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  });
}

cv::Mat RenderPolarImage(std::span<const mapping::Beam> sweep, const std::string& title) {
  std::size_t bins = 0;
  for (const auto& beam : sweep) bins = std::max(bins, beam.intensities.size());
  const int rows = std::max<int>(1, static_cast<int>(sweep.size()));
  cv::Mat gray(rows, std::max<int>(1, static_cast<int>(bins)), CV_8UC1, cv::Scalar(0));
  for (std::size_t r = 0; r < sweep.size(); ++r) {
    std::copy(sweep[r].intensities.begin(), sweep[r].intensities.end(),
              gray.ptr<uchar>(static_cast<int>(r)));
  }
  cv::Mat colour;
  cv::applyColorMap(gray, colour, cv::COLORMAP_INFERNO);
  const int scale_y = std::max(2, 200 / rows);
  cv::resize(colour, colour, cv::Size(), 2.0, scale_y, cv::INTER_NEAREST);
  // Rows in time order; a tick where the head angle passes a multiple of 45 deg, a line at 0.
  figure::Axis y{static_cast<double>(rows), 0.0, "head angle [deg], beams in time order", {}};
  auto degrees = [&](std::size_t r) {
    const double deg = std::fmod(sweep[r].head_angle_rad / mapping::kDegToRad, 360.0);
    return deg < 0.0 ? deg + 360.0 : deg;
  };
  for (std::size_t r = 0; r < sweep.size(); ++r) {
    const double deg = degrees(r);
    const double before = r == 0 ? deg - 1e-9 : degrees(r - 1);
    const bool wrapped = deg < before;
    const int crossed = static_cast<int>(std::floor(deg / 45.0));
    if (!wrapped && crossed == static_cast<int>(std::floor(before / 45.0))) continue;
    const int label = wrapped ? 0 : crossed * 45;
    y.ticks.emplace_back(static_cast<double>(r), std::to_string(label));
    if (label != 0) continue;
    const int v = static_cast<int>(r) * scale_y;
    for (int u = 0; u < colour.cols; u += 12) {
      cv::line(colour, {u, v}, {std::min(u + 6, colour.cols - 1), v}, cv::Scalar(255, 255, 255), 1);
    }
  }
  const double bin_size = sweep.empty() ? 0.0 : sweep.front().bin_size_m;
  const figure::Axis x{0.0, bin_size * static_cast<double>(bins), "range [m]", {}};
  return figure::Framed(colour, title, x, y, figure::IntensityBar(colour.rows));
}

void WritePolarImage(const std::string& path, std::span<const mapping::Beam> sweep,
                     const std::string& title) {
  WritePng(path, RenderPolarImage(sweep, title));
}

namespace {

// The fan with metric axes in the sonar frame, head angle 0 (+x) marked, a scale bar and the
// intensity colour bar.
cv::Mat FramedFan(cv::Mat colour, int half, double pixel_m, const std::string& title) {
  const cv::Scalar white(255, 255, 255);
  const cv::Point centre(half, half);
  cv::line(colour, centre, {colour.cols - 1, half}, white, 1, cv::LINE_AA);
  cv::putText(colour, "head angle 0", {std::max(0, colour.cols - 120), half - 6},
              cv::FONT_HERSHEY_SIMPLEX, 0.45, white, 1, cv::LINE_AA);
  figure::DrawScaleBar(colour, pixel_m);
  const double extent = (half + 0.5) * pixel_m;
  return figure::Framed(colour, title, {-extent, extent, "x [m], sonar frame", {}},
                        {-extent, extent, "y [m]", {}}, figure::IntensityBar(colour.rows));
}

}  // namespace

namespace {

// A sweep's beams by head angle in [0, 2π): the beam nearest a bearing is in the group of equal
// angles just below it or just above it (circularly); among those the smallest angular distance
// wins, then the earliest beam, as a scan in sweep order would choose.
class BeamsByAngle {
 public:
  explicit BeamsByAngle(std::span<const mapping::Beam> sweep) : sweep_(sweep) {
    std::vector<std::pair<double, std::size_t>> by_angle;
    for (std::size_t i = 0; i < sweep.size(); ++i)
      by_angle.emplace_back(Wrapped(sweep[i].head_angle_rad), i);
    std::sort(by_angle.begin(), by_angle.end());
    for (const auto& [angle, i] : by_angle) {
      angles_.push_back(angle);
      beams_.push_back(i);
    }
    // Equal angles lie side by side: each position's group of them.
    group_.resize(angles_.size());
    for (std::size_t k = 0, first = 0; k < angles_.size(); ++k) {
      if (angles_[k] != angles_[first]) first = k;
      group_[k].first = first;
    }
    for (std::size_t k = angles_.size(), end = k; k-- > 0;) {
      if (angles_[k] != angles_[end - 1]) end = k + 1;
      group_[k].second = end;
    }
  }

  // The beam nearest `bearing` [rad]; the sweep must not be empty.
  const mapping::Beam& Nearest(double bearing) const {
    const std::size_t n = angles_.size();
    const auto first_above = std::lower_bound(angles_.begin(), angles_.end(), Wrapped(bearing));
    std::size_t above = static_cast<std::size_t>(first_above - angles_.begin());
    if (above == n) above = 0;
    const std::size_t below = (above == 0 ? n : above) - 1;
    std::size_t best = sweep_.size();
    double best_distance = 0.0;
    for (const std::size_t start : {below, above}) {
      for (std::size_t k = group_[start].first; k < group_[start].second; ++k) {
        const std::size_t i = beams_[k];
        const double d = AngleBetween(sweep_[i].head_angle_rad, bearing);
        if (best == sweep_.size() || d < best_distance || (d == best_distance && i < best)) {
          best = i;
          best_distance = d;
        }
      }
    }
    return sweep_[best];
  }

 private:
  static constexpr double kTwoPi = 2.0 * std::numbers::pi;
  static double Wrapped(double angle) { return angle - kTwoPi * std::floor(angle / kTwoPi); }
  // |remainder(a - b, 2π)|, exact as remainder is, without its call for differences within
  // ±3π: d <= π is its own remainder, and d - 2π is exact for d <= 4π (Sterbenz); the ties at
  // ±π round to the even quotient, which gives the same magnitude.
  static double AngleBetween(double a, double b) {
    const double d = std::abs(a - b);
    if (d <= 0.5 * kTwoPi) return d;
    const double r = std::abs(d - kTwoPi);
    return r <= 0.5 * kTwoPi ? r : std::abs(std::remainder(a - b, kTwoPi));
  }

  std::span<const mapping::Beam> sweep_;
  std::vector<double> angles_;      // the beams' wrapped head angles, sorted
  std::vector<std::size_t> beams_;  // the beam at each
  std::vector<std::pair<std::size_t, std::size_t>> group_;  // [first, end) of equal angles
};

}  // namespace

cv::Mat RenderFanImage(std::span<const mapping::Beam> sweep, double pixel_m,
                       const std::string& title) {
  double max_range = 0.0;
  for (const auto& beam : sweep) {
    max_range = std::max(max_range, beam.bin_size_m * static_cast<double>(beam.intensities.size()));
  }
  // A longer reach takes larger pixels: at most kMaxFanHalf a side of the sonar (4097² pixels).
  constexpr int kMaxFanHalf = 2048;
  pixel_m = std::max(pixel_m, max_range / kMaxFanHalf);
  const int half = static_cast<int>(std::ceil(max_range / pixel_m));
  cv::Mat gray(2 * half + 1, 2 * half + 1, CV_8UC1, cv::Scalar(0));
  if (!sweep.empty()) {
    const BeamsByAngle beams(sweep);
    // Rows are independent: the same pixels whatever the threads.
#pragma omp parallel for schedule(static)
    for (int row = 0; row < gray.rows; ++row) {
      for (int col = 0; col < gray.cols; ++col) {
        const double x = (col - half) * pixel_m;
        const double y = (half - row) * pixel_m;
        const double range = std::hypot(x, y);
        if (range >= max_range) continue;  // beyond every beam's last bin
        const mapping::Beam& nearest = beams.Nearest(std::atan2(y, x));
        const auto bin = static_cast<std::size_t>(range / nearest.bin_size_m);
        if (bin < nearest.intensities.size()) gray.at<uchar>(row, col) = nearest.intensities[bin];
      }
    }
  }
  cv::Mat colour;
  cv::applyColorMap(gray, colour, cv::COLORMAP_INFERNO);
  return FramedFan(colour, half, pixel_m, title);
}

void WriteFanImage(const std::string& path, std::span<const mapping::Beam> sweep, double pixel_m,
                   const std::string& title) {
  WritePng(path, RenderFanImage(sweep, pixel_m, title));
}

namespace {

// A map view's cells as labels, one per cell column (top) or slab cell (side), row 0 at the top:
// 0 unknown, 1 free, 2 missed truth, 3 false positive, 4 the detector's ghost, 5 true positive,
// 6 occupied without a truth (higher wins); and the keys of its first and last column and row.
struct ViewLabels {
  cv::Mat label;
  int lo_u = 0, hi_u = 0, lo_v = 0, hi_v = 0;
};

ViewLabels LabelView(const MapCells& map, const mapping::KeySet& truth,
                     const mapping::KeySet& observable, const mapping::KeySet& detector_ghosts,
                     const MapView& view) {
  // Image axes: u (key index) to the right, v up; the third axis is projected (top) or sliced.
  const int u = 0;
  const int v = view.kind == MapView::Kind::kTop ? 1 : 2;
  const int w = view.kind == MapView::Kind::kTop ? 2 : 1;
  auto in_view = [&](const octomap::OcTreeKey& k) {
    return view.kind == MapView::Kind::kTop ||
           std::abs(static_cast<int>(k[w]) - static_cast<int>(view.slab_key)) <=
               view.slab_half_cells;
  };
  ViewLabels out{{}, 1 << 16, 0, 1 << 16, 0};
  for (const mapping::KeySet* cells : {&map.occupied, &map.free, &truth}) {
    for (const auto& k : *cells) {
      if (!in_view(k)) continue;
      out.lo_u = std::min<int>(out.lo_u, k[u]);
      out.hi_u = std::max<int>(out.hi_u, k[u]);
      out.lo_v = std::min<int>(out.lo_v, k[v]);
      out.hi_v = std::max<int>(out.hi_v, k[v]);
    }
  }
  if (out.hi_u < out.lo_u) out.lo_u = out.hi_u = out.lo_v = out.hi_v = 0;
  out.label = cv::Mat(out.hi_v - out.lo_v + 1, out.hi_u - out.lo_u + 1, CV_8UC1, cv::Scalar(0));
  auto mark = [&](const octomap::OcTreeKey& k, uchar value) {
    if (!in_view(k)) return;
    uchar& cell = out.label.at<uchar>(out.hi_v - k[v], k[u] - out.lo_u);
    cell = std::max(cell, value);
  };
  for (const auto& k : map.free) mark(k, 1);
  for (const auto& k : observable) {
    if (truth.contains(k) && !map.occupied.contains(k)) mark(k, 2);
  }
  // Without a truth (a real log), occupied is simply occupied: drawn white.
  const bool scored = !truth.empty();
  for (const auto& k : map.occupied) {
    mark(k, !scored ? 6 : truth.contains(k) ? 5 : detector_ghosts.contains(k) ? 4 : 3);
  }
  return out;
}

const cv::Vec3b kSonarColour(0, 220, 255);

// The sonar's cells on the map scaled `scale` pixels a cell: a cross at the first, a dot at each
// other in the view (a side view's slab, a top view's every one). Whether any was drawn.
bool DrawSonar(cv::Mat& colour, const MapView& view, const ViewLabels& labels, int scale) {
  const int v = view.kind == MapView::Kind::kTop ? 1 : 2;
  const cv::Scalar yellow(kSonarColour[0], kSonarColour[1], kSonarColour[2]);
  bool drawn = false;
  for (std::size_t i = 0; i < view.sonar.size(); ++i) {
    const octomap::OcTreeKey& k = view.sonar[i];
    if (view.kind == MapView::Kind::kSide &&
        std::abs(static_cast<int>(k[1]) - static_cast<int>(view.slab_key)) > view.slab_half_cells) {
      continue;
    }
    const cv::Point p((k[0] - labels.lo_u) * scale + scale / 2,
                      (labels.hi_v - k[v]) * scale + scale / 2);
    if (p.x < 0 || p.y < 0 || p.x >= colour.cols || p.y >= colour.rows) continue;
    if (i == 0) {
      cv::drawMarker(colour, p, yellow, cv::MARKER_CROSS, 16, 2);
    } else {
      cv::circle(colour, p, 2, yellow, cv::FILLED);
    }
    drawn = true;
  }
  return drawn;
}

}  // namespace

cv::Mat RenderMapView(const MapCells& map, const mapping::KeySet& truth,
                      const mapping::KeySet& observable, const MapView& view,
                      const mapping::KeySet& detector_ghosts) {
  const ViewLabels labels = LabelView(map, truth, observable, detector_ghosts, view);
  const cv::Mat& label = labels.label;
  const cv::Vec3b palette[] = {{0, 0, 0},     {70, 70, 70}, {255, 120, 0},  {0, 0, 230},
                               {230, 0, 230}, {0, 210, 0},  {255, 255, 255}};
  const char* names[] = {"unknown",
                         "free",
                         "observable surface missed",
                         "occupied, off surface",
                         "occupied, the detector's ghost",
                         "occupied, on a surface",
                         "occupied"};
  bool present[7] = {};
  cv::Mat colour(label.size(), CV_8UC3);
  for (int r = 0; r < label.rows; ++r) {
    for (int c = 0; c < label.cols; ++c) {
      const uchar l = label.at<uchar>(r, c);
      present[l] = true;
      colour.at<cv::Vec3b>(r, c) = palette[l];
    }
  }
  // Whole pixels per cell, the longer side at least 800 pixels.
  const int scale =
      std::max(1, (800 + std::max(label.rows, label.cols) - 1) / std::max(label.rows, label.cols));
  cv::resize(colour, colour, cv::Size(), scale, scale, cv::INTER_NEAREST);
  std::vector<std::pair<cv::Vec3b, std::string>> legend;
  for (int l = 0; l < 7; ++l) {
    if (present[l]) legend.emplace_back(palette[l], names[l]);
  }
  const double res = view.resolution_m > 0.0 ? view.resolution_m : 1.0;
  const char* unit = view.resolution_m > 0.0 ? " [m]" : " [cells]";
  auto metres = [&](int key) { return (key - 32768) * res; };
  if (DrawSonar(colour, view, labels, scale)) legend.emplace_back(kSonarColour, "sonar (x: start)");
  cv::Mat side = figure::Legend(legend);
  figure::AppendScaleBar(side, view.resolution_m > 0.0 ? res / scale : 0.0);
  const figure::Axis x{metres(labels.lo_u), metres(labels.hi_u + 1), std::string("x") + unit, {}};
  const figure::Axis y{metres(labels.lo_v),
                       metres(labels.hi_v + 1),
                       std::string(view.kind == MapView::Kind::kTop ? "y" : "z") + unit,
                       {}};
  return figure::Framed(colour, view.title, x, y, side);
}

namespace {

// Ticks at the series' x values `xs` (sorted, distinct), or for long series (a profile) at about
// ten round steps.
std::vector<double> XTicks(const std::vector<double>& xs, bool log2_x,
                           std::size_t max_value_ticks) {
  std::vector<double> ticks = xs;
  if (!log2_x && xs.size() > max_value_ticks) {
    const double raw = (xs.back() - xs.front()) / 10.0;
    const double decade = std::pow(10.0, std::floor(std::log10(raw)));
    const double step = raw / decade < 2.0   ? 2.0 * decade
                        : raw / decade < 5.0 ? 5.0 * decade
                                             : 10.0 * decade;
    ticks.clear();
    for (double t = std::ceil(xs.front() / step) * step; t <= xs.back(); t += step) {
      ticks.push_back(t);
    }
  }
  return ticks;
}

}  // namespace

namespace {

// The plot area's frame in every plot; the legend's rows (kLegendRow each) go below it.
constexpr int kPlotWidth = 720, kPlotHeight = 470, kPlotLeft = 80, kPlotRight = 20, kPlotTop = 50,
              kPlotBottom = 60, kLegendRow = 18;

// Where a plot's values fall in its image.
struct PlotScale {
  double x0, x1, y_min, y_top;
  bool log2_x;
  [[nodiscard]] double Fx(double x) const { return log2_x ? std::log2(std::max(x, 1e-9)) : x; }
  [[nodiscard]] cv::Point At(double x, double y) const {
    return {kPlotLeft +
                static_cast<int>((Fx(x) - x0) / (x1 - x0) * (kPlotWidth - kPlotLeft - kPlotRight)),
            kPlotHeight - kPlotBottom -
                static_cast<int>((y - y_min) / (y_top - y_min) *
                                 (kPlotHeight - kPlotTop - kPlotBottom))};
  }
};

// Each series' points (a marker each, up to 64, or always when unjoined, with its label), joined
// by a line only when its x values increase, and its legend entry below the axes.
void DrawSeries(cv::Mat& img, const std::vector<PlotSeries>& series, const PlotScale& scale) {
  constexpr std::size_t kMaxMarkers = 64;
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  int legend_y = kPlotHeight + 8;
  for (const auto& s : series) {
    const bool joined = std::adjacent_find(s.x.begin(), s.x.end(),
                                           [](double a, double b) { return b <= a; }) == s.x.end();
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const cv::Point p = scale.At(s.x[i], s.y[i]);
      if (s.x.size() <= kMaxMarkers || !joined) {
        cv::circle(img, p, 3, s.colour, cv::FILLED, cv::LINE_AA);
        if (i < s.labels.size()) {
          cv::putText(img, s.labels[i], {p.x + 5, p.y - 5}, font, 0.35, s.colour, 1, cv::LINE_AA);
        }
      }
      if (i > 0 && joined) {
        cv::line(img, scale.At(s.x[i - 1], s.y[i - 1]), p, s.colour, 2, cv::LINE_AA);
      }
    }
    const int text_x = kPlotLeft + 40;
    cv::circle(img, {text_x - 18, legend_y - 4}, 3, s.colour, cv::FILLED, cv::LINE_AA);
    if (joined) {
      cv::line(img, {text_x - 30, legend_y - 4}, {text_x - 5, legend_y - 4}, s.colour, 2);
    }
    cv::putText(img, s.name, {text_x, legend_y}, font, 0.42, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    legend_y += kLegendRow;
  }
}

}  // namespace

cv::Mat RenderLinePlot(const std::string& title, const std::string& x_label,
                       const std::string& y_label, const std::vector<PlotSeries>& series,
                       bool log2_x, double y_min, std::optional<double> y_max,
                       std::optional<std::pair<double, double>> x_range) {
  constexpr std::size_t kMaxValueTicks = 16;  // more x values: round ticks
  const int legend_height = kLegendRow * static_cast<int>(series.size()) + 8;
  cv::Mat img(kPlotHeight + legend_height, kPlotWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  std::vector<double> xs;
  double top = y_max.value_or(y_min);
  for (const auto& s : series) {
    xs.insert(xs.end(), s.x.begin(), s.x.end());
    if (!y_max) {
      for (double v : s.y) top = std::max(top, v);
    }
  }
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
  if (xs.empty()) return img;
  if (top <= y_min) top = y_min + 1.0;
  // Round y ticks, the top one at or above the data.
  const std::vector<double> round = figure::RoundTicks(y_min, top, 4);
  const double y_step = round.size() > 1 ? round[1] - round[0] : (top - y_min) / 4.0;
  if (!y_max) top = y_min + std::ceil((top - y_min) / y_step - 1e-9) * y_step;
  PlotScale scale{0.0, 1.0, y_min, top, log2_x};
  scale.x0 = scale.Fx(x_range ? x_range->first : xs.front());
  scale.x1 = x_range         ? scale.Fx(x_range->second)
             : xs.size() > 1 ? scale.Fx(xs.back())
                             : scale.x0 + 1.0;
  if (x_range) xs = {x_range->first, x_range->second};  // a continuous axis: round ticks
  const cv::Scalar black(0, 0, 0), grey(200, 200, 200);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const int bottom = kPlotHeight - kPlotBottom;
  for (double x : XTicks(xs, log2_x, x_range ? 1 : kMaxValueTicks)) {
    const int u = scale.At(x, y_min).x;
    cv::line(img, {u, kPlotTop}, {u, bottom}, grey, 1);
    char text[32];
    std::snprintf(text, sizeof text, "%g", x);
    int baseline = 0;
    const int width = cv::getTextSize(text, font, 0.42, 1, &baseline).width;
    const int left = std::clamp(u - width / 2, 2, kPlotWidth - width - 2);  // never cut
    cv::putText(img, text, {left, bottom + 18}, font, 0.42, black, 1, cv::LINE_AA);
  }
  for (double y = y_min; y <= top + 1e-9 * y_step; y += y_step) {
    const int v = scale.At(xs.front(), y).y;
    cv::line(img, {kPlotLeft, v}, {kPlotWidth - kPlotRight, v}, grey, 1);
    char text[32];
    std::snprintf(text, sizeof text, "%g", std::abs(y) < 1e-12 ? 0.0 : y);
    cv::putText(img, text, {8, v + 4}, font, 0.42, black, 1, cv::LINE_AA);
  }
  cv::rectangle(img, {kPlotLeft, kPlotTop}, {kPlotWidth - kPlotRight, bottom}, black, 1);
  // The title at its size, or smaller until it fits the image.
  double title_scale = 0.55;
  int baseline = 0;
  while (title_scale > 0.3 &&
         cv::getTextSize(title, font, title_scale, 1, &baseline).width > kPlotWidth - 16) {
    title_scale -= 0.05;
  }
  const int title_width = cv::getTextSize(title, font, title_scale, 1, &baseline).width;
  cv::putText(img, title, {std::min(kPlotLeft, kPlotWidth - 8 - title_width), 18}, font,
              title_scale, black, 1, cv::LINE_AA);
  cv::putText(img, x_label, {kPlotLeft + 180, kPlotHeight - 18}, font, 0.5, black, 1, cv::LINE_AA);
  cv::putText(img, y_label, {8, kPlotTop - 6}, font, 0.45, black, 1, cv::LINE_AA);
  DrawSeries(img, series, scale);
  return img;
}

}  // namespace sonarbench::sim
