#include "sonarbench/sim/eval/fidelity.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <sstream>

#include "fidelity_parts.hpp"

namespace sonarbench::sim {
namespace {

using namespace fidelity_parts;

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

// FidelityReport::Stats::wall_profile for `beams`.
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

// FidelityReport::Stats::behind_walls for `beams`: over the beams whose head angle lies in each
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

// FidelityReport::Stats::behind_walls_by_side for `beams`: over the beams within kSquareDeg of each
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

namespace {

// The ringing bins: before the usable ones, from the first to the last whose mean intensity is
// at least half the largest there; none when there is no such bin.
std::optional<std::array<std::size_t, 2>> RingingBins(std::span<const double> mean,
                                                      std::size_t usable) {
  const std::span<const double> own = mean.first(std::min(usable, mean.size()));
  if (own.empty()) return std::nullopt;
  const double half = 0.5 * *std::max_element(own.begin(), own.end());
  std::size_t low = 0;
  while (low < own.size() && own[low] < half) ++low;
  std::size_t high = own.size() - 1;
  while (high > low && own[high] < half) --high;
  if (low >= own.size() || !(half > 0.0)) return std::nullopt;
  return std::array<std::size_t, 2>{low, high};
}

// Measure's texture statistics, over the far half of the usable bins.
void MeasureTexture(std::span<const mapping::Beam> beams, const mapping::SensorGeometry& sensor,
                    FidelityReport::Stats& s) {
  const auto bins = static_cast<std::size_t>(sensor.num_bins);
  const auto first = static_cast<std::size_t>(sensor.FirstUsableBin());
  const std::size_t far_half = (first + bins) / 2;
  const auto rows = CentredRows(beams, far_half, bins);
  s.range_correlation = RangeCorrelation(rows);
  s.beam_correlation = BeamCorrelation(beams, rows, sensor);
  const auto local_rows = LocallyCentredRows(beams, far_half, bins);
  s.local_range_correlation = RangeCorrelation(local_rows);
  s.local_beam_correlation = BeamCorrelation(beams, local_rows, sensor);
  s.local_contrast = LocalContrast(beams, local_rows, far_half);
}

// Measure's per-head-angle statistics: the ringing bins and the near range past them.
void MeasureHeadAngles(std::span<const mapping::Beam> beams, const mapping::SensorGeometry& sensor,
                       const FidelitySettings& settings, FidelityReport::Stats& s) {
  const auto bins = static_cast<std::size_t>(sensor.num_bins);
  const std::size_t usable = std::min(static_cast<std::size_t>(sensor.FirstUsableBin()), bins);
  if (settings.ringing_bins) {
    s.ringing =
        HeadAngleStats(beams, sensor, (*settings.ringing_bins)[0], (*settings.ringing_bins)[1]);
  }
  const auto near_end = static_cast<std::size_t>(
      std::min<double>(static_cast<double>(bins),
                       std::floor(FidelityReport::kNearRangeM / sensor.bin_size_m + 0.5)));
  if (near_end > usable) s.near_range = HeadAngleStats(beams, sensor, usable, near_end - 1);
}

}  // namespace

FidelityReport::Stats Measure(std::span<const mapping::Beam> beams,
                              const mapping::SensorGeometry& sensor,
                              const FidelitySettings& settings) {
  FidelityReport::Stats s;
  const auto bins = static_cast<std::size_t>(sensor.num_bins);
  const auto first = static_cast<std::size_t>(sensor.FirstUsableBin());
  s.mean = MeanProfile(beams, bins);
  s.band_means = BandMeans(s.mean, sensor.bin_size_m);
  const StrongestBins strongest = FindStrongestBins(beams, settings.wall_min_range_m);
  s.wall_m = WallRanges(beams, strongest, sensor);
  s.wall_peak_by_angle = WallPeaksByAngle(beams, strongest, sensor);
  s.wall_profile = WallProfile(beams, strongest, first);
  s.behind_walls = BehindWalls(beams, strongest, first);
  s.behind_walls_by_side = BehindWallsBySide(beams, strongest, first);
  const auto& reference = settings.reference_wall_m.empty() ? s.wall_m : settings.reference_wall_m;
  s.direct_wall_profile =
      WallProfile(beams,
                  NearWall(beams, strongest, reference, sensor, FidelityReport::kDirectWallReach,
                           s.direct_wall_beams),
                  first);
  s.second_trip_beams =
      SecondTripProfile(beams, strongest, first, s.second_trip_profile, s.second_trip_excess);
  s.wall_peak = WallPeaks(beams, strongest);
  s.sweep_spread = SweepSpread(beams, sensor);
  s.sweep_spread_by_band = SweepSpreadByBand(beams, sensor);
  MeasureTexture(beams, sensor, s);
  MeasureHeadAngles(beams, sensor, settings, s);
  s.histogram = Histogram(beams, first);
  for (const double fraction : s.histogram) s.values += fraction > 0.0 ? 1 : 0;
  return s;
}

void Compare(FidelityReport& r, const mapping::SensorGeometry& sensor) {
  const FidelityReport::Stats& sim = r.sim;
  const FidelityReport::Stats& real = r.real;
  const auto bins = static_cast<std::size_t>(sensor.num_bins);
  const std::size_t usable = std::min(static_cast<std::size_t>(sensor.FirstUsableBin()), bins);
  r.profile_correlation_all = PearsonCorrelation(sim.mean, real.mean);
  r.profile_correlation_usable =
      PearsonCorrelation(std::span(sim.mean).subspan(usable), std::span(real.mean).subspan(usable));
  r.profile_mean_abs_difference =
      MeanAbsDifference(std::span(sim.mean).subspan(usable), std::span(real.mean).subspan(usable));
  const auto tail_start =
      static_cast<std::size_t>(FidelityReport::kWallProfileBefore + FidelityReport::kWallTailStart);
  r.wall_tail_mean_abs_difference =
      MeanAbsDifference(std::span(sim.wall_profile).subspan(tail_start),
                        std::span(real.wall_profile).subspan(tail_start));
  constexpr auto kFront = static_cast<std::size_t>(FidelityReport::kWallFront);
  constexpr auto kFrontStart =
      static_cast<std::size_t>(FidelityReport::kWallProfileBefore) - kFront;
  r.wall_front_mean_abs_difference =
      MeanAbsDifference(std::span(sim.direct_wall_profile).subspan(kFrontStart, kFront),
                        std::span(real.direct_wall_profile).subspan(kFrontStart, kFront));
  r.second_trip_mean_abs_difference =
      MeanAbsDifference(sim.second_trip_profile, real.second_trip_profile);
  std::vector<double> differences;
  for (std::size_t a = 0; a < sim.wall_m.size(); ++a) {
    if (sim.wall_m[a] && real.wall_m[a]) {
      differences.push_back(std::abs(*sim.wall_m[a] - *real.wall_m[a]) / sensor.bin_size_m);
    }
  }
  r.wall_angles_compared = differences.size();
  if (!differences.empty()) {
    const auto middle = differences.begin() + static_cast<long>(differences.size() / 2);
    std::nth_element(differences.begin(), middle, differences.end());
    r.median_wall_difference_bins = *middle;
  }
  for (std::size_t v = 0; v < 256; ++v) {
    r.histogram_intersection += std::min(sim.histogram[v], real.histogram[v]);
    r.sim_values_not_real += sim.histogram[v] > 0.0 && !(real.histogram[v] > 0.0) ? 1 : 0;
  }
}

FidelityReport CompareWithLog(std::span<const mapping::Beam> sim,
                              std::span<const mapping::Beam> real,
                              const mapping::SensorGeometry& sensor, double wall_min_range_m) {
  const auto bins = static_cast<std::size_t>(sensor.num_bins);
  const std::size_t usable = std::min(static_cast<std::size_t>(sensor.FirstUsableBin()), bins);
  FidelitySettings settings;
  settings.wall_min_range_m = wall_min_range_m;
  settings.ringing_bins = RingingBins(MeanProfile(real, bins), usable);
  FidelityReport r;
  r.sim = Measure(sim, sensor, settings);  // its own walls are the direct-wall reference
  settings.reference_wall_m = r.sim.wall_m;
  r.real = Measure(real, sensor, settings);
  Compare(r, sensor);
  return r;
}

}  // namespace sonarbench::sim
