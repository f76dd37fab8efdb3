#include "sonarbench/mapping/detection.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "cfar.hpp"
#include "walls.hpp"

namespace sonarbench::mapping {
namespace {

// A candidate echo along one beam: where it starts, and how strong it gets.
struct Echo {
  int bin;
  double peak;
};

// The first echo always counts (nothing nearer was seen); then the strongest, so that a weak echo
// in front (the floor at the beam's lower edge) does not hide the strongest (a wall).
std::vector<double> ChooseEchoes(std::vector<Echo> echoes, const Beam& beam, int max_obstacles) {
  std::vector<double> ranges;
  if (echoes.empty()) return ranges;
  std::vector<Echo> chosen{echoes.front()};
  std::stable_sort(echoes.begin() + 1, echoes.end(),
                   [](const Echo& a, const Echo& b) { return a.peak > b.peak; });
  for (auto it = echoes.begin() + 1;
       it != echoes.end() && static_cast<int>(chosen.size()) < max_obstacles; ++it) {
    chosen.push_back(*it);
  }
  std::sort(chosen.begin(), chosen.end(),
            [](const Echo& a, const Echo& b) { return a.bin < b.bin; });
  for (const Echo& e : chosen)
    ranges.push_back(beam.BinCentreRange(static_cast<std::size_t>(e.bin)));
  return ranges;
}

// The threshold detector's candidate echoes of one beam, nearest first.
std::vector<Echo> ThresholdEchoes(const Beam& beam, const SensorGeometry& sensor,
                                  const DetectionConfig& config) {
  const int n = static_cast<int>(beam.intensities.size());
  const int first = std::min(sensor.FirstUsableBin(), n);
  const int half = config.smoothing_bins / 2;
  // The window only averages usable bins, so self-reflections never leak into the first ones.
  auto smoothed = [&](int k) {
    const int lo = std::max(first, k - half);
    const int hi = std::min(n - 1, k + half);
    int sum = 0;
    for (int j = lo; j <= hi; ++j) sum += beam.intensities[static_cast<std::size_t>(j)];
    return static_cast<double>(sum) / (hi - lo + 1);
  };
  std::vector<Echo> runs;
  int run_start = -1;
  double peak = 0.0;
  for (int k = first; k <= n; ++k) {
    const double value = k < n ? smoothed(k) : 0.0;
    const bool above = k < n && value >= config.threshold;
    if (above && run_start < 0) {
      run_start = k;
      peak = 0.0;
    }
    if (above) peak = std::max(peak, value);
    if (!above && run_start >= 0) {
      if (k - run_start >= config.min_run_bins) runs.push_back({run_start, peak});
      run_start = -1;
    }
  }
  return runs;
}

// The runs of at least `min_run_bins` bins that pass, from `first` on: echoes at their first bin,
// each with its highest intensity.
std::vector<Echo> PassingRuns(const Beam& beam, const std::vector<bool>& passes, int first,
                              int min_run_bins) {
  std::vector<Echo> runs;
  const int n = static_cast<int>(passes.size());
  for (int k = first; k < n;) {
    if (!passes[static_cast<std::size_t>(k)]) {
      ++k;
      continue;
    }
    int end = k;
    double peak = 0.0;
    for (; end < n && passes[static_cast<std::size_t>(end)]; ++end) {
      peak = std::max<double>(peak, beam.intensities[static_cast<std::size_t>(end)]);
    }
    if (end - k >= min_run_bins) runs.push_back({k, peak});
    k = end;
  }
  return runs;
}

// The CFAR detector's candidate echoes of one beam, nearest first: on its power, past the
// self-reflection bins.
std::vector<Echo> CfarEchoes(const Beam& beam, const SensorGeometry& sensor,
                             const DetectionConfig& config, const CfarFactors& factors) {
  const int first = std::min(sensor.FirstUsableBin(), static_cast<int>(beam.intensities.size()));
  const std::vector<bool> passes = CfarPasses(BeamPower(beam, factors), first, config, factors);
  return PassingRuns(beam, passes, first, config.min_run_bins);
}

// Whether `method` works on one beam at a time.
bool PerBeam(DetectionConfig::Method method) {
  return method == DetectionConfig::Method::kThreshold ||
         method == DetectionConfig::Method::kCaCfar || method == DetectionConfig::Method::kOsCfar;
}

// The Canny detector's candidate echoes of every beam of a batch, nearest first.
std::vector<std::vector<Echo>> CannyEchoes(std::span<const Beam> beams,
                                           const SensorGeometry& sensor,
                                           const DetectionConfig& config) {
  std::vector<std::vector<Echo>> candidates(beams.size());
  std::size_t bins = 0;
  for (const Beam& beam : beams) bins = std::max(bins, beam.intensities.size());
  const int first = sensor.FirstUsableBin();
  if (beams.empty() || static_cast<int>(bins) <= first) return candidates;

  cv::Mat image(static_cast<int>(beams.size()), static_cast<int>(bins), CV_8UC1, cv::Scalar(0));
  for (std::size_t r = 0; r < beams.size(); ++r) {
    const auto& v = beams[r].intensities;
    for (std::size_t k = static_cast<std::size_t>(first); k < v.size(); ++k) {
      image.at<std::uint8_t>(static_cast<int>(r), static_cast<int>(k)) = v[k];
    }
  }
  cv::Mat blurred;
  // Replicate at the batch's first and last beams: a batch need not be a full revolution.
  cv::GaussianBlur(image, blurred, cv::Size(5, 5), config.canny_blur_sigma, config.canny_blur_sigma,
                   cv::BORDER_REPLICATE);
  double low = config.canny_low;
  double high = config.canny_high;
  if (config.method == DetectionConfig::Method::kAutoCanny) {
    std::vector<std::uint8_t> usable;
    for (int r = 0; r < blurred.rows; ++r) {
      const auto* row = blurred.ptr<std::uint8_t>(r);
      usable.insert(usable.end(), row + first, row + blurred.cols);
    }
    std::nth_element(usable.begin(), usable.begin() + static_cast<long>(usable.size() / 2),
                     usable.end());
    const double median = usable[usable.size() / 2];
    low = std::max(0.0, (1.0 - config.auto_canny_sigma) * median);
    high = std::min(255.0, (1.0 + config.auto_canny_sigma) * median);
  }
  cv::Mat edges;
  cv::Canny(blurred, edges, low, high, 3, /*L2gradient=*/true);
  cv::Mat dx;
  cv::Sobel(blurred, dx, CV_16S, 1, 0, 3);
  // Blanking the self-reflection bins makes a step at the first usable bin: skip the Sobel and
  // blur reach (2 bins) past it.
  const int start = first + 2;
  for (int r = 0; r < edges.rows; ++r) {
    std::vector<Echo> echoes;
    const auto* edge = edges.ptr<std::uint8_t>(r);
    const auto* gradient = dx.ptr<std::int16_t>(r);
    const auto* intensity = blurred.ptr<std::uint8_t>(r);
    const int n = static_cast<int>(beams[static_cast<std::size_t>(r)].intensities.size());
    for (int k = start; k < n; ++k) {
      if (edge[k] == 0 || gradient[k] <= 0) continue;
      if (!echoes.empty() && k - echoes.back().bin <= 1) continue;  // same edge, one bin on
      double peak = 0.0;
      for (int j = k; j < std::min(n, k + 5); ++j) peak = std::max<double>(peak, intensity[j]);
      echoes.push_back({k, peak});
    }
    candidates[static_cast<std::size_t>(r)] = std::move(echoes);
  }
  return candidates;
}

// The beams of a batch in order of head angle in [0, 2π) (their order on a tie).
std::vector<std::size_t> HeadAngleOrder(std::span<const Beam> beams) {
  std::vector<std::size_t> order(beams.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  auto angle = [&](std::size_t b) {
    const double a = std::fmod(beams[b].head_angle_rad, 2.0 * std::numbers::pi);
    return a < 0.0 ? a + 2.0 * std::numbers::pi : a;
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return angle(a) < angle(b); });
  return order;
}

// Drops every echo heard more than a margin behind the walls that the batch's first echoes
// outline (FitWalls, top-down in the world frame), along the beam's bearing. The margin is what
// the wall's own echoes can reach past its line: the slant range of its top or foot at the beam's
// vertical edge, d (1 / cos(β/2 + α) - 1) for a fan tilted α from vertical, plus the line's band
// and a bin. Only beams whose fan stands within kMaxWallFanTilt of vertical take part: top-down,
// another's bearing and range say nothing of a vertical wall. Marks the beams that lose every echo.
void DropEchoesBehindWalls(std::vector<std::vector<Echo>>& candidates, std::span<const Beam> beams,
                           const SensorGeometry& sensor, std::vector<bool>& heard_through) {
  const auto tilt = [](const Beam& beam) {
    const double up = (beam.T_world_sonar.linear() * Eigen::Vector3d::UnitZ()).z();
    return std::acos(std::clamp(std::abs(up), 0.0, 1.0));
  };
  std::vector<double> tilts(beams.size());
  for (std::size_t b = 0; b < beams.size(); ++b) tilts[b] = tilt(beams[b]);
  const auto upright = [&](std::size_t b) { return tilts[b] <= kMaxWallFanTilt; };
  auto top_down = [&](const Beam& beam) {
    const Eigen::Vector3d axis =
        beam.T_world_sonar.linear() * SonarRayDirection(beam.head_angle_rad, 0.0);
    return std::pair<Eigen::Vector2d, Eigen::Vector2d>{beam.T_world_sonar.translation().head<2>(),
                                                       axis.head<2>().normalized()};
  };
  std::vector<FirstEcho> firsts;
  for (const std::size_t b : HeadAngleOrder(beams)) {
    if (candidates[b].empty() || !upright(b)) continue;
    const auto [origin, bearing] = top_down(beams[b]);
    const double range = beams[b].BinCentreRange(static_cast<std::size_t>(candidates[b][0].bin));
    firsts.push_back({origin, origin + range * bearing});
  }
  const std::vector<WallLine> walls = FitWalls(firsts);
  for (std::size_t b = 0; b < beams.size(); ++b) {
    if (!upright(b)) continue;
    const auto [origin, bearing] = top_down(beams[b]);
    const std::optional<double> wall = WallAhead(origin, bearing, walls);
    if (!wall || candidates[b].empty()) continue;
    const double slant = 1.0 / std::cos(sensor.beam_width_vertical_rad / 2.0 + tilts[b]) - 1.0;
    const double limit = *wall * (1.0 + slant) + kWallBand + beams[b].bin_size_m;
    std::erase_if(candidates[b], [&](const Echo& e) {
      return beams[b].BinCentreRange(static_cast<std::size_t>(e.bin)) > limit;
    });
    heard_through[b] = candidates[b].empty();
  }
}

// Removes each beam's later echoes (all but its first) that no other beam within
// `support_window_deg` of head angle hears first within `support_range_m` of their range.
void DropUnsupportedLaterEchoes(std::vector<std::vector<Echo>>& candidates,
                                std::span<const Beam> beams, const DetectionConfig& config) {
  const double window = config.support_window_deg * std::numbers::pi / 180.0;
  std::vector<double> first_range(beams.size(), -1.0);
  for (std::size_t b = 0; b < beams.size(); ++b) {
    if (!candidates[b].empty())
      first_range[b] = beams[b].BinCentreRange(static_cast<std::size_t>(candidates[b][0].bin));
  }
  // Beams in order of head angle, so that each one's neighbours are a contiguous (circular) run.
  const std::size_t n = beams.size();
  const std::vector<std::size_t> order = HeadAngleOrder(beams);
  auto supported = [&](std::size_t at, double range) {
    const std::size_t b = order[at];
    for (std::size_t step = 1; step <= n / 2; ++step) {
      bool within = false;
      for (const std::size_t other : {order[(at + step) % n], order[(at + n - step) % n]}) {
        const double gap = std::abs(std::remainder(
            beams[other].head_angle_rad - beams[b].head_angle_rad, 2.0 * std::numbers::pi));
        if (gap > window) continue;
        within = true;
        if (first_range[other] >= 0.0 &&
            std::abs(first_range[other] - range) <= config.support_range_m)
          return true;
      }
      if (!within) return false;
    }
    return false;
  };
  for (std::size_t at = 0; at < n; ++at) {
    std::vector<Echo>& echoes = candidates[order[at]];
    if (echoes.size() < 2) continue;
    const Beam& beam = beams[order[at]];
    std::vector<Echo> kept{echoes.front()};
    for (std::size_t e = 1; e < echoes.size(); ++e) {
      if (supported(at, beam.BinCentreRange(static_cast<std::size_t>(echoes[e].bin))))
        kept.push_back(echoes[e]);
    }
    echoes = std::move(kept);
  }
}

// The ranges a batch's beams report, from their candidate echoes.
std::vector<std::vector<double>> ChooseAll(std::vector<std::vector<Echo>> candidates,
                                           std::span<const Beam> beams,
                                           const SensorGeometry& sensor,
                                           const DetectionConfig& config,
                                           std::vector<bool>* heard_through_walls) {
  std::vector<bool> through(beams.size(), false);
  if (config.behind_walls == DetectionConfig::BehindWalls::kRefuse)
    DropEchoesBehindWalls(candidates, beams, sensor, through);
  if (heard_through_walls != nullptr) *heard_through_walls = std::move(through);
  if (config.later_echoes == DetectionConfig::LaterEchoes::kSupported)
    DropUnsupportedLaterEchoes(candidates, beams, config);
  std::vector<std::vector<double>> ranges(beams.size());
  for (std::size_t b = 0; b < beams.size(); ++b)
    ranges[b] = ChooseEchoes(std::move(candidates[b]), beams[b], config.max_obstacles);
  return ranges;
}

}  // namespace

std::vector<double> DetectThreshold(const Beam& beam, const SensorGeometry& sensor,
                                    const DetectionConfig& config) {
  return ChooseEchoes(ThresholdEchoes(beam, sensor, config), beam, config.max_obstacles);
}

std::vector<std::vector<double>> DetectCanny(std::span<const Beam> beams,
                                             const SensorGeometry& sensor,
                                             const DetectionConfig& config) {
  return ChooseAll(CannyEchoes(beams, sensor, config), beams, sensor, config, nullptr);
}

std::vector<std::vector<double>> DetectObstacles(std::span<const Beam> beams,
                                                 const SensorGeometry& sensor,
                                                 const DetectionConfig& config,
                                                 std::vector<bool>* heard_through_walls) {
  std::vector<std::vector<Echo>> candidates(beams.size());
  if (!PerBeam(config.method)) {
    candidates = CannyEchoes(beams, sensor, config);
  } else {
    const bool cfar = config.method != DetectionConfig::Method::kThreshold;
    const std::optional<CfarFactors> factors =
        cfar ? std::optional<CfarFactors>(config) : std::nullopt;
    for (std::size_t b = 0; b < beams.size(); ++b) {
      candidates[b] = cfar ? CfarEchoes(beams[b], sensor, config, *factors)
                           : ThresholdEchoes(beams[b], sensor, config);
    }
  }
  return ChooseAll(std::move(candidates), beams, sensor, config, heard_through_walls);
}

}  // namespace sonarbench::mapping
