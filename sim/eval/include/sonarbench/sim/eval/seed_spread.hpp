#pragma once

#include <span>
#include <vector>

namespace sonarbench::sim {

/// Student's t distribution with `dof` ≥ 1 degrees of freedom: P(T <= t).
[[nodiscard]] double StudentTCdf(double t, int dof);
/// Its quantile: the t with StudentTCdf(t, dof) = p, for p in (0, 1).
[[nodiscard]] double StudentTQuantile(double p, int dof);

/// Whether one value (a real log's figure) lies within the spread of N simulated runs of the same
/// place (docs/fidelity.md, "The verdict"): the log's statistic against the runs, the same
/// statistic of each run left out against the others, and the bound they allow.
struct SpreadJudgement {
  double statistic = 0.0;
  std::vector<double> left_out;
  double bound = 0.0;
  bool within = true;
  /// How far the statistic lies beyond the bound (0 within), in the figure's units.
  double excess = 0.0;
};

/// One figure: the statistic is the log's difference from the runs' mean, `left_out` each run's
/// from the others' mean; within when |difference| <= t_{N-1}(1 - level/2) · s · sqrt(1 + 1/N),
/// s the runs' standard deviation, the prediction interval of a normal sample (its size is
/// `level` when the log is one more run). Needs N >= 3 runs.
[[nodiscard]] SpreadJudgement JudgeValue(double log, std::span<const double> runs, double level);

/// K settings at once: the statistic is the mean over settings of |log_k - the runs' mean_k|,
/// `left_out` each run's against the others' (scaled by sqrt(1 - 1/N²), the log being judged
/// against one run more); within when the statistic <= mean + t_{N-1}(1 - level) · sd ·
/// sqrt(1 + 1/N) of `left_out` (one-sided, approximate: its size is tested). `runs[i][k]` is run
/// i's value at setting k; needs N >= 3 runs of K = log.size() values each.
[[nodiscard]] SpreadJudgement JudgeSettings(std::span<const double> log,
                                            const std::vector<std::vector<double>>& runs,
                                            double level);

}  // namespace sonarbench::sim
