#include "cfar.hpp"

#include <algorithm>
#include <cmath>

namespace sonarbench::mapping {

double CaCfarFactor(int n, double false_alarm) {
  return n * (std::pow(false_alarm, -1.0 / n) - 1.0);
}

double OsCfarFactor(int n, int k, double false_alarm) {
  // log Pfa(α) = Σ_{i<k} log((n - i) / (n - i + α)) falls from 0 as α grows: bisect on it.
  const double target = std::log(false_alarm);
  auto log_pfa = [&](double alpha) {
    double sum = 0.0;
    for (int i = 0; i < k; ++i) sum += std::log((n - i) / (n - i + alpha));
    return sum;
  };
  double lo = 0.0;
  double hi = 1.0;
  while (log_pfa(hi) > target) hi *= 2.0;
  for (int step = 0; step < 100; ++step) {
    const double mid = 0.5 * (lo + hi);
    (log_pfa(mid) > target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

CfarFactors::CfarFactors(const DetectionConfig& config) {
  const DetectionConfig::Cfar& cfar = config.cfar;
  const bool ordered = config.method == DetectionConfig::Method::kOsCfar;
  const int most = 2 * cfar.training_bins;
  for (std::size_t c = 0; c < power_.size(); ++c) {
    power_[c] = std::pow(10.0, static_cast<double>(c) * cfar.db_per_count / 10.0);
  }
  factor_.assign(static_cast<std::size_t>(most) + 1, 0.0);
  order_.assign(static_cast<std::size_t>(most) + 1, 0);
  for (int count = 2; count <= most; ++count) {
    const int k = std::clamp(static_cast<int>(std::ceil(cfar.order * count)), 1, count);
    order_[static_cast<std::size_t>(count)] = k;
    factor_[static_cast<std::size_t>(count)] =
        ordered ? OsCfarFactor(count, k, cfar.false_alarm) : CaCfarFactor(count, cfar.false_alarm);
  }
}

std::vector<bool> CfarPasses(std::span<const double> power, int first,
                             const DetectionConfig& config, const CfarFactors& factors) {
  const int n = static_cast<int>(power.size());
  const DetectionConfig::Cfar& cfar = config.cfar;
  const bool ordered = config.method == DetectionConfig::Method::kOsCfar;
  const int most = 2 * cfar.training_bins;
  std::vector<bool> passes(power.size(), false);
  std::vector<double> training;
  training.reserve(static_cast<std::size_t>(most));
  for (int i = std::max(first, 0); i < n; ++i) {
    training.clear();
    for (int side : {-1, 1}) {
      for (int j = cfar.guard_bins + 1; j <= cfar.guard_bins + cfar.training_bins; ++j) {
        const int at = i + side * j;
        if (at >= first && at < n) training.push_back(power[static_cast<std::size_t>(at)]);
      }
    }
    const int count = static_cast<int>(training.size());
    if (count < 2) continue;
    double background = 0.0;
    if (ordered) {
      const auto kth = training.begin() + (factors.order(count) - 1);
      std::nth_element(training.begin(), kth, training.end());
      background = *kth;
    } else {
      for (const double p : training) background += p;
      background /= count;
    }
    passes[static_cast<std::size_t>(i)] =
        power[static_cast<std::size_t>(i)] > factors.factor(count) * background;
  }
  return passes;
}

std::vector<double> BeamPower(const Beam& beam, const CfarFactors& factors) {
  std::vector<double> power(beam.intensities.size());
  for (std::size_t k = 0; k < power.size(); ++k) power[k] = factors.power(beam.intensities[k]);
  return power;
}

}  // namespace sonarbench::mapping
