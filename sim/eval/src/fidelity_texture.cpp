#include <algorithm>
#include <cmath>
#include <numeric>

#include "fidelity_parts.hpp"

namespace sonarbench::sim::fidelity_parts {
namespace {

// Per head-angle step and bin of [first, end): the count, sum and sum of squares of the
// intensity over the beams that hold the bin (cell c = step · width + bin - first).
struct CellSums {
  std::size_t width = 0;
  std::vector<double> n, sum, sum_sq;

  // The intensity's standard deviation over the sweeps, averaged over the cells seen twice or
  // more (0 if none is).
  [[nodiscard]] double MeanSpread() const {
    double spread = 0.0;
    double counted = 0.0;
    for (std::size_t c = 0; c < n.size(); ++c) {
      if (n[c] < 2.0) continue;
      const double mean = sum[c] / n[c];
      const double variance = std::max(0.0, (sum_sq[c] - n[c] * mean * mean) / (n[c] - 1.0));
      spread += std::sqrt(variance);
      counted += 1.0;
    }
    return counted > 0.0 ? spread / counted : 0.0;
  }
};

CellSums SumCells(std::span<const mapping::Beam> beams, const mapping::SensorGeometry& sensor,
                  std::size_t first, std::size_t end) {
  CellSums out;
  out.width = end > first ? end - first : 0;
  const std::size_t cells = static_cast<std::size_t>(sensor.BeamsPerSweep()) * out.width;
  out.n.assign(cells, 0.0);
  out.sum.assign(cells, 0.0);
  out.sum_sq.assign(cells, 0.0);
  for (const auto& beam : beams) {
    const std::size_t row = StepIndex(beam, sensor) * out.width;
    for (std::size_t k = first; k < std::min(end, beam.intensities.size()); ++k) {
      const double v = beam.intensities[k];
      out.n[row + k - first] += 1.0;
      out.sum[row + k - first] += v;
      out.sum_sq[row + k - first] += v * v;
    }
  }
  return out;
}

// Bin k's cells' means across the head steps seen twice or more, around the turn: their spread
// and correlations at 1 and kRingingFarStep steps added to `out`; false if under two were seen.
bool AddBinAcrossAngles(const CellSums& cells, std::size_t steps, std::size_t k,
                        FidelityReport::HeadAngleCells& out) {
  const std::vector<double>& n = cells.n;
  const std::vector<double>& sum = cells.sum;
  const std::size_t width = cells.width;
  std::vector<double> means(steps, 0.0);
  std::vector<bool> seen(steps, false);
  for (std::size_t j = 0; j < steps; ++j) {
    const std::size_t c = j * width + k;
    if (n[c] < 2.0) continue;
    means[j] = sum[c] / n[c];
    seen[j] = true;
  }
  std::vector<double> a;
  std::vector<double> b_near;
  std::vector<double> a_far;
  std::vector<double> b_far;
  std::vector<double> all;
  for (std::size_t j = 0; j < steps; ++j) {
    if (!seen[j]) continue;
    all.push_back(means[j]);
    if (const std::size_t next = (j + 1) % steps; seen[next]) {
      a.push_back(means[j]);
      b_near.push_back(means[next]);
    }
    const std::size_t far = (j + FidelityReport::kRingingFarStep) % steps;
    if (seen[far]) {
      a_far.push_back(means[j]);
      b_far.push_back(means[far]);
    }
  }
  if (all.size() < 2) return false;
  const double mean =
      std::accumulate(all.begin(), all.end(), 0.0) / static_cast<double>(all.size());
  double squares = 0.0;
  for (const double m : all) squares += (m - mean) * (m - mean);
  out.angle_spread += std::sqrt(squares / static_cast<double>(all.size() - 1));
  out.angle_correlation[0] += PearsonCorrelation(a, b_near);
  out.angle_correlation[1] += PearsonCorrelation(a_far, b_far);
  return true;
}

}  // namespace

// Each beam's bins [first, bins) (fewer for a short beam), less the beam's mean over them.
std::vector<std::vector<double>> CentredRows(std::span<const mapping::Beam> beams,
                                             std::size_t first, std::size_t bins) {
  std::vector<std::vector<double>> rows(beams.size());
  for (std::size_t i = 0; i < beams.size(); ++i) {
    const auto& v = beams[i].intensities;
    const std::size_t end = std::min(bins, v.size());
    if (end <= first) continue;
    rows[i].assign(v.begin() + static_cast<long>(first), v.begin() + static_cast<long>(end));
    const double mean =
        std::accumulate(rows[i].begin(), rows[i].end(), 0.0) / static_cast<double>(end - first);
    for (double& x : rows[i]) x -= mean;
  }
  return rows;
}

// Each beam's bins [first, bins) (fewer for a short beam), less the beam's mean over the bins
// within FidelityReport::kLocalReach of each (from the whole beam, fewer at its ends).
std::vector<std::vector<double>> LocallyCentredRows(std::span<const mapping::Beam> beams,
                                                    std::size_t first, std::size_t bins) {
  const auto reach = static_cast<std::size_t>(FidelityReport::kLocalReach);
  std::vector<std::vector<double>> rows(beams.size());
  std::vector<double> prefix;
  for (std::size_t i = 0; i < beams.size(); ++i) {
    const auto& v = beams[i].intensities;
    const std::size_t end = std::min(bins, v.size());
    if (end <= first) continue;
    prefix.assign(1, 0.0);
    for (const std::uint8_t x : v) prefix.push_back(prefix.back() + x);
    rows[i].reserve(end - first);
    for (std::size_t k = first; k < end; ++k) {
      const std::size_t lo = k > reach ? k - reach : 0;
      const std::size_t hi = std::min(v.size(), k + reach + 1);
      rows[i].push_back(v[k] - (prefix[hi] - prefix[lo]) / static_cast<double>(hi - lo));
    }
  }
  return rows;
}

// FidelityReport::Stats::local_contrast from the beams' locally centred rows of bins [first, ...).
double LocalContrast(std::span<const mapping::Beam> beams,
                     const std::vector<std::vector<double>>& rows, std::size_t first) {
  double squares = 0.0;
  double intensity = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < beams.size(); ++i) {
    for (std::size_t k = 0; k < rows[i].size(); ++k) {
      squares += rows[i][k] * rows[i][k];
      intensity += beams[i].intensities[first + k];
    }
    count += rows[i].size();
  }
  if (count == 0 || intensity <= 0.0) return 0.0;
  return std::sqrt(squares / static_cast<double>(count)) / (intensity / static_cast<double>(count));
}

