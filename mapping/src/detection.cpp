#include "sonarbench/mapping/detection.hpp"

#include <algorithm>

namespace sonarbench::mapping {

std::vector<double> DetectThreshold(const Beam& beam, const SensorGeometry& sensor,
                                    const DetectionConfig& config) {
  std::vector<double> ranges;
  const int n = static_cast<int>(beam.intensities.size());
  const int first = std::min(sensor.FirstUsableBin(), n);
  const int half = config.smoothing_bins / 2;
  // The window only averages usable bins, so self-reflections never leak into the first ones.
  auto smoothed = [&](int k) {
    const int lo = std::max(first, k - half);
    const int hi = std::min(n - 1, k + half);
    int sum = 0;
    for (int j = lo; j <= hi; ++j) sum += beam.intensities[j];
    return static_cast<double>(sum) / (hi - lo + 1);
  };
  struct Run {
    int start;
    double peak;
  };
  std::vector<Run> runs;
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
  if (runs.empty()) return ranges;
  // The first run always counts (nothing nearer was seen); the rest by peak intensity, so that a
  // weak echo in front (the floor at the beam's lower edge) does not hide the strongest (a wall).
  std::vector<Run> chosen{runs.front()};
  std::vector<Run> rest(runs.begin() + 1, runs.end());
  std::stable_sort(rest.begin(), rest.end(), [](const Run& a, const Run& b) { return a.peak > b.peak; });
  for (const Run& run : rest) {
    if (static_cast<int>(chosen.size()) >= config.max_obstacles) break;
    chosen.push_back(run);
  }
  std::sort(chosen.begin(), chosen.end(), [](const Run& a, const Run& b) { return a.start < b.start; });
  for (const Run& run : chosen) ranges.push_back(beam.BinCentreRange(static_cast<std::size_t>(run.start)));
  return ranges;
}

}  // namespace sonarbench::mapping
