#include "sonarbench/sim/eval/seed_spread.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

namespace sonarbench::sim {
namespace {

double Mean(std::span<const double> v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

// The sample standard deviation (N - 1 in the denominator).
double SampleSd(std::span<const double> v) {
  const double mean = Mean(v);
  double sum = 0.0;
  for (const double x : v) sum += (x - mean) * (x - mean);
  return std::sqrt(sum / static_cast<double>(v.size() - 1));
}

// The mean of `runs` at `setting` without run `skip` (none: runs.size()).
double MeanWithout(const std::vector<std::vector<double>>& runs, std::size_t setting,
                   std::size_t skip) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (i == skip) continue;
    sum += runs[i][setting];
    ++n;
  }
  return sum / static_cast<double>(n);
}

void Check(std::size_t runs, double level) {
  if (runs < 3) throw std::invalid_argument("a seed spread needs at least 3 runs");
  if (!(level > 0.0 && level < 1.0)) throw std::invalid_argument("level outside (0, 1)");
}

}  // namespace

// Abramowitz and Stegun 26.7.3 (odd dof) and 26.7.4 (even dof): P(|T| <= t) as a finite series
// in θ = atan(t / sqrt(dof)).
double StudentTCdf(double t, int dof) {
  if (dof < 1) throw std::invalid_argument("Student's t needs at least one degree of freedom");
  if (std::isinf(t)) return t > 0.0 ? 1.0 : 0.0;
  const double theta = std::atan(std::abs(t) / std::sqrt(static_cast<double>(dof)));
  const double c2 = std::cos(theta) * std::cos(theta);
  double inside = 0.0;
  if (dof % 2 == 1) {
    double sum = 0.0;
    if (dof > 1) {
      double term = std::cos(theta);
      sum = term;
      for (int k = 3; k <= dof - 2; k += 2) {
        term *= static_cast<double>(k - 1) / k * c2;
        sum += term;
      }
    }
    inside = 2.0 / std::numbers::pi * (theta + std::sin(theta) * sum);
  } else {
    double term = 1.0;
    double sum = 1.0;
    for (int k = 2; k <= dof - 2; k += 2) {
      term *= static_cast<double>(k - 1) / k * c2;
      sum += term;
    }
    inside = std::sin(theta) * sum;
  }
  return t >= 0.0 ? 0.5 + 0.5 * inside : 0.5 - 0.5 * inside;
}

double StudentTQuantile(double p, int dof) {
  if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("a quantile needs p in (0, 1)");
  if (p < 0.5) return -StudentTQuantile(1.0 - p, dof);
  double hi = 1.0;
  while (StudentTCdf(hi, dof) < p) hi *= 2.0;
  double lo = 0.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (StudentTCdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

SpreadJudgement JudgeValue(double log, std::span<const double> runs, double level) {
  Check(runs.size(), level);
  const auto n = static_cast<double>(runs.size());
  SpreadJudgement j;
  j.statistic = log - Mean(runs);
  const double sum = std::accumulate(runs.begin(), runs.end(), 0.0);
  for (const double x : runs) j.left_out.push_back(x - (sum - x) / (n - 1.0));
  // The left-out differences are N/(N-1) times the runs' deviations from their mean.
  const double s = SampleSd(j.left_out) * (n - 1.0) / n;
  j.bound = StudentTQuantile(1.0 - level / 2.0, static_cast<int>(runs.size()) - 1) * s *
            std::sqrt(1.0 + 1.0 / n);
  j.excess = std::max(0.0, std::abs(j.statistic) - j.bound);
  j.within = j.excess == 0.0;
  return j;
}

SpreadJudgement JudgeSettings(std::span<const double> log,
                              const std::vector<std::vector<double>>& runs, double level) {
  Check(runs.size(), level);
  for (const auto& run : runs) {
    if (run.size() != log.size() || run.empty()) {
      throw std::invalid_argument("every run needs a value per setting");
    }
  }
  const std::size_t k_settings = log.size();
  const auto n = static_cast<double>(runs.size());
  SpreadJudgement j;
  for (std::size_t k = 0; k < k_settings; ++k) {
    j.statistic += std::abs(log[k] - MeanWithout(runs, k, runs.size()));
  }
  j.statistic /= static_cast<double>(k_settings);
  const double scale = std::sqrt(1.0 - 1.0 / (n * n));
  for (std::size_t i = 0; i < runs.size(); ++i) {
    double s = 0.0;
    for (std::size_t k = 0; k < k_settings; ++k) {
      s += std::abs(runs[i][k] - MeanWithout(runs, k, i));
    }
    j.left_out.push_back(scale * s / static_cast<double>(k_settings));
  }
  j.bound = Mean(j.left_out) + StudentTQuantile(1.0 - level, static_cast<int>(runs.size()) - 1) *
                                   SampleSd(j.left_out) * std::sqrt(1.0 + 1.0 / n);
  j.excess = std::max(0.0, j.statistic - j.bound);
  j.within = j.excess == 0.0;
  return j;
}

}  // namespace sonarbench::sim