// FidelityReport::Stats::range_correlation from the beams' centred rows.
std::vector<double> RangeCorrelation(const std::vector<std::vector<double>>& rows) {
  const auto lags = static_cast<std::size_t>(FidelityReport::kTextureLags);
  std::vector<double> covariance(lags + 1, 0.0);
  for (const auto& row : rows) {
    if (row.size() <= lags) continue;
    for (std::size_t m = 0; m <= lags; ++m) {
      double sum = 0.0;
      for (std::size_t k = 0; k + m < row.size(); ++k) sum += row[k] * row[k + m];
      covariance[m] += sum / static_cast<double>(row.size() - m);
    }
  }
  if (covariance[0] > 0.0) {
    for (std::size_t m = lags + 1; m-- > 0;) covariance[m] /= covariance[0];
  }
  return covariance;
}

// FidelityReport::Stats::beam_correlation from the beams' centred rows.
std::vector<double> BeamCorrelation(std::span<const mapping::Beam> beams,
                                    const std::vector<std::vector<double>>& rows,
                                    const mapping::SensorGeometry& sensor) {
  const auto lags = static_cast<std::size_t>(FidelityReport::kBeamLags);
  const auto steps = static_cast<std::size_t>(sensor.BeamsPerSweep());
  std::vector<double> out(lags + 1, 0.0);
  out[0] = 1.0;
  for (std::size_t m = 1; m <= lags; ++m) {
    double covariance = 0.0;
    double spread = 0.0;
    for (std::size_t i = 0; i + m < beams.size(); ++i) {
      if ((StepIndex(beams[i], sensor) + m) % steps != StepIndex(beams[i + m], sensor)) continue;
      const std::vector<double>& a = rows[i];
      const std::vector<double>& b = rows[i + m];
      double ab = 0.0, aa = 0.0, bb = 0.0;
      for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
        ab += a[k] * b[k];
        aa += a[k] * a[k];
        bb += b[k] * b[k];
      }
      covariance += ab;
      spread += std::sqrt(aa * bb);
    }
    out[m] = spread > 0.0 ? covariance / spread : 0.0;
  }
  return out;
}

