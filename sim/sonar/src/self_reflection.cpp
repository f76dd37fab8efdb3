#include "sonarbench/sim/sonar/self_reflection.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "kernels.hpp"

namespace sonarbench::sim {

SelfReflection::SelfReflection(const SensorModel& sensor, std::uint64_t run_seed)
    : acoustics_(sensor.acoustics), step_angle_rad_(sensor.geometry.step_angle_rad) {
  const Acoustics& a = acoustics_;
  const std::size_t n = a.self_reflection.profile_db.size();
  const double sigma_a = a.self_reflection.angle_spread_db;
  const double sigma_p = a.self_reflection.ping_spread_db;
  // The ping's spread covers the ringing's bins: those whose centre lies within its range.
  ringing_bins_ = n;
  if (a.self_reflection.ringing_range_m > 0.0) {
    ringing_bins_ = std::min(
        n,
        static_cast<std::size_t>(std::max(
            0.0, std::ceil(a.self_reflection.ringing_range_m / sensor.geometry.bin_size_m - 0.5))));
  }
  // E[10^(σ z / 10)] = exp(½ (σ ln 10 / 10)²) for z standard normal: divided out, so the
  // profile stays the mean power.
  const auto mean_factor = [&](std::size_t k) {
    const double sigma_k = k < ringing_bins_ ? sigma_p : 0.0;
    return std::exp(0.5 * kNepersPerDecibel * kNepersPerDecibel *
                    (sigma_a * sigma_a + sigma_k * sigma_k));
  };
  turn_ =
      sigma_a > 0.0 ? static_cast<int>(std::llround(2.0 * std::numbers::pi / step_angle_rad_)) : 1;
  const auto turn = static_cast<std::size_t>(turn_);
  by_head_.assign(turn * n, 0.0);
  for (std::size_t j = 0; j < turn; ++j) {
    for (std::size_t k = 0; k < n; ++k) {
      by_head_[j * n + k] = std::pow(10.0, a.self_reflection.profile_db[k] / 10.0) / mean_factor(k);
    }
  }
  if (sigma_a > 0.0 && n > 0) SpreadOverHeadSteps(run_seed);
}

void SelfReflection::SpreadOverHeadSteps(std::uint64_t run_seed) {
  const Acoustics& a = acoustics_;
  const std::size_t n = a.self_reflection.profile_db.size();
  const auto turn = static_cast<std::size_t>(turn_);
  const double sigma_a = a.self_reflection.angle_spread_db;
  // Head step j's draw in bin k: u_jk = (z_jk + z_j,k+1) / √2, the z independent standard normals
  // of Rng(DeriveSeed(seed, j)); then A_jk = Σ_e c_e u_(j+e mod turn),k, c_e ∝ exp(-|e| Δ / θ)
  // with Σ c² = 1, cut at half a turn or where what is left holds under 1e-12 of its power.
  const std::uint64_t seed = DeriveSeed(run_seed, 0x72696e67ULL);  // "ring"
  std::vector<double> u(turn * n);
  for (std::size_t j = 0; j < turn; ++j) {
    Rng rng(DeriveSeed(seed, j));
    double z = rng.Normal();
    for (std::size_t k = 0; k < n; ++k) {
      const double next = rng.Normal();
      u[j * n + k] = (z + next) / std::numbers::sqrt2;
      z = next;
    }
  }
  std::vector<double> kernel{1.0};
  if (a.self_reflection.angle_correlation_deg > 0.0) {
    const double steps =
        a.self_reflection.angle_correlation_deg * std::numbers::pi / 180.0 / step_angle_rad_;
    kernel = ExponentialKernel(steps, (turn_ - 1) / 2);
    double squares = 0.0;
    for (const double c : kernel) squares += c * c;
    for (double& c : kernel) c /= std::sqrt(squares);
  }
  const int reach = static_cast<int>(kernel.size() / 2);
  for (std::size_t j = 0; j < turn; ++j) {
    for (std::size_t k = 0; k < n; ++k) {
      double level = 0.0;
      for (int e = -reach; e <= reach; ++e) {
        const auto from = static_cast<std::size_t>((static_cast<int>(j) + e + turn_) % turn_);
        level += kernel[static_cast<std::size_t>(e + reach)] * u[from * n + k];
      }
      by_head_[j * n + k] *= std::exp(kNepersPerDecibel * sigma_a * level);
    }
  }
}

void SelfReflection::Draw(double head_angle_rad, Rng& ping_rng, std::vector<double>& power) const {
  const std::size_t n = acoustics_.self_reflection.profile_db.size();
  const long long turn = turn_;
  const long long step = std::llround(head_angle_rad / step_angle_rad_);
  const auto j = static_cast<std::size_t>(((step % turn) + turn) % turn);
  power.assign(by_head_.begin() + static_cast<std::ptrdiff_t>(j * n),
               by_head_.begin() + static_cast<std::ptrdiff_t>((j + 1) * n));
  const double sigma_p = acoustics_.self_reflection.ping_spread_db;
  if (sigma_p <= 0.0 || n == 0) return;
  double z = ping_rng.Normal();
  for (std::size_t k = 0; k < ringing_bins_; ++k) {
    const double next = ping_rng.Normal();
    power[k] *= std::exp(kNepersPerDecibel * sigma_p * (z + next) / std::numbers::sqrt2);
    z = next;
  }
}

}  // namespace sonarbench::sim
