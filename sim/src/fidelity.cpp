#include "sonarbench/sim/fidelity.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "sonarbench/mapping/atomic_file.hpp"
#include "sonarbench/sim/images.hpp"
#include "sonarbench/sim/report.hpp"

namespace sonarbench::sim {
namespace {

std::vector<double> MeanProfile(std::span<const mapping::Beam> beams, std::size_t bins) {
  std::vector<double> sum(bins, 0.0);
  std::vector<double> count(bins, 0.0);
  for (const auto& beam : beams) {
    for (std::size_t k = 0; k < std::min(bins, beam.intensities.size()); ++k) {
      sum[k] += beam.intensities[k];
      count[k] += 1.0;
    }
  }
  for (std::size_t k = 0; k < bins; ++k) sum[k] = count[k] > 0 ? sum[k] / count[k] : 0.0;
  return sum;
}

// The head-angle step of a beam, in [0, steps).
std::size_t StepIndex(const mapping::Beam& beam, const mapping::SensorGeometry& sensor) {
  const int steps = sensor.BeamsPerSweep();
  const long step = std::lround(beam.head_angle_rad / sensor.step_angle_rad);
  return static_cast<std::size_t>(((step % steps) + steps) % steps);
}

// Per beam, its strongest bin at or beyond `min_range_m` (the wall, in a tank), if it has one.
using StrongestBins = std::vector<std::optional<std::size_t>>;
StrongestBins FindStrongestBins(std::span<const mapping::Beam> beams, double min_range_m) {
  StrongestBins out(beams.size());
  for (std::size_t i = 0; i < beams.size(); ++i) {
    const auto& v = beams[i].intensities;
    const auto first = static_cast<std::size_t>(std::ceil(min_range_m / beams[i].bin_size_m));
    if (first >= v.size()) continue;
    out[i] = static_cast<std::size_t>(
        std::max_element(v.begin() + static_cast<long>(first), v.end()) - v.begin());
  }
  return out;
}

// Mean |a - b| over two equally long series (0 for empty ones).
double MeanAbsDifference(std::span<const double> a, std::span<const double> b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += std::abs(a[i] - b[i]);
  return a.empty() ? 0.0 : sum / static_cast<double>(a.size());
}

// The 10th, 50th and 90th percentiles (the values at ⌊q·n⌋ of the sorted n) of each beam's
// strongest intensity beyond `min_range_m`.
std::array<double, 3> WallPeaks(std::span<const mapping::Beam> beams,
                                const StrongestBins& strongest) {
  std::vector<double> peaks;
  for (std::size_t i = 0; i < beams.size(); ++i) {
    if (strongest[i]) peaks.push_back(beams[i].intensities[*strongest[i]]);
  }
  std::array<double, 3> out{};
  if (peaks.empty()) return out;
  std::sort(peaks.begin(), peaks.end());
  const std::array<double, 3> quantiles = {0.1, 0.5, 0.9};
  for (std::size_t i = 0; i < 3; ++i) {
    out[i] = peaks[static_cast<std::size_t>(quantiles[i] * static_cast<double>(peaks.size()))];
  }
  return out;
}

// FidelityReport::sim_wall_profile for `beams`.
std::vector<double> WallProfile(std::span<const mapping::Beam> beams,
                                const StrongestBins& strongest, std::size_t first_usable) {
  constexpr int kBefore = FidelityReport::kWallProfileBefore;
  const auto size = static_cast<std::size_t>(kBefore + FidelityReport::kWallProfileAfter + 1);
  std::vector<double> sum(size, 0.0);
  std::vector<double> count(size, 0.0);
  for (std::size_t b = 0; b < beams.size(); ++b) {
    if (!strongest[b]) continue;
    const auto& beam = beams[b];
    for (std::size_t i = 0; i < size; ++i) {
      const auto k = static_cast<long>(*strongest[b]) + static_cast<long>(i) - kBefore;
      if (k < static_cast<long>(first_usable) || k >= static_cast<long>(beam.intensities.size()))
        continue;
      sum[i] += beam.intensities[static_cast<std::size_t>(k)];
      count[i] += 1.0;
    }
  }
  for (std::size_t i = 0; i < size; ++i) sum[i] = count[i] > 0.0 ? sum[i] / count[i] : 0.0;
  return sum;
}

// The wall profile over the beams whose head angle `keep` accepts [deg], averaged over the
// offsets kBehindFirst..kBehindLast past the strongest echo.
template <typename Keep>
double BehindWall(std::span<const mapping::Beam> beams, const StrongestBins& strongest,
                  std::size_t first_usable, Keep keep) {
  using R = FidelityReport;
  static_assert(R::kBehindFirst >= 0 && R::kBehindLast <= R::kWallProfileAfter,
                "the offsets behind the wall lie in the wall profile");
  StrongestBins kept(strongest.size());
  for (std::size_t b = 0; b < beams.size(); ++b) {
    if (keep(beams[b].head_angle_rad * 180.0 / std::numbers::pi)) kept[b] = strongest[b];
  }
  const std::vector<double> profile = WallProfile(beams, kept, first_usable);
  const auto from = static_cast<std::size_t>(R::kWallProfileBefore + R::kBehindFirst);
  const auto to = static_cast<std::size_t>(R::kWallProfileBefore + R::kBehindLast);
  return std::accumulate(profile.begin() + static_cast<long>(from),
                         profile.begin() + static_cast<long>(to) + 1, 0.0) /
         static_cast<double>(to - from + 1);
}

// FidelityReport::sim_behind_walls for `beams`: over the beams whose head angle lies in each
// band off the nearest side's normal.
std::array<double, 2> BehindWalls(std::span<const mapping::Beam> beams,
                                  const StrongestBins& strongest, std::size_t first_usable) {
  using R = FidelityReport;
  const std::array<std::array<double, 2>, 2> bands = {
      {{0.0, R::kSquareDeg}, {R::kCornerFromDeg, 45.0}}};
  std::array<double, 2> out{};
  for (std::size_t band = 0; band < 2; ++band) {
    out[band] = BehindWall(beams, strongest, first_usable, [&](double degrees) {
      // std::remainder leaves the head angle within ±45° of the nearest multiple of 90°.
      const double off = std::abs(std::remainder(degrees, 90.0));
      return off >= bands[band][0] && off <= bands[band][1];
    });
  }
  return out;
}

// FidelityReport::sim_behind_walls_by_side for `beams`: over the beams within kSquareDeg of each
// side's normal.
std::array<double, 4> BehindWallsBySide(std::span<const mapping::Beam> beams,
                                        const StrongestBins& strongest, std::size_t first_usable) {
  std::array<double, 4> out{};
  for (std::size_t side = 0; side < 4; ++side) {
    out[side] = BehindWall(beams, strongest, first_usable, [&](double degrees) {
      const double off =
          std::abs(std::remainder(degrees - 90.0 * static_cast<double>(side), 360.0));
      return off <= FidelityReport::kSquareDeg;
    });
  }
  return out;
}

// `strongest`, less the beams whose strongest bin lies more than `reach` bins from the range
// `wall_m` gives for their head angle (or whose angle has none); `kept` counts the rest.
StrongestBins NearWall(std::span<const mapping::Beam> beams, const StrongestBins& strongest,
                       const std::vector<std::optional<double>>& wall_m,
                       const mapping::SensorGeometry& sensor, int reach, std::size_t& kept) {
  StrongestBins out(strongest.size());
  kept = 0;
  for (std::size_t b = 0; b < beams.size(); ++b) {
    const std::optional<double>& wall = wall_m[StepIndex(beams[b], sensor)];
    if (!strongest[b] || !wall) continue;
    const double bins_off = (beams[b].BinCentreRange(*strongest[b]) - *wall) / sensor.bin_size_m;
    if (std::labs(std::lround(bins_off)) > reach) continue;
    out[b] = strongest[b];
    ++kept;
  }
  return out;
}

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

// FidelityReport::sim_local_contrast from the beams' locally centred rows of bins [first, ...).
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

// FidelityReport::sim_range_correlation from the beams' centred rows.
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

// FidelityReport::sim_beam_correlation from the beams' centred rows.
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

// Per head-angle step, the median over sweeps of value(beam, its strongest bin).
template <typename Value>
std::vector<std::optional<double>> PerAngleMedian(std::span<const mapping::Beam> beams,
                                                  const StrongestBins& strongest,
                                                  const mapping::SensorGeometry& sensor,
                                                  Value value) {
  const int steps = sensor.BeamsPerSweep();
  std::vector<std::vector<double>> per_angle(static_cast<std::size_t>(steps));
  for (std::size_t i = 0; i < beams.size(); ++i) {
    if (strongest[i]) {
      per_angle[StepIndex(beams[i], sensor)].push_back(value(beams[i], *strongest[i]));
    }
  }
  std::vector<std::optional<double>> out(per_angle.size());
  for (std::size_t a = 0; a < per_angle.size(); ++a) {
    auto& v = per_angle[a];
    if (v.empty()) continue;
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    out[a] = v[v.size() / 2];
  }
  return out;
}

std::vector<std::optional<double>> WallRanges(std::span<const mapping::Beam> beams,
                                              const StrongestBins& strongest,
                                              const mapping::SensorGeometry& sensor) {
  return PerAngleMedian(beams, strongest, sensor, [](const mapping::Beam& beam, std::size_t bin) {
    return beam.BinCentreRange(bin);
  });
}

std::vector<std::optional<double>> WallPeaksByAngle(std::span<const mapping::Beam> beams,
                                                    const StrongestBins& strongest,
                                                    const mapping::SensorGeometry& sensor) {
  return PerAngleMedian(beams, strongest, sensor, [](const mapping::Beam& beam, std::size_t bin) {
    return static_cast<double>(beam.intensities[bin]);
  });
}

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

// FidelityReport::sim_sweep_spread_by_band: SweepSpread over the usable bins of each band.
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
  // Per bin, the cells' means over the head steps seen twice or more, around the turn.
  double bins_counted = 0.0;
  for (std::size_t k = 0; k < width; ++k) {
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
    if (all.size() < 2) continue;
    const double mean =
        std::accumulate(all.begin(), all.end(), 0.0) / static_cast<double>(all.size());
    double squares = 0.0;
    for (const double m : all) squares += (m - mean) * (m - mean);
    out.angle_spread += std::sqrt(squares / static_cast<double>(all.size() - 1));
    out.angle_correlation[0] += PearsonCorrelation(a, b_near);
    out.angle_correlation[1] += PearsonCorrelation(a_far, b_far);
    bins_counted += 1.0;
  }
  if (bins_counted > 0.0) {
    out.angle_spread /= bins_counted;
    for (double& c : out.angle_correlation) c /= bins_counted;
  }
  return out;
}

nlohmann::json HeadAngleJson(const FidelityReport::HeadAngleCells& cells) {
  return {{"mean", cells.mean},
          {"ping_spread", cells.ping_spread},
          {"angle_spread", cells.angle_spread},
          {"angle_correlation_1_and_5_steps", cells.angle_correlation}};
}

std::array<double, 256> Histogram(std::span<const mapping::Beam> beams, std::size_t first) {
  std::array<double, 256> h{};
  double total = 0.0;
  for (const auto& beam : beams) {
    for (std::size_t k = first; k < beam.intensities.size(); ++k) {
      h[beam.intensities[k]] += 1.0;
      total += 1.0;
    }
  }
  if (total > 0) {
    for (double& v : h) v /= total;
  }
  return h;
}

void WriteText(const std::string& path, const std::string& text) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

// Two images side by side (the right one scaled to the left one's size).
cv::Mat SideBySide(const cv::Mat& left, const cv::Mat& right) {
  cv::Mat right_sized;
  cv::resize(right, right_sized, left.size(), 0, 0, cv::INTER_NEAREST);
  cv::Mat joined;
  cv::hconcat(left, right_sized, joined);
  return joined;
}

// The mean of `profile` over the bins whose centres lie in each of FidelityReport::kRangeBandsM.
FidelityReport::RangeBands BandMeans(std::span<const double> profile, double bin_size_m) {
  FidelityReport::RangeBands means{};
  for (std::size_t band = 0; band < means.size(); ++band) {
    const auto [first, end] = BandBins(band, bin_size_m, profile.size());
    if (first == end) continue;
    double sum = 0.0;
    for (std::size_t k = first; k < end; ++k) sum += profile[k];
    means[band] = sum / static_cast<double>(end - first);
  }
  return means;
}

}  // namespace