double SweepSpread(std::span<const mapping::Beam> beams, const mapping::SensorGeometry& sensor) {
  return SumCells(beams, sensor, static_cast<std::size_t>(sensor.FirstUsableBin()),
                  static_cast<std::size_t>(sensor.num_bins))
      .MeanSpread();
}

// The bins [first, end) among the first `bins` whose centres (k + ½) bins lie in band `band` of
// FidelityReport::kRangeBandsM (empty when none does).
std::pair<std::size_t, std::size_t> BandBins(std::size_t band, double bin_size_m,
                                             std::size_t bins) {
  const auto [from, to] = FidelityReport::kRangeBandsM[band];
  const auto centre = [&](std::size_t k) { return (static_cast<double>(k) + 0.5) * bin_size_m; };
  std::size_t first = 0;
  while (first < bins && centre(first) < from) ++first;
  std::size_t end = first;
  while (end < bins && centre(end) < to) ++end;
  return {first, end};
}

// FidelityReport::Stats::sweep_spread_by_band: SweepSpread over the usable bins of each band.
FidelityReport::RangeBands SweepSpreadByBand(std::span<const mapping::Beam> beams,
                                             const mapping::SensorGeometry& sensor) {
  FidelityReport::RangeBands out{};
  const auto usable = static_cast<std::size_t>(sensor.FirstUsableBin());
  for (std::size_t band = 0; band < out.size(); ++band) {
    const auto [in_band, end] =
        BandBins(band, sensor.bin_size_m, static_cast<std::size_t>(sensor.num_bins));
    const std::size_t first = std::max(usable, in_band);
    if (first < end) out[band] = SumCells(beams, sensor, first, end).MeanSpread();
  }
  return out;
}

// FidelityReport::HeadAngleCells over bins [first, last] (last < bins).
FidelityReport::HeadAngleCells HeadAngleStats(std::span<const mapping::Beam> beams,
                                              const mapping::SensorGeometry& sensor,
                                              std::size_t first, std::size_t last) {
  FidelityReport::HeadAngleCells out;
  out.first_bin = first;
  out.last_bin = last;
  const CellSums cells = SumCells(beams, sensor, first, last + 1);
  const std::size_t width = cells.width;
  const auto steps = static_cast<std::size_t>(sensor.BeamsPerSweep());
  const std::vector<double>& n = cells.n;
  const std::vector<double>& sum = cells.sum;
  const double count = std::accumulate(n.begin(), n.end(), 0.0);
  if (count == 0.0) return out;
  out.mean = std::accumulate(sum.begin(), sum.end(), 0.0) / count;
  out.ping_spread = cells.MeanSpread();
  out.by_head_angle.resize(steps);
  for (std::size_t j = 0; j < steps; ++j) {
    const auto row = static_cast<std::ptrdiff_t>(j * width);
    const double seen = std::accumulate(n.begin() + row, n.begin() + row + width, 0.0);
    if (seen > 0.0) {
      out.by_head_angle[j] =
          std::accumulate(sum.begin() + row, sum.begin() + row + width, 0.0) / seen;
    }
  }
  double bins_counted = 0.0;
  for (std::size_t k = 0; k < width; ++k)
    bins_counted += AddBinAcrossAngles(cells, steps, k, out) ? 1.0 : 0.0;
  if (bins_counted > 0.0) {
    out.angle_spread /= bins_counted;
    for (double& c : out.angle_correlation) c /= bins_counted;
  }
  return out;
}

}  // namespace sonarbench::sim::fidelity_parts
