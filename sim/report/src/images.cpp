#include "sonarbench/sim/report/images.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "sonarbench/mapping/atomic_file.hpp"

namespace sonarbench::sim {
std::vector<unsigned char> EncodePng(const cv::Mat& image) {
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", image, bytes)) throw std::runtime_error("PNG encoding failed");
  return bytes;
}

void WritePng(const std::string& path, const cv::Mat& image) {
  const std::vector<uchar> bytes = EncodePng(image);
  WriteFileAtomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  });
}

cv::Mat RenderPolarImage(std::span<const mapping::Beam> sweep) {
  std::size_t bins = 0;
  for (const auto& beam : sweep) bins = std::max(bins, beam.intensities.size());
  cv::Mat gray(static_cast<int>(sweep.size()), static_cast<int>(bins), CV_8UC1, cv::Scalar(0));
  for (std::size_t r = 0; r < sweep.size(); ++r) {
    std::copy(sweep[r].intensities.begin(), sweep[r].intensities.end(),
              gray.ptr<uchar>(static_cast<int>(r)));
  }
  cv::Mat colour;
  cv::applyColorMap(gray, colour, cv::COLORMAP_INFERNO);
  cv::resize(colour, colour, cv::Size(), 2.0, 2.0, cv::INTER_NEAREST);
  return colour;
}

void WritePolarImage(const std::string& path, std::span<const mapping::Beam> sweep) {
  WritePng(path, RenderPolarImage(sweep));
}

cv::Mat RenderFanImage(std::span<const mapping::Beam> sweep, double pixel_m) {
  double max_range = 0.0;
  for (const auto& beam : sweep) {
    max_range = std::max(max_range, beam.bin_size_m * static_cast<double>(beam.intensities.size()));
  }
  const int half = static_cast<int>(std::ceil(max_range / pixel_m));
  cv::Mat gray(2 * half + 1, 2 * half + 1, CV_8UC1, cv::Scalar(0));
  if (sweep.empty()) return gray;
  // Beams sorted by head angle in [0, 2π): the beam nearest a bearing is in the group of equal
  // angles just below it or just above it (circularly); among those the smallest angular
  // distance wins, then the earliest beam, as a scan in sweep order would choose.
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  auto wrapped = [&](double angle) { return angle - kTwoPi * std::floor(angle / kTwoPi); };
  std::vector<std::pair<double, std::size_t>> by_angle;
  for (std::size_t i = 0; i < sweep.size(); ++i)
    by_angle.emplace_back(wrapped(sweep[i].head_angle_rad), i);
  std::sort(by_angle.begin(), by_angle.end());
  const std::size_t n = by_angle.size();
  auto nearest_beam = [&](double bearing) {
    const double b = wrapped(bearing);
    const std::size_t above =
        static_cast<std::size_t>(
            std::lower_bound(by_angle.begin(), by_angle.end(), std::make_pair(b, std::size_t{0})) -
            by_angle.begin()) %
        n;
    const std::size_t below = (above + n - 1) % n;
    std::size_t best = sweep.size();
    double best_distance = 0.0;
    for (const std::size_t start : {below, above}) {
      // The whole group of beams sharing this angle.
      std::size_t k = start;
      while (by_angle[(k + n - 1) % n].first == by_angle[start].first && (k + n - 1) % n != start)
        k = (k + n - 1) % n;
      for (std::size_t step = 0; step < n && by_angle[k].first == by_angle[start].first;
           ++step, k = (k + 1) % n) {
        const std::size_t i = by_angle[k].second;
        const double d = std::abs(std::remainder(sweep[i].head_angle_rad - bearing, kTwoPi));
        if (best == sweep.size() || d < best_distance || (d == best_distance && i < best)) {
          best = i;
          best_distance = d;
        }
      }
    }
    return &sweep[best];
  };
  for (int row = 0; row < gray.rows; ++row) {
    for (int col = 0; col < gray.cols; ++col) {
      const double x = (col - half) * pixel_m;
      const double y = (half - row) * pixel_m;
      const mapping::Beam* nearest = nearest_beam(std::atan2(y, x));
      const auto bin = static_cast<std::size_t>(std::hypot(x, y) / nearest->bin_size_m);
      if (bin < nearest->intensities.size()) gray.at<uchar>(row, col) = nearest->intensities[bin];
    }
  }
  cv::Mat colour;
  cv::applyColorMap(gray, colour, cv::COLORMAP_INFERNO);
  return colour;
}

void WriteFanImage(const std::string& path, std::span<const mapping::Beam> sweep, double pixel_m) {
  WritePng(path, RenderFanImage(sweep, pixel_m));
}

