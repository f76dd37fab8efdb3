#include "sonarbench/sim/sonar/range_spread.hpp"

#include <algorithm>
#include <cmath>

#include "kernels.hpp"

namespace sonarbench::sim {

void AddPulseSkirts(const SensorModel& sensor, std::vector<double>& echo_power) {
  const Acoustics& a = sensor.acoustics;
  if (a.pulse.skirt_length_m <= 0.0) return;
  const double q = std::exp(-sensor.geometry.bin_size_m / a.pulse.skirt_length_m);
  // The skirts hold S = 10^(db/10) of the pulse's power, shared out of the echo's: the pulse
  // keeps 1 / (1 + S), each side S / (2 (1 + S)), a geometric series of ratio q from q.
  const double skirts_share = std::pow(10.0, a.pulse.skirt_db / 10.0);
  const double keep = 1.0 / (1.0 + skirts_share);
  const double feed = keep * skirts_share * (1.0 - q) / (2.0 * q);
  // Two passes, each an exponential sum of the bins on one side: `before` holds
  // Σ_{j<k} P_j q^(k-j) and `after` Σ_{j>k} P_j q^(j-k), from the unchanged powers.
  thread_local std::vector<double> skirts;
  const std::size_t bins = echo_power.size();
  skirts.assign(bins, 0.0);
  double before = 0.0;
  for (std::size_t k = 0; k < bins; ++k) {
    skirts[k] = before;
    before = q * (before + echo_power[k]);
  }
  double after = 0.0;
  for (std::size_t k = bins; k-- > 0;) {
    const double power = echo_power[k];
    echo_power[k] = keep * power + feed * (skirts[k] + after);
    after = q * (after + power);
  }
}

void AddReverberation(const SensorModel& sensor, std::vector<double>& echo_power) {
  const Acoustics& a = sensor.acoustics;
  if (a.tail.reverberation_length_m <= 0.0) return;
  const double keep = std::exp(-sensor.geometry.bin_size_m / a.tail.reverberation_length_m);
  const double feed = std::pow(10.0, a.tail.reverberation_db / 10.0) * (1.0 - keep);
  double tail = 0.0;
  for (double& power : echo_power) {
    const double echo = power;
    power += tail;
    tail = keep * tail + feed * echo;
  }
}

void AddSecondTrip(const SensorModel& sensor, const Receiver& receiver,
                   std::vector<double>& echo_power, std::span<const double> impulse_power) {
  if (!HasSecondTrip(sensor.acoustics)) return;
  const double second_trip = std::pow(10.0, sensor.acoustics.tail.second_trip_db / 10.0);
  const std::span<const double> tvg_at_bin = receiver.TvgAtBin();
  const std::span<const double> untvg_at_bin = receiver.UntvgAtBin();
  const std::size_t bins = std::min({echo_power.size(), impulse_power.size(), tvg_at_bin.size()});
  // Each trip's powers with the time-varied gain taken off.
  thread_local std::vector<double> out;
  thread_local std::vector<double> back;
  thread_local std::vector<double> sums;
  out.resize(bins);
  back.resize(bins);
  double largest_out = 0.0;
  double largest_back = 0.0;
  for (std::size_t i = 0; i < bins; ++i) {
    out[i] = echo_power[i] * untvg_at_bin[i];
    back[i] = impulse_power[i] * untvg_at_bin[i];
    largest_out = std::max(largest_out, out[i]);
    largest_back = std::max(largest_back, back[i]);
  }
  if (largest_out <= 0.0 || largest_back <= 0.0) return;
  // The way back's bins from its first to its last worth a product (1e-6 of its largest), as
  // one span: the products of one way-out bin with them are one vectorisable loop.
  std::size_t first = 0;
  while (back[first] < 1e-6 * largest_back) ++first;
  std::size_t last = bins - 1;
  while (back[last] < 1e-6 * largest_back) --last;
  // sums[m] = Σ_{i + j = m} out_i · back_j over i in increasing order, each way-out bin's
  // products one AddScaled; a pair's half in m + 1 is added when spreading.
  sums.assign(bins, 0.0);
  for (std::size_t i = 0; i < bins && i + first < bins; ++i) {
    const double o = out[i];
    if (o < 1e-6 * largest_out) continue;
    const std::size_t end = std::min(last + 1, bins - i);
    AddScaled(std::span(sums).subspan(i + first, end - first),
              std::span<const double>(back).subspan(first, end - first), o);
  }
  // Each pair's halves in m and m + 1, the gain at the summed range put back; then the way
  // back's reverberation (the way out's, which the whole beam gets, comes after).
  double previous = 0.0;
  for (std::size_t m = 0; m < bins; ++m) {
    const double pair_sum = sums[m];
    sums[m] = second_trip * tvg_at_bin[m] * (0.5 * (pair_sum + previous));
    previous = pair_sum;
  }
  AddReverberation(sensor, sums);
  for (std::size_t m = 0; m < bins; ++m) echo_power[m] += sums[m];
}

}  // namespace sonarbench::sim