double PearsonCorrelation(std::span<const double> a, std::span<const double> b) {
  const std::size_t n = std::min(a.size(), b.size());
  if (n == 0) return 0.0;
  double ma = 0.0, mb = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= static_cast<double>(n);
  mb /= static_cast<double>(n);
  double sab = 0.0, saa = 0.0, sbb = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

std::size_t SecondTripProfile(std::span<const mapping::Beam> beams,
                              std::span<const std::optional<std::size_t>> strongest,
                              std::size_t first_usable, std::vector<double>& profile,
                              double& excess) {
  constexpr long kReach = FidelityReport::kSecondTripReach;
  profile.assign(2 * kReach + 1, 0.0);
  excess = 0.0;
  std::size_t count = 0;
  for (std::size_t b = 0; b < beams.size(); ++b) {
    if (!strongest[b]) continue;
    const auto& v = beams[b].intensities;
    const long centre = 2 * static_cast<long>(*strongest[b]);
    if (centre - kReach < static_cast<long>(first_usable) ||
        centre + kReach >= static_cast<long>(v.size())) {
      continue;
    }
    for (long o = -kReach; o <= kReach; ++o) {
      profile[static_cast<std::size_t>(o + kReach)] += v[static_cast<std::size_t>(centre + o)];
    }
    ++count;
  }
  if (count == 0) return 0;
  // The flanks' least-squares line: the tail behind the walls falls with range.
  double n = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (long o = -kReach; o <= kReach; ++o) {
    double& mean = profile[static_cast<std::size_t>(o + kReach)];
    mean /= static_cast<double>(count);
    if (o < FidelityReport::kRingFirst || o > FidelityReport::kRingLast) {
      const auto x = static_cast<double>(o);
      n += 1.0;
      sx += x;
      sy += mean;
      sxx += x * x;
      sxy += x * mean;
    }
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  const double intercept = (sy - slope * sx) / n;
  for (long o = FidelityReport::kRingFirst; o <= FidelityReport::kRingLast; ++o) {
    excess += profile[static_cast<std::size_t>(o + kReach)] -
              (intercept + slope * static_cast<double>(o));
  }
  return count;
}

FidelityReport CompareWithLog(std::span<const mapping::Beam> sim,
                              std::span<const mapping::Beam> real,
                              const mapping::SensorGeometry& sensor, double wall_min_range_m) {
  FidelityReport r;
  const auto bins = static_cast<std::size_t>(sensor.num_bins);
  r.sim_mean = MeanProfile(sim, bins);
  r.real_mean = MeanProfile(real, bins);
  r.profile_correlation_all = PearsonCorrelation(r.sim_mean, r.real_mean);
  const auto first = static_cast<std::size_t>(sensor.FirstUsableBin());
  const std::size_t usable = std::min(first, bins);  // all bins may lie in the self-reflection
  r.profile_correlation_usable = PearsonCorrelation(std::span(r.sim_mean).subspan(usable),
                                                    std::span(r.real_mean).subspan(usable));
  r.profile_mean_abs_difference = MeanAbsDifference(std::span(r.sim_mean).subspan(usable),
                                                    std::span(r.real_mean).subspan(usable));
  r.sim_band_means = BandMeans(r.sim_mean, sensor.bin_size_m);
  r.real_band_means = BandMeans(r.real_mean, sensor.bin_size_m);
  const StrongestBins sim_strongest = FindStrongestBins(sim, wall_min_range_m);
  const StrongestBins real_strongest = FindStrongestBins(real, wall_min_range_m);
  r.sim_wall_m = WallRanges(sim, sim_strongest, sensor);
  r.real_wall_m = WallRanges(real, real_strongest, sensor);
  r.sim_wall_peak_by_angle = WallPeaksByAngle(sim, sim_strongest, sensor);
  r.real_wall_peak_by_angle = WallPeaksByAngle(real, real_strongest, sensor);
  r.sim_wall_profile = WallProfile(sim, sim_strongest, first);
  r.real_wall_profile = WallProfile(real, real_strongest, first);
  const auto tail_start =
      static_cast<std::size_t>(FidelityReport::kWallProfileBefore + FidelityReport::kWallTailStart);
  r.wall_tail_mean_abs_difference =
      MeanAbsDifference(std::span(r.sim_wall_profile).subspan(tail_start),
                        std::span(r.real_wall_profile).subspan(tail_start));
  r.sim_behind_walls = BehindWalls(sim, sim_strongest, first);
  r.real_behind_walls = BehindWalls(real, real_strongest, first);
  r.sim_behind_walls_by_side = BehindWallsBySide(sim, sim_strongest, first);
  r.real_behind_walls_by_side = BehindWallsBySide(real, real_strongest, first);
  r.sim_direct_wall_profile =
      WallProfile(sim,
                  NearWall(sim, sim_strongest, r.sim_wall_m, sensor,
                           FidelityReport::kDirectWallReach, r.sim_direct_wall_beams),
                  first);
  r.real_direct_wall_profile =
      WallProfile(real,
                  NearWall(real, real_strongest, r.sim_wall_m, sensor,
                           FidelityReport::kDirectWallReach, r.real_direct_wall_beams),
                  first);
  constexpr auto kFront = static_cast<std::size_t>(FidelityReport::kWallFront);
  constexpr auto kFrontStart =
      static_cast<std::size_t>(FidelityReport::kWallProfileBefore) - kFront;
  r.wall_front_mean_abs_difference =
      MeanAbsDifference(std::span(r.sim_direct_wall_profile).subspan(kFrontStart, kFront),
                        std::span(r.real_direct_wall_profile).subspan(kFrontStart, kFront));
  r.sim_second_trip_beams = SecondTripProfile(sim, sim_strongest, first, r.sim_second_trip_profile,
                                              r.sim_second_trip_excess);
  r.real_second_trip_beams = SecondTripProfile(
      real, real_strongest, first, r.real_second_trip_profile, r.real_second_trip_excess);
  r.second_trip_mean_abs_difference =
      MeanAbsDifference(r.sim_second_trip_profile, r.real_second_trip_profile);
  r.sim_wall_peak = WallPeaks(sim, sim_strongest);
  r.real_wall_peak = WallPeaks(real, real_strongest);
  std::vector<double> differences;
  for (std::size_t a = 0; a < r.sim_wall_m.size(); ++a) {
    if (r.sim_wall_m[a] && r.real_wall_m[a]) {
      differences.push_back(std::abs(*r.sim_wall_m[a] - *r.real_wall_m[a]) / sensor.bin_size_m);
    }
  }
  r.wall_angles_compared = differences.size();
  if (!differences.empty()) {
    std::nth_element(differences.begin(),
                     differences.begin() + static_cast<long>(differences.size() / 2),
                     differences.end());
    r.median_wall_difference_bins = differences[differences.size() / 2];
  }
  r.sim_sweep_spread = SweepSpread(sim, sensor);
  r.real_sweep_spread = SweepSpread(real, sensor);
  r.sim_sweep_spread_by_band = SweepSpreadByBand(sim, sensor);
  r.real_sweep_spread_by_band = SweepSpreadByBand(real, sensor);
  const std::size_t far_half = (first + bins) / 2;
  const auto sim_rows = CentredRows(sim, far_half, bins);
  const auto real_rows = CentredRows(real, far_half, bins);
  r.sim_range_correlation = RangeCorrelation(sim_rows);
  r.real_range_correlation = RangeCorrelation(real_rows);
  r.sim_beam_correlation = BeamCorrelation(sim, sim_rows, sensor);
  r.real_beam_correlation = BeamCorrelation(real, real_rows, sensor);
  const auto sim_local_rows = LocallyCentredRows(sim, far_half, bins);
  const auto real_local_rows = LocallyCentredRows(real, far_half, bins);
  r.sim_local_range_correlation = RangeCorrelation(sim_local_rows);
  r.real_local_range_correlation = RangeCorrelation(real_local_rows);
  r.sim_local_beam_correlation = BeamCorrelation(sim, sim_local_rows, sensor);
  r.real_local_beam_correlation = BeamCorrelation(real, real_local_rows, sensor);
  r.sim_local_contrast = LocalContrast(sim, sim_local_rows, far_half);
  r.real_local_contrast = LocalContrast(real, real_local_rows, far_half);
  {
    // The ringing bins: before the usable ones, where the real mean is half its largest there.
    const std::span<const double> own = std::span(r.real_mean).first(usable);
    if (!own.empty()) {
      const double half = 0.5 * *std::max_element(own.begin(), own.end());
      std::size_t low = 0;
      while (low < own.size() && own[low] < half) ++low;
      std::size_t high = own.size() - 1;
      while (high > low && own[high] < half) --high;
      if (low < own.size() && half > 0.0) {
        r.sim_ringing = HeadAngleStats(sim, sensor, low, high);
        r.real_ringing = HeadAngleStats(real, sensor, low, high);
      }
    }
  }
  {
    const auto near_end = static_cast<std::size_t>(
        std::min<double>(static_cast<double>(bins),
                         std::floor(FidelityReport::kNearRangeM / sensor.bin_size_m + 0.5)));
    if (near_end > usable) {
      r.sim_near_range = HeadAngleStats(sim, sensor, usable, near_end - 1);
      r.real_near_range = HeadAngleStats(real, sensor, usable, near_end - 1);
    }
  }
  r.sim_histogram = Histogram(sim, first);
  r.real_histogram = Histogram(real, first);
  for (std::size_t v = 0; v < 256; ++v) {
    r.histogram_intersection += std::min(r.sim_histogram[v], r.real_histogram[v]);
    const bool in_sim = r.sim_histogram[v] > 0.0;
    const bool in_real = r.real_histogram[v] > 0.0;
    r.sim_values += in_sim ? 1 : 0;
    r.real_values += in_real ? 1 : 0;
    r.sim_values_not_real += in_sim && !in_real ? 1 : 0;
  }
  return r;
}

namespace {

// A value per range band of each run (the mean profiles', the sweep spreads'), for fidelity.json:
// one object per band, null where a run's bins do not reach it.
nlohmann::json RangeBandsJson(const FidelityReport::RangeBands& sim,
                              const FidelityReport::RangeBands& real) {
  nlohmann::json bands = nlohmann::json::array();
  const auto value = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  for (std::size_t b = 0; b < FidelityReport::kRangeBandsM.size(); ++b) {
    bands.push_back({{"from_m", FidelityReport::kRangeBandsM[b][0]},
                     {"to_m", FidelityReport::kRangeBandsM[b][1]},
                     {"sim", value(sim[b])},
                     {"real", value(real[b])}});
  }
  return bands;
}

}  // namespace

void WriteFidelityOutputs(const std::string& out_dir, const FidelityReport& r,
                          std::span<const mapping::Beam> sim_sweep,
                          std::span<const mapping::Beam> real_sweep,
                          const mapping::SensorGeometry& sensor, const std::string& scene_file,
                          const std::string& log_file) {
  namespace fs = std::filesystem;
  CreateOutputDirectory(out_dir);
  const fs::path dir(out_dir);
  std::ostringstream profile;
  profile << "bin,range_m,sim_mean,real_mean\n";
  for (std::size_t k = 0; k < r.sim_mean.size(); ++k) {
    profile << k << "," << (k + 0.5) * sensor.bin_size_m << "," << r.sim_mean[k] << ","
            << r.real_mean[k] << "\n";
  }
  WriteText((dir / "profile.csv").string(), profile.str());
  std::ostringstream walls;
  walls << "head_angle_deg,sim_wall_m,real_wall_m,sim_wall_intensity,real_wall_intensity\n";
  const auto field = [](const std::optional<double>& v) {
    return v ? std::to_string(*v) : std::string();
  };
  for (std::size_t a = 0; a < r.sim_wall_m.size(); ++a) {
    walls << a * sensor.step_angle_rad * 180.0 / std::numbers::pi << "," << field(r.sim_wall_m[a])
          << "," << field(r.real_wall_m[a]) << "," << field(r.sim_wall_peak_by_angle[a]) << ","
          << field(r.real_wall_peak_by_angle[a]) << "\n";
  }
  WriteText((dir / "wall_range.csv").string(), walls.str());
  std::ostringstream angles;
  angles << "head_angle_deg,sim_self_reflection,real_self_reflection,sim_near_range,"
            "real_near_range\n";
  const auto at = [](const FidelityReport::HeadAngleCells& cells, std::size_t a) {
    return a < cells.by_head_angle.size() ? cells.by_head_angle[a] : std::nullopt;
  };
  for (std::size_t a = 0; a < static_cast<std::size_t>(sensor.BeamsPerSweep()); ++a) {
    angles << a * sensor.step_angle_rad * 180.0 / std::numbers::pi << ","
           << field(at(r.sim_ringing, a)) << "," << field(at(r.real_ringing, a)) << ","
           << field(at(r.sim_near_range, a)) << "," << field(at(r.real_near_range, a)) << "\n";
  }
  WriteText((dir / "by_head_angle.csv").string(), angles.str());
  // An aligned profile, entry i at offset i - before.
  const auto write_aligned = [&](const char* name, const std::vector<double>& sim,
                                 const std::vector<double>& real, long before) {
    std::ostringstream csv;
    csv << "offset_bins,sim_mean,real_mean\n";
    for (std::size_t i = 0; i < sim.size(); ++i) {
      csv << static_cast<long>(i) - before << "," << sim[i] << "," << real[i] << "\n";
    }
    WriteText((dir / name).string(), csv.str());
  };
  write_aligned("wall_profile.csv", r.sim_wall_profile, r.real_wall_profile,
                FidelityReport::kWallProfileBefore);
  write_aligned("direct_wall_profile.csv", r.sim_direct_wall_profile, r.real_direct_wall_profile,
                FidelityReport::kWallProfileBefore);
  write_aligned("second_trip_profile.csv", r.sim_second_trip_profile, r.real_second_trip_profile,
                FidelityReport::kSecondTripReach);
  std::ostringstream hist;
  hist << "intensity,sim_fraction,real_fraction\n";
  for (std::size_t v = 0; v < 256; ++v) {
    hist << v << "," << r.sim_histogram[v] << "," << r.real_histogram[v] << "\n";
  }
  WriteText((dir / "histogram.csv").string(), hist.str());

  // The two mean profiles against range: sim orange, real black.
  PlotSeries real_profile{"real log", cv::Scalar(0, 0, 0), {}, r.real_mean};
  PlotSeries sim_profile{"simulated", cv::Scalar(0, 140, 255), {}, r.sim_mean};
  for (std::size_t k = 0; k < r.sim_mean.size(); ++k) {
    real_profile.x.push_back((static_cast<double>(k) + 0.5) * sensor.bin_size_m);
  }
  sim_profile.x = real_profile.x;
  WritePng((dir / "profile.png").string(),
           RenderLinePlot("Mean intensity against range", "range [m]", "mean intensity",
                          {real_profile, sim_profile}, false, 0.0));

  WritePng((dir / "polar.png").string(),
           SideBySide(RenderPolarImage(sim_sweep), RenderPolarImage(real_sweep)));
  WritePng((dir / "fan.png").string(),
           SideBySide(RenderFanImage(sim_sweep, 0.01), RenderFanImage(real_sweep, 0.01)));

  nlohmann::json report = ReportHeader();
  report.update({{"scene", scene_file},
                 {"log", log_file},
                 {"profile_correlation_all_bins", r.profile_correlation_all},
                 {"profile_correlation_usable_bins", r.profile_correlation_usable},
                 {"profile_mean_abs_difference_usable_bins", r.profile_mean_abs_difference},
                 {"mean_by_range_band", RangeBandsJson(r.sim_band_means, r.real_band_means)},
                 {"median_wall_range_difference_bins", r.median_wall_difference_bins},
                 {"wall_angles_compared", r.wall_angles_compared},
                 {"wall_peak_intensity_p10_p50_p90_sim", r.sim_wall_peak},
                 {"wall_tail_mean_abs_difference", r.wall_tail_mean_abs_difference},
                 {"behind_walls_square_corners_sim", r.sim_behind_walls},
                 {"behind_walls_square_by_side_sim", r.sim_behind_walls_by_side},
                 {"behind_walls_square_by_side_real", r.real_behind_walls_by_side},
                 {"behind_walls_square_corners_real", r.real_behind_walls},
                 {"wall_peak_intensity_p10_p50_p90_real", r.real_wall_peak},
                 {"wall_front_mean_abs_difference", r.wall_front_mean_abs_difference},
                 {"direct_wall_beams_sim", r.sim_direct_wall_beams},
                 {"direct_wall_beams_real", r.real_direct_wall_beams},
                 {"second_trip_excess_sim", r.sim_second_trip_excess},
                 {"second_trip_excess_real", r.real_second_trip_excess},
                 {"second_trip_beams_sim", r.sim_second_trip_beams},
                 {"second_trip_beams_real", r.real_second_trip_beams},
                 {"second_trip_mean_abs_difference", r.second_trip_mean_abs_difference},
                 {"histogram_intersection", r.histogram_intersection},
                 {"values_held_sim", r.sim_values},
                 {"values_held_real", r.real_values},
                 {"values_held_sim_not_real", r.sim_values_not_real},
                 {"range_correlation_by_lag_sim", r.sim_range_correlation},
                 {"range_correlation_by_lag_real", r.real_range_correlation},
                 {"beam_correlation_by_step_sim", r.sim_beam_correlation},
                 {"beam_correlation_by_step_real", r.real_beam_correlation},
                 {"local_range_correlation_by_lag_sim", r.sim_local_range_correlation},
                 {"local_range_correlation_by_lag_real", r.real_local_range_correlation},
                 {"local_beam_correlation_by_step_sim", r.sim_local_beam_correlation},
                 {"local_beam_correlation_by_step_real", r.real_local_beam_correlation},
                 {"local_contrast_sim", r.sim_local_contrast},
                 {"local_contrast_real", r.real_local_contrast},
                 {"self_reflection",
                  {{"bins", {r.real_ringing.first_bin, r.real_ringing.last_bin}},
                   {"sim", HeadAngleJson(r.sim_ringing)},
                   {"real", HeadAngleJson(r.real_ringing)}}},
                 {"near_range",
                  {{"bins", {r.real_near_range.first_bin, r.real_near_range.last_bin}},
                   {"sim", HeadAngleJson(r.sim_near_range)},
                   {"real", HeadAngleJson(r.real_near_range)}}},
                 {"sweep_spread_sim", r.sim_sweep_spread},
                 {"sweep_spread_real", r.real_sweep_spread},
                 {"sweep_spread_by_range_band",
                  RangeBandsJson(r.sim_sweep_spread_by_band, r.real_sweep_spread_by_band)},
                 {"outputs",
                  {"profile.csv", "profile.png", "wall_range.csv", "wall_profile.csv",
                   "direct_wall_profile.csv", "second_trip_profile.csv", "histogram.csv",
                   "by_head_angle.csv", "polar.png", "fan.png"}}});
  WriteJson((dir / "fidelity.json").string(), report);
}

}  // namespace sonarbench::sim