cv::Mat RenderMapView(const MapCells& map, const mapping::KeySet& truth,
                      const mapping::KeySet& observable, const MapView& view) {
  // Image axes: u (key index) to the right, v up; the third axis is projected (top) or sliced.
  const int u = 0;
  const int v = view.kind == MapView::Kind::kTop ? 1 : 2;
  const int w = view.kind == MapView::Kind::kTop ? 2 : 1;
  auto in_view = [&](const octomap::OcTreeKey& k) {
    return view.kind == MapView::Kind::kTop ||
           std::abs(static_cast<int>(k[w]) - static_cast<int>(view.slab_key)) <=
               view.slab_half_cells;
  };
  int lo_u = 1 << 16, lo_v = 1 << 16, hi_u = 0, hi_v = 0;
  auto extend = [&](const mapping::KeySet& cells) {
    for (const auto& k : cells) {
      if (!in_view(k)) continue;
      lo_u = std::min<int>(lo_u, k[u]);
      hi_u = std::max<int>(hi_u, k[u]);
      lo_v = std::min<int>(lo_v, k[v]);
      hi_v = std::max<int>(hi_v, k[v]);
    }
  };
  extend(map.occupied);
  extend(map.free);
  extend(truth);
  if (hi_u < lo_u) lo_u = hi_u = lo_v = hi_v = 0;
  // Per pixel: 1 free, 2 missed truth, 3 false positive, 4 true positive (higher wins).
  cv::Mat label(hi_v - lo_v + 1, hi_u - lo_u + 1, CV_8UC1, cv::Scalar(0));
  auto mark = [&](const octomap::OcTreeKey& k, uchar value) {
    if (!in_view(k)) return;
    uchar& cell = label.at<uchar>(hi_v - k[v], k[u] - lo_u);
    cell = std::max(cell, value);
  };
  for (const auto& k : map.free) mark(k, 1);
  for (const auto& k : observable) {
    if (truth.contains(k) && !map.occupied.contains(k)) mark(k, 2);
  }
  // Without a truth (a real log), occupied is simply occupied: drawn white.
  const bool scored = !truth.empty();
  for (const auto& k : map.occupied) mark(k, !scored ? 5 : truth.contains(k) ? 4 : 3);
  const cv::Vec3b palette[] = {{0, 0, 0},   {70, 70, 70}, {255, 120, 0},
                               {0, 0, 230}, {0, 210, 0},  {255, 255, 255}};
  cv::Mat colour(label.size(), CV_8UC3);
  for (int r = 0; r < label.rows; ++r) {
    for (int c = 0; c < label.cols; ++c)
      colour.at<cv::Vec3b>(r, c) = palette[label.at<uchar>(r, c)];
  }
  const double scale = std::max(1.0, 400.0 / std::max(label.rows, label.cols));
  cv::resize(colour, colour, cv::Size(), scale, scale, cv::INTER_NEAREST);
  return colour;
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

cv::Mat RenderLinePlot(const std::string& title, const std::string& x_label,
                       const std::string& y_label, const std::vector<PlotSeries>& series,
                       bool log2_x, double y_min, std::optional<double> y_max) {
  constexpr int kWidth = 720, kHeight = 460, kLeft = 80, kRight = 20, kTop = 40, kBottom = 60;
  constexpr std::size_t kMaxValueTicks = 16;  // more x values: round ticks
  constexpr std::size_t kMaxMarkers = 64;     // a longer series: a line alone
  cv::Mat img(kHeight, kWidth, CV_8UC3, cv::Scalar(255, 255, 255));
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
  auto fx = [&](double x) { return log2_x ? std::log2(std::max(x, 1e-9)) : x; };
  const double x0 = fx(xs.front());
  const double x1 = xs.size() > 1 ? fx(xs.back()) : x0 + 1.0;
  auto px = [&](double x) {
    return cv::Point(kLeft + static_cast<int>((fx(x) - x0) / (x1 - x0) * (kWidth - kLeft - kRight)),
                     0);
  };
  auto py = [&](double y) {
    return kHeight - kBottom -
           static_cast<int>((y - y_min) / (top - y_min) * (kHeight - kTop - kBottom));
  };
  const cv::Scalar black(0, 0, 0), grey(200, 200, 200);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const std::vector<double> ticks = XTicks(xs, log2_x, kMaxValueTicks);
  for (double x : ticks) {
    const int u = px(x).x;
    cv::line(img, {u, kTop}, {u, kHeight - kBottom}, grey, 1);
    char text[32];
    std::snprintf(text, sizeof text, "%g", x);
    cv::putText(img, text, {u - 8, kHeight - kBottom + 18}, font, 0.42, black, 1, cv::LINE_AA);
  }
  for (int i = 0; i <= 4; ++i) {
    const double y = y_min + (top - y_min) * i / 4.0;
    cv::line(img, {kLeft, py(y)}, {kWidth - kRight, py(y)}, grey, 1);
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", y);
    cv::putText(img, text, {8, py(y) + 4}, font, 0.42, black, 1, cv::LINE_AA);
  }
  cv::rectangle(img, {kLeft, kTop}, {kWidth - kRight, kHeight - kBottom}, black, 1);
  cv::putText(img, title, {kLeft, 18}, font, 0.55, black, 1, cv::LINE_AA);
  cv::putText(img, x_label, {kLeft + 180, kHeight - 18}, font, 0.5, black, 1, cv::LINE_AA);
  cv::putText(img, y_label, {8, kTop - 6}, font, 0.45, black, 1, cv::LINE_AA);
  // The legend sits in the lower right, where coverage-like curves that rise to 1 leave room.
  int legend_y = kHeight - kBottom - 12 - 18 * (static_cast<int>(series.size()) - 1);
  for (const auto& s : series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const cv::Point p(px(s.x[i]).x, py(s.y[i]));
      if (s.x.size() <= kMaxMarkers) cv::circle(img, p, 3, s.colour, cv::FILLED, cv::LINE_AA);
      if (i > 0) cv::line(img, {px(s.x[i - 1]).x, py(s.y[i - 1])}, p, s.colour, 2, cv::LINE_AA);
    }
    cv::line(img, {kWidth - 250, legend_y - 4}, {kWidth - 225, legend_y - 4}, s.colour, 2);
    cv::putText(img, s.name, {kWidth - 220, legend_y}, font, 0.42, black, 1, cv::LINE_AA);
    legend_y += 18;
  }
  return img;
}

void WriteTopDownImage(const std::string& path, const MapCells& map, const mapping::KeySet& truth,
                       const mapping::KeySet& observable) {
  WritePng(path, RenderMapView(map, truth, observable, MapView{}));
}

}  // namespace sonarbench::sim
