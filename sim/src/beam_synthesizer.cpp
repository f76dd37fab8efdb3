#include "sonarbench/sim/beam_synthesizer.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <complex>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sonarbench/sim/pulse_spreader.hpp"
#include "sonarbench/sim/random.hpp"

namespace sonarbench::sim {
namespace {

// The receiver's ceiling (Acoustics::ad_knee, ad_ceiling) on a level x in AD steps, as the AD
// window maps it: x to the knee, then knee + w·tanh((x - knee) / w), w = ceiling - knee (a hard
// clip at the ceiling for w = 0).
double ReceiverCeiling(const Acoustics& a, double x) {
  const double width = a.ad_ceiling - a.ad_knee;
  if (x <= a.ad_knee) return x;
  if (width <= 0.0) return a.ad_ceiling;
  return a.ad_knee + width * std::tanh((x - a.ad_knee) / width);
}

// Its inverse: the least x whose output reaches y; infinite where the ceiling keeps it from y.
double UnderCeiling(const Acoustics& a, double y) {
  const double width = a.ad_ceiling - a.ad_knee;
  if (y <= a.ad_knee) return y;
  if (y >= a.ad_ceiling) return std::numeric_limits<double>::infinity();
  return a.ad_knee + width * std::atanh((y - a.ad_knee) / width);
}

// c_e = exp(-|e| / steps) for |e| up to `max_reach` or to where what is left holds under 1e-12
// of the power, whichever is nearer (entry e + reach): the kernel that makes draws e-fold their
// correlation over `steps` head steps.
std::vector<double> ExponentialKernel(double steps, int max_reach) {
  const int reach = std::min(static_cast<int>(std::ceil(steps * std::log(1e12) / 2.0)), max_reach);
  std::vector<double> kernel(2 * static_cast<std::size_t>(reach) + 1);
  for (int e = -reach; e <= reach; ++e) {
    kernel[static_cast<std::size_t>(e + reach)] = std::exp(-std::abs(e) / steps);
  }
  return kernel;
}

}  // namespace

BeamSynthesizer::BeamSynthesizer(const SensorModel& sensor, const RayTracer& tracer,
                                 std::vector<Material> materials_by_mesh, std::uint64_t run_seed,
                                 const VehicleParts& vehicle)
    : sensor_(sensor),
      tracer_(tracer),
      materials_by_mesh_(std::move(materials_by_mesh)),
      vehicle_first_mesh_(static_cast<std::uint32_t>(materials_by_mesh_.size())),
      place_seed_(DeriveSeed(run_seed, 0x706c616365ULL)),
      rough_mirrors_(std::ranges::any_of(
          materials_by_mesh_,
          [](const Material& m) { return m.specular > 0.0 && m.specular_spread_rad > 0.0; })),
      scene_glints_(std::ranges::any_of(materials_by_mesh_,
                                        [](const Material& m) { return m.glint > 0.0; })) {
  if (vehicle.meshes.size() != vehicle.materials.size()) {
    throw std::invalid_argument("BeamSynthesizer: " + std::to_string(vehicle.meshes.size()) +
                                " vehicle meshes but " + std::to_string(vehicle.materials.size()) +
                                " materials");
  }
  if (!vehicle.meshes.empty()) {
    vehicle_tracer_ = std::make_shared<const RayTracer>(vehicle.meshes);
    materials_by_mesh_.insert(materials_by_mesh_.end(), vehicle.materials.begin(),
                              vehicle.materials.end());
  }
  // A bin's speckle is the coherent sum of the scatterers its range response covers: the pulse
  // and, with skirts, one e-folding of each; or the range a scene sets.
  const Acoustics& acoustics = sensor_.acoustics;
  const double speckle_range_m =
      acoustics.speckle_window_m > 0.0
          ? acoustics.speckle_window_m
          : acoustics.pulse_length_m + 2.0 * acoustics.pulse_skirt_length_m;
  speckle_window_ =
      static_cast<int>(std::max(1L, std::lround(speckle_range_m / sensor_.geometry.bin_size_m)));
  // Sector d's share of the two-way horizontal pattern exp(-θ²/2σ²), σ = w_h / √(8 ln 2): the
  // normal distribution's mass over [(d - ½) Δ, (d + ½) Δ], Δ the head step.
  {
    const mapping::SensorGeometry& g = sensor_.geometry;
    const double sigma = g.beam_width_horizontal_rad / std::sqrt(8.0 * std::log(2.0));
    const auto cdf = [&](double x) { return 0.5 * std::erfc(-x / (sigma * std::sqrt(2.0))); };
    sector_weights_.assign(2 * kPatternReach + 1, 0.0);
    double total = 0.0;
    for (int d = -kPatternReach; d <= kPatternReach; ++d) {
      const double share = cdf((d + 0.5) * g.step_angle_rad) - cdf((d - 0.5) * g.step_angle_rad);
      if (share < 1e-3) continue;
      sector_weights_[static_cast<std::size_t>(d + kPatternReach)] = share;
      total += share;
    }
    for (double& w : sector_weights_) w = std::sqrt(w / total);
    if (acoustics.speckle_angular_correlation_deg > 0.0) CorrelateSectors();
    // The beam's own scatterers' share, after the sectors' (SeedPlace seeds it last).
    if (const double own = acoustics.speckle_own_share; own > 0.0) {
      for (double& w : sector_weights_) w *= std::sqrt(1.0 - own);
      sector_weights_.push_back(std::sqrt(own));
    }
  }
  if (sensor_.acoustics.second_trip_db > -100.0) {
    second_trip_ = std::pow(10.0, sensor_.acoustics.second_trip_db / 10.0);
  }
  {
    const Acoustics& a = sensor_.acoustics;
    const mapping::SensorGeometry& g = sensor_.geometry;
    const double noise = std::pow(10.0, a.noise_level_db / 10.0);
    const double before_tvg =
        a.noise_before_tvg_db > -100.0 ? std::pow(10.0, a.noise_before_tvg_db / 10.0) : 0.0;
    for (int i = 0; i < g.num_bins; ++i) {
      const double r = (i + 0.5) * g.bin_size_m;
      tvg_at_bin_.push_back(std::pow(r, a.tvg_db_per_decade / 10.0));
      untvg_at_bin_.push_back(1.0 / tvg_at_bin_.back());
      noise_at_bin_.push_back(noise + before_tvg * tvg_at_bin_.back());
    }
  }
  TabulateSelfReflection(run_seed);
  // Quantise rounds half up: the converter's reading q begins where the output reaches q - 0.5
  // of its steps (255 / ad_levels intensity units each), at the level the ceiling's inverse
  // gives; the readings past the ceiling, or past ad_levels, are never reached.
  const Acoustics& a = sensor_.acoustics;
  const double reading_steps = 255.0 / a.ad_levels;  // 1 exactly for 255 levels
  ad_thresholds_.fill(std::numeric_limits<double>::infinity());
  ad_thresholds_[0] = 0.0;
  ad_top_reading_ = 0;
  for (int q = 1; q <= a.ad_levels; ++q) {
    const double steps = UnderCeiling(a, (q - 0.5) * reading_steps);
    const double level_db = a.ad_low_db + steps / 255.0 * a.ad_span_db;
    ad_thresholds_[static_cast<std::size_t>(q)] =
        std::isinf(steps) ? steps : std::pow(10.0, level_db / 10.0);
    if (!std::isinf(steps)) ad_top_reading_ = static_cast<std::uint8_t>(q);
  }
  for (int q = 0; q < 256; ++q) {
    ad_reported_[static_cast<std::size_t>(q)] =
        static_cast<std::uint8_t>(std::min(q, a.ad_levels) * 255 / a.ad_levels);
  }
  // Buckets of positive doubles by their exponent and top mantissa bits: with 2^m per octave,
  // a bucket spans 3.01/2^m dB; m is chosen so that spans half a reading's step, or less.
  const double step_db = a.ad_span_db / a.ad_levels;
  int mantissa_bits = 0;
  while (mantissa_bits < 20 &&
         10.0 * std::log10(2.0) / std::ldexp(1.0, mantissa_bits) > 0.5 * step_db) {
    ++mantissa_bits;
  }
  ad_bucket_shift_ = 52 - mantissa_bits;
  ad_first_bucket_ = std::bit_cast<std::uint64_t>(ad_thresholds_[1]) >> ad_bucket_shift_;
  const std::uint64_t last_bucket =
      std::bit_cast<std::uint64_t>(ad_thresholds_[ad_top_reading_]) >> ad_bucket_shift_;
  ad_bucket_steps_.resize(last_bucket - ad_first_bucket_ + 1);
  unsigned q = 0;
  for (std::uint64_t b = ad_first_bucket_; b <= last_bucket; ++b) {
    const double start = std::bit_cast<double>(b << ad_bucket_shift_);
    while (q < ad_top_reading_ && start >= ad_thresholds_[q + 1]) ++q;
    ad_bucket_steps_[b - ad_first_bucket_] = static_cast<std::uint8_t>(q);
  }

  const double range_step_m = sensor_.geometry.bin_size_m / 16.0;
  range_steps_per_m_ = 16.0 / sensor_.geometry.bin_size_m;
  const auto steps =
      static_cast<std::size_t>(std::ceil(sensor_.geometry.MaxRangeM() / range_step_m));
  range_loss_.resize(steps + 2);
  for (std::size_t k = 0; k < range_loss_.size(); ++k) {
    range_loss_[k] = RangeLoss(static_cast<double>(k) * range_step_m);
  }

  // Slot a of stratum i sits at (i + (a + ½)/slots)/strata of the aperture (scaled by the
  // aperture scale), centred on the axis; its pattern factor is exp(-k · angle²), so the two
  // directions' factors multiply to the two-way pattern.
  const mapping::SensorGeometry& g = sensor_.geometry;
  pattern_k_h_ = 4.0 * std::log(2.0) / (g.beam_width_horizontal_rad * g.beam_width_horizontal_rad);
  pattern_k_v_ = 4.0 * std::log(2.0) / (g.beam_width_vertical_rad * g.beam_width_vertical_rad);
  if (a.sidelobe_extent_deg > 0.0) {
    sidelobe_level_ = std::pow(10.0, a.sidelobe_db / 10.0);
    sidelobe_width2_ = std::pow(a.sidelobe_width_deg * mapping::kDegToRad, 2);
    sidelobe_extent_rad_ = a.sidelobe_extent_deg * mapping::kDegToRad;
    // 1e-9 over: past it atan2 can round no azimuth back inside the extent.
    sidelobe_extent_sin2_ = std::pow(std::sin(sidelobe_extent_rad_), 2) * (1.0 + 1e-9);
  }
  // The slots of `strata` strata: slot a of stratum i at the angle angle_at((i + (a + ½)/slots)
  // / strata), with the factor factor(angle).
  const auto tabulate = [](int strata, const auto& angle_at, const auto& factor) {
    std::vector<JitterSlot> slots;
    for (int i = 0; i < strata; ++i) {
      for (int slot = 0; slot < kJitterSlots; ++slot) {
        const double angle = angle_at((i + (slot + 0.5) / kJitterSlots) / strata);
        slots.push_back({std::sin(angle), std::cos(angle), factor(angle)});
      }
    }
    return slots;
  };
  const auto centred = [](double aperture) {
    return [aperture](double fraction) { return (fraction - 0.5) * aperture; };
  };
  const auto horizontal = [&](double angle) {
    return std::exp(-pattern_k_h_ * angle * angle) + SidelobePattern(angle);
  };
  const auto vertical = [&](double angle) { return std::exp(-pattern_k_v_ * angle * angle); };
  const double aperture_h = a.aperture_scale_horizontal * g.beam_width_horizontal_rad;
  const double aperture_v = a.aperture_scale_vertical * g.beam_width_vertical_rad;
  horizontal_slots_ = tabulate(a.rays_horizontal, centred(aperture_h), horizontal);
  vertical_slots_ = tabulate(a.rays_vertical, centred(aperture_v), vertical);
  if (a.sidelobe_extent_deg > 0.0) {
    // A sidelobe ray stands for a stratum wider than a main-lobe ray's in both directions: its
    // pattern factor carries the ratio of their solid angles, so the weights stay the pattern's
    // integral over the rays' strata.
    const double span = sidelobe_extent_rad_ - 0.5 * aperture_h;
    const double area = (span / a.sidelobe_rays_horizontal) / (aperture_h / a.rays_horizontal) *
                        (static_cast<double>(a.rays_vertical) / a.sidelobe_rays_vertical);
    sidelobe_horizontal_slots_ = tabulate(
        a.sidelobe_rays_horizontal,
        [&](double fraction) { return 0.5 * aperture_h + fraction * span; },
        [&](double angle) { return area * horizontal(angle); });
    sidelobe_vertical_slots_ = tabulate(a.sidelobe_rays_vertical, centred(aperture_v), vertical);
  }
  if (a.back_lobe_width_deg > 0.0) {
    back_level_ = std::pow(10.0, a.back_lobe_db / 10.0);
    const double sigma = a.back_lobe_width_deg * mapping::kDegToRad;
    back_k_ = 1.0 / (sigma * sigma);
    // Strata over ±min(3σ, 90°) about the axis behind in both directions. A stratum at
    // elevation ε spans Δφ cos ε · Δε of solid angle; a main-lobe ray stands for Δθ · Δε_main.
    const double span = 2.0 * std::min(3.0 * sigma, 0.5 * std::numbers::pi);
    const double stratum = span / a.back_lobe_rays;
    const double level = back_level_ * back_level_;
    back_horizontal_slots_ = tabulate(a.back_lobe_rays, centred(span), [&](double angle) {
      return level * std::exp(-back_k_ * angle * angle) * stratum /
             (aperture_h / a.rays_horizontal);
    });
    back_vertical_slots_ = tabulate(a.back_lobe_rays, centred(span), [&](double angle) {
      return std::exp(-back_k_ * angle * angle) * std::cos(angle) * stratum /
             (aperture_v / a.rays_vertical);
    });
  }

  if (a.level_jitter_db > 0.0) {
    // a² + b² = 1 and a b = ρ: a² and b² are the roots of x² - x + ρ².
    const double rho = a.level_jitter_bin_correlation;
    const double root = std::sqrt(1.0 - 4.0 * rho * rho);
    const double own = rho > 0.0 ? std::sqrt(0.5 * (1.0 + root)) : 1.0;
    const double shared = std::sqrt(0.5 * (1.0 - root));
    level_jitter_factors_.reserve(kLevelJitters);
    for (int i = 0; i < kLevelJitters; ++i) {
      const double z = NormalQuantile((i + 0.5) / kLevelJitters);
      level_jitter_factors_.push_back(std::pow(10.0, a.level_jitter_db * own * z / 10.0));
      if (rho > 0.0) {
        level_jitter_next_factors_.push_back(std::pow(10.0, a.level_jitter_db * shared * z / 10.0));
      }
    }
  }

  // A standard 2-D Gaussian offset has a Rayleigh radius, P(radius ≤ ρ) = 1 - exp(-ρ²/2), and a
  // uniform direction: radius quantiles times evenly spaced directions.
  spread_offsets_.reserve(kSpreadOffsets);
  for (int i = 0; i < 64; ++i) {
    const double radius = std::sqrt(-2.0 * std::log(1.0 - (i + 0.5) / 64.0));
    for (int j = 0; j < 64; ++j) {
      const double angle = 2.0 * std::numbers::pi * (j + 0.5) / 64.0;
      spread_offsets_.emplace_back(static_cast<float>(radius * std::cos(angle)),
                                   static_cast<float>(radius * std::sin(angle)));
    }
  }
}

void BeamSynthesizer::TabulateSelfReflection(std::uint64_t run_seed) {
  const Acoustics& a = sensor_.acoustics;
  const std::size_t n = a.self_reflection_db.size();
  const double sigma_a = a.self_reflection_angle_spread_db;
  const double sigma_p = a.self_reflection_ping_spread_db;
  // The ping's spread covers the ringing's bins: those whose centre lies within its range.
  self_reflection_ringing_bins_ = n;
  if (a.self_reflection_ringing_range_m > 0.0) {
    self_reflection_ringing_bins_ = std::min(
        n, static_cast<std::size_t>(std::max(
               0.0,
               std::ceil(a.self_reflection_ringing_range_m / sensor_.geometry.bin_size_m - 0.5))));
  }
  // E[10^(σ z / 10)] = exp(½ (σ ln 10 / 10)²) for z standard normal: divided out, so the
  // profile stays the mean power.
  const auto mean_factor = [&](std::size_t k) {
    const double sigma_k = k < self_reflection_ringing_bins_ ? sigma_p : 0.0;
    return std::exp(0.5 * kNepersPerDecibel * kNepersPerDecibel *
                    (sigma_a * sigma_a + sigma_k * sigma_k));
  };
  self_reflection_turn_ =
      sigma_a > 0.0
          ? static_cast<int>(std::llround(2.0 * std::numbers::pi / sensor_.geometry.step_angle_rad))
          : 1;
  const auto turn = static_cast<std::size_t>(self_reflection_turn_);
  self_reflection_by_head_.assign(turn * n, 0.0);
  for (std::size_t j = 0; j < turn; ++j) {
    for (std::size_t k = 0; k < n; ++k) {
      self_reflection_by_head_[j * n + k] =
          std::pow(10.0, a.self_reflection_db[k] / 10.0) / mean_factor(k);
    }
  }
  if (sigma_a <= 0.0 || n == 0) return;

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
  if (a.self_reflection_angle_correlation_deg > 0.0) {
    const double steps = a.self_reflection_angle_correlation_deg * std::numbers::pi / 180.0 /
                         sensor_.geometry.step_angle_rad;
    kernel = ExponentialKernel(steps, (self_reflection_turn_ - 1) / 2);
    double squares = 0.0;
    for (const double c : kernel) squares += c * c;
    for (double& c : kernel) c /= std::sqrt(squares);
  }
  const int reach = static_cast<int>(kernel.size() / 2);
  for (std::size_t j = 0; j < turn; ++j) {
    for (std::size_t k = 0; k < n; ++k) {
      double level = 0.0;
      for (int e = -reach; e <= reach; ++e) {
        const auto from = static_cast<std::size_t>(
            (static_cast<int>(j) + e + self_reflection_turn_) % self_reflection_turn_);
        level += kernel[static_cast<std::size_t>(e + reach)] * u[from * n + k];
      }
      self_reflection_by_head_[j * n + k] *= std::exp(kNepersPerDecibel * sigma_a * level);
    }
  }
}

void BeamSynthesizer::SelfReflection(double head_angle_rad, Rng& ping_rng,
                                     std::vector<double>& power) const {
  const std::size_t n = sensor_.acoustics.self_reflection_db.size();
  const long long turn = self_reflection_turn_;
  const long long step = std::llround(head_angle_rad / sensor_.geometry.step_angle_rad);
  const auto j = static_cast<std::size_t>(((step % turn) + turn) % turn);
  power.assign(self_reflection_by_head_.begin() + static_cast<std::ptrdiff_t>(j * n),
               self_reflection_by_head_.begin() + static_cast<std::ptrdiff_t>((j + 1) * n));
  const double sigma_p = sensor_.acoustics.self_reflection_ping_spread_db;
  if (sigma_p <= 0.0 || n == 0) return;
  double z = ping_rng.Normal();
  for (std::size_t k = 0; k < self_reflection_ringing_bins_; ++k) {
    const double next = ping_rng.Normal();
    power[k] *= std::exp(kNepersPerDecibel * sigma_p * (z + next) / std::numbers::sqrt2);
    z = next;
  }
}

double BeamSynthesizer::NormalQuantile(double u) {
  double low = -8.0;
  double high = 8.0;
  for (int i = 0; i < 64; ++i) {
    const double mid = 0.5 * (low + high);
    (0.5 * std::erfc(-mid / std::numbers::sqrt2) < u ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

void BeamSynthesizer::CorrelateSectors() {
  const mapping::SensorGeometry& g = sensor_.geometry;
  // Sector s's scatterers are Σ_e c_e u_{s+e}, the u independent and c_e ∝ exp(-|e| Δ / θ)
  // (cut where what is left holds under 1e-12 of its power; normalised with the weights below),
  // so a beam hears Σ_d w_d Σ_e c_e u_{a+d+e}: its weights on the independent sectors are w
  // convolved with c.
  const double steps = sensor_.acoustics.speckle_angular_correlation_deg * std::numbers::pi /
                       180.0 / g.step_angle_rad;
  const std::vector<double> kernel = ExponentialKernel(steps, std::numeric_limits<int>::max());
  const int kernel_reach = static_cast<int>(kernel.size() / 2);
  const int reach = kPatternReach + kernel_reach;
  std::vector<double> weights(2 * static_cast<std::size_t>(reach) + 1, 0.0);
  for (int d = -kPatternReach; d <= kPatternReach; ++d) {
    const double w = sector_weights_[static_cast<std::size_t>(d + kPatternReach)];
    for (int e = -kernel_reach; e <= kernel_reach; ++e) {
      weights[static_cast<std::size_t>(d + e + reach)] +=
          w * kernel[static_cast<std::size_t>(e + kernel_reach)];
    }
  }
  // The sectors beyond ±kept dropped while they hold under 1e-3 of the power in all, and never
  // more sectors than a turn has (each sector once).
  double total = 0.0;
  for (const double w : weights) total += w * w;
  const long long turn = std::llround(2.0 * std::numbers::pi / g.step_angle_rad);
  int kept = std::min<int>(reach, static_cast<int>((turn - 1) / 2));
  const auto square = [&](int d) {
    const double w = weights[static_cast<std::size_t>(d + reach)];
    return w * w;
  };
  double dropped = 0.0;
  for (int d = reach; d > kept; --d) dropped += square(d) + square(-d);
  while (kept > 0 && dropped + square(kept) + square(-kept) < 1e-3 * total) {
    dropped += square(kept) + square(-kept);
    --kept;
  }
  sector_weights_.assign(weights.begin() + (reach - kept), weights.begin() + (reach + kept + 1));
  double kept_total = 0.0;
  for (const double w : sector_weights_) kept_total += w * w;
  for (double& w : sector_weights_) w /= std::sqrt(kept_total);
}

Eigen::Vector3f BeamSynthesizer::Tilt(const Eigen::Vector3f& unit, float sigma, Rng& rng) const {
  static_assert((kSpreadOffsets & (kSpreadOffsets - 1)) == 0, "offsets are picked by a mask");
  const Eigen::Vector2f tilt = sigma * spread_offsets_[(rng.Next() >> 32) & (kSpreadOffsets - 1)];
  // Two unit directions across `unit`, orthonormal with it by construction (Duff et al.,
  // "Building an orthonormal basis, revisited", JCGT 2017: one division, no root), so
  // unit + tilt has length √(1 + |tilt|²).
  const float sign = std::copysign(1.0f, unit.z());
  const float a = -1.0f / (sign + unit.z());
  const float b = unit.x() * unit.y() * a;
  const Eigen::Vector3f across(1.0f + sign * unit.x() * unit.x() * a, sign * b, -sign * unit.x());
  const Eigen::Vector3f across_too(b, sign + unit.y() * unit.y() * a, -unit.y());
  const float length = 1.0f / std::sqrt(1.0f + tilt.squaredNorm());
  return (unit + tilt.x() * across + tilt.y() * across_too) * length;
}

Eigen::Vector3f BeamSynthesizer::SpreadMirror(const Eigen::Vector3f& mirror,
                                              const Eigen::Vector3f& normal,
                                              const Material& material, Rng& rng) const {
  if (material.specular_spread_rad <= 0.0) return mirror;
  Eigen::Vector3f spread = Tilt(mirror, static_cast<float>(material.specular_spread_rad), rng);
  // A direction into the surface is mirrored back out of it.
  const float side = spread.dot(normal);
  if ((side > 0.0f) != (mirror.dot(normal) > 0.0f)) spread -= 2.0f * side * normal;
  return spread;
}

double BeamSynthesizer::RangeLoss(double range_m) const {
  const Acoustics& a = sensor_.acoustics;
  const double spreading_exponent = (a.spreading_db_per_decade - a.tvg_db_per_decade) / 10.0;
  const double absorption_per_m = a.absorption_db_per_m * std::log(10.0) / 10.0;
  const double exponent =
      (spreading_exponent != 0.0 ? spreading_exponent * std::log(range_m) : 0.0) +
      absorption_per_m * range_m;
  return std::exp(-exponent);
}

namespace {

// QuantisePower's tables, held in locals by a loop over bins: an 8-bit store may alias anything,
// so a loop reading them through `this` reloads them after every level it writes.
struct AdSteps {
  const double* thresholds;
  const std::uint8_t* bucket_steps;
  const std::uint8_t* reported;
  std::uint64_t first_bucket;
  int bucket_shift;
  std::uint8_t top;  // the highest reading the ceiling lets a level reach

  // The value reported for the largest reading q with thresholds[q] <= power (the thresholds
  // increase; q = 0 below them): the table gives q at the start of the power's bucket, and the
  // power may pass the next threshold within the bucket (a compare added, not branched on: it is
  // a coin toss). Buckets of half a reading's step hold at most one threshold; the loop keeps it
  // exact for wider ones.
  std::uint8_t operator()(double power) const {
    if (!(power >= thresholds[1])) return reported[0];
    if (power >= thresholds[top]) return reported[top];
    const std::uint64_t bucket =
        (std::bit_cast<std::uint64_t>(power) >> bucket_shift) - first_bucket;
    unsigned q = bucket_steps[bucket];
    q += power >= thresholds[q + 1] ? 1 : 0;
    while (power >= thresholds[q + 1]) ++q;
    return reported[q];
  }
};

}  // namespace

std::uint8_t BeamSynthesizer::QuantisePower(double power) const {
  return AdSteps{.thresholds = ad_thresholds_.data(),
                 .bucket_steps = ad_bucket_steps_.data(),
                 .reported = ad_reported_.data(),
                 .first_bucket = ad_first_bucket_,
                 .bucket_shift = ad_bucket_shift_,
                 .top = ad_top_reading_}(power);
}

namespace {

// A circular complex Gaussian of unit power: an amplitude √E, E exponential, and one of
// BeamSynthesizer::kSpecklePhases evenly spaced phases from the top bits of a second draw.
std::complex<double> DrawPhasor(Rng& rng) {
  static const std::array<std::complex<double>, BeamSynthesizer::kSpecklePhases> phases = [] {
    std::array<std::complex<double>, BeamSynthesizer::kSpecklePhases> table;
    for (int i = 0; i < BeamSynthesizer::kSpecklePhases; ++i) {
      table[static_cast<std::size_t>(i)] =
          std::polar(1.0, 2.0 * std::numbers::pi * i / BeamSynthesizer::kSpecklePhases);
    }
    return table;
  }();
  static_assert(BeamSynthesizer::kSpecklePhases == 1 << 10, "a phase is a draw's top 10 bits");
  const double amplitude = std::sqrt(rng.Exponential());
  return amplitude * phases[static_cast<std::size_t>(rng.Next() >> 54)];
}

// factors[k] = |Σ_{j=k..k+L-1} amplitudes[j]|² / L, for amplitudes.size() = factors.size() + L - 1.
void WindowPower(std::span<const std::complex<double>> amplitudes, std::size_t window,
                 std::span<double> factors) {
  std::complex<double> sum = 0.0;
  for (std::size_t j = 0; j + 1 < window; ++j) sum += amplitudes[j];
  const double scale = 1.0 / static_cast<double>(window);
  for (std::size_t k = 0; k < factors.size(); ++k) {
    sum += amplitudes[k + window - 1];
    factors[k] = std::norm(sum) * scale;
    sum -= amplitudes[k];
  }
}

// The mean of `looks` independent looks' factors, each drawn by `look(factors, l)`; look 0
// alone written straight into `factors`.
template <typename Look>
void AverageLooks(std::span<double> factors, int looks, Look look) {
  look(factors, 0);
  if (looks <= 1) return;
  thread_local std::vector<double> further;
  further.resize(factors.size());
  for (int l = 1; l < looks; ++l) {
    look(std::span(further), l);
    for (std::size_t k = 0; k < factors.size(); ++k) factors[k] += further[k];
  }
  const double per_look = 1.0 / looks;
  for (double& f : factors) f *= per_look;
}

}  // namespace

void BeamSynthesizer::CorrelatedSpeckle(std::span<double> factors, int window, Rng& rng,
                                        int looks) {
  AverageLooks(factors, looks, [&](std::span<double> out, int) {
    if (window <= 1) {
      for (double& f : out) f = rng.Exponential();
      return;
    }
    const auto size = static_cast<std::size_t>(window);
    thread_local std::vector<std::complex<double>> amplitudes;
    amplitudes.resize(out.size() + size - 1);
    for (auto& a : amplitudes) a = DrawPhasor(rng);
    WindowPower(amplitudes, size, out);
  });
}

namespace {

// ThreadSanitizer instruments the clones' resolver, which runs before it starts: one baseline.
#if defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define SONARBENCH_NO_CLONES
#endif
#endif
#ifdef SONARBENCH_NO_CLONES
#define SONARBENCH_CLONES
#else
#define SONARBENCH_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#endif

// to[k] += w · from[k] for every k. Compiled for AVX-512 and AVX2 besides the baseline, picked
// when the program starts: the loop is the same element-wise products and sums at any vector
// width, and the file is built without fused multiply-adds (sim/CMakeLists.txt), so every
// clone gives the same bits; the wider ones in a fraction of the time (synthesis_bench).
SONARBENCH_CLONES void AddScaled(std::span<double> to, std::span<const double> from, double w) {
  for (std::size_t k = 0; k < to.size(); ++k) to[k] += w * from[k];
}

}  // namespace

namespace {

// SectorSpeckle's look `look` alone.
void SectorSpeckleLook(std::span<double> factors, int window,
                       std::span<const double> amplitude_weights,
                       std::span<const std::uint64_t> sector_seeds, int look) {
  const auto size = static_cast<std::size_t>(std::max(window, 1));
  const std::size_t length = factors.size() + size - 1;
  // A sector's phasors, kept per thread and look for the next beams: a static sonar's
  // neighbouring beams share all but one of their sectors. Keyed by seed and length, so what a
  // beam gets does not depend on which beams the thread did before. The least recently used
  // goes first: a beam's own sector (Acoustics::speckle_own_share), which no other beam hears,
  // then leaves after one beam instead of pushing out sectors the next beam needs.
  struct Sector {
    std::uint64_t seed = 0;
    std::uint64_t used = 0;  // the cache's clock when last asked for; 0 if never
    std::vector<std::complex<double>> phasors;
  };
  struct Cache {
    std::vector<Sector> sectors;
    std::uint64_t clock = 0;
  };
  thread_local std::vector<Cache> caches;
  if (caches.size() <= static_cast<std::size_t>(look)) {
    caches.resize(static_cast<std::size_t>(look) + 1);
  }
  Cache& cache = caches[static_cast<std::size_t>(look)];
  if (cache.sectors.size() < amplitude_weights.size() + 1) {
    cache.sectors.resize(amplitude_weights.size() + 1);
  }
  const auto phasors_of =
      [&](std::uint64_t sector_seed) -> const std::vector<std::complex<double>>& {
    const std::uint64_t seed =
        look == 0 ? sector_seed : DeriveSeed(sector_seed, static_cast<std::uint64_t>(look));
    ++cache.clock;
    Sector* oldest = &cache.sectors.front();
    for (Sector& sector : cache.sectors) {
      if (sector.seed == seed && sector.phasors.size() == length) {
        sector.used = cache.clock;
        return sector.phasors;
      }
      if (sector.used < oldest->used) oldest = &sector;
    }
    Sector& sector = *oldest;
    sector.used = cache.clock;
    sector.seed = seed;
    sector.phasors.resize(length);
    Rng rng(seed);
    for (auto& z : sector.phasors) z = DrawPhasor(rng);
    return sector.phasors;
  };
  thread_local std::vector<std::complex<double>> amplitudes;
  amplitudes.assign(length, 0.0);
  for (std::size_t d = 0; d < amplitude_weights.size(); ++d) {
    const double w = amplitude_weights[d];
    if (w == 0.0) continue;
    const std::vector<std::complex<double>>& z = phasors_of(sector_seeds[d]);
    // A complex number is an array of its real and imaginary parts ([complex.numbers]).
    AddScaled(std::span(reinterpret_cast<double*>(amplitudes.data()), 2 * length),
              std::span(reinterpret_cast<const double*>(z.data()), 2 * length), w);
  }
  WindowPower(amplitudes, size, factors);
}

}  // namespace

void BeamSynthesizer::SectorSpeckle(std::span<double> factors, int window,
                                    std::span<const double> amplitude_weights,
                                    std::span<const std::uint64_t> sector_seeds, int looks) {
  AverageLooks(factors, looks, [&](std::span<double> out, int look) {
    SectorSpeckleLook(out, window, amplitude_weights, sector_seeds, look);
  });
}

void BeamSynthesizer::AddPulseSkirts(std::vector<double>& echo_power) const {
  const Acoustics& a = sensor_.acoustics;
  if (a.pulse_skirt_length_m <= 0.0) return;
  const double q = std::exp(-sensor_.geometry.bin_size_m / a.pulse_skirt_length_m);
  // The skirts hold S = 10^(db/10) of the pulse's power, shared out of the echo's: the pulse
  // keeps 1 / (1 + S), each side S / (2 (1 + S)), a geometric series of ratio q from q.
  const double skirts_share = std::pow(10.0, a.pulse_skirt_db / 10.0);
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

void BeamSynthesizer::AddReverberation(std::vector<double>& echo_power) const {
  const Acoustics& a = sensor_.acoustics;
  if (a.reverberation_length_m <= 0.0) return;
  const double keep = std::exp(-sensor_.geometry.bin_size_m / a.reverberation_length_m);
  const double feed = std::pow(10.0, a.reverberation_db / 10.0) * (1.0 - keep);
  double tail = 0.0;
  for (double& power : echo_power) {
    const double echo = power;
    power += tail;
    tail = keep * tail + feed * echo;
  }
}

void BeamSynthesizer::AddSecondTrip(std::vector<double>& echo_power,
                                    std::span<const double> impulse_power) const {
  if (second_trip_ <= 0.0) return;
  const std::size_t bins = std::min({echo_power.size(), impulse_power.size(), tvg_at_bin_.size()});
  // Each trip's powers with the time-varied gain taken off.
  thread_local std::vector<double> out;
  thread_local std::vector<double> back;
  thread_local std::vector<double> sums;
  out.resize(bins);
  back.resize(bins);
  double largest_out = 0.0;
  double largest_back = 0.0;
  for (std::size_t i = 0; i < bins; ++i) {
    out[i] = echo_power[i] * untvg_at_bin_[i];
    back[i] = impulse_power[i] * untvg_at_bin_[i];
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
    sums[m] = second_trip_ * tvg_at_bin_[m] * (0.5 * (pair_sum + previous));
    previous = pair_sum;
  }
  AddReverberation(sums);
  for (std::size_t m = 0; m < bins; ++m) echo_power[m] += sums[m];
}

namespace {

// A bistatic return whose weight, one ray's, is under this is not worth the occlusion ray. A
// perfect reflector filling the beam sums all its rays' pattern weights (about 420 for the
// Micron's 640), so one such return lies about 86 dB under that echo, and a beam's few thousand
// of them together about 50 dB: under the AD window's 40 dB.
constexpr double kNegligibleWeight = 1e-6;

// cosⁿ, with the exponents scenes use most spared a pow().
double CosPower(double c, double n) {
  if (n == 1.0) return c;
  if (n == 0.5) return std::sqrt(c);
  if (n == 2.0) return c * c;
  return std::pow(c, n);
}

// An upper bound on exp(-x) within a factor of 2 and without exp(): 2^-⌊x log₂e⌋, built from
// its exponent bits (0 past 2^-1000; infinity for x < 0, where it is not needed).
double ExpBound(double x) {
  const double octaves = std::floor(x * std::numbers::log2e);
  if (!(octaves >= 0.0)) return std::numeric_limits<double>::infinity();
  if (octaves >= 1000.0) return 0.0;
  return std::bit_cast<double>(static_cast<std::uint64_t>(1023 - static_cast<int>(octaves)) << 52);
}

// A rough mirror's glint towards a receiver whose direction makes cos_alpha with the mirror
// direction (Material::glint): g exp(-α²/2σ²); 0 without one.
double Glint(const Material& m, double cos_alpha) {
  if (m.glint <= 0.0) return 0.0;
  const double alpha = std::acos(std::clamp(cos_alpha, -1.0, 1.0));
  const double z = alpha / m.specular_spread_rad;
  return m.glint * std::exp(-0.5 * z * z);
}

}  // namespace

std::uint8_t BeamSynthesizer::Quantise(double level_db) const {
  const Acoustics& a = sensor_.acoustics;
  const double output = ReceiverCeiling(a, (level_db - a.ad_low_db) / a.ad_span_db * 255.0);
  const double reading = std::round(output / (255.0 / a.ad_levels));  // / 1 for 255 levels
  return ad_reported_[static_cast<std::size_t>(std::clamp(reading, 0.0, 255.0))];
}

double BeamSynthesizer::BackLobePattern(const Eigen::Vector3d& u, double blur) const {
  if (back_level_ <= 0.0) return 0.0;
  const double phi = std::atan2(u.y(), -u.x());
  const double epsilon = std::asin(std::clamp(u.z(), -1.0, 1.0));
  // exp(-k θ²/2) per direction, each averaged over a Gaussian offset of variance `blur`.
  const double wide = 1.0 + back_k_ * blur;
  return back_level_ * std::exp(-0.5 * back_k_ * (phi * phi + epsilon * epsilon) / wide) / wide;
}

double BeamSynthesizer::OneWayPatternTowards(const Eigen::Vector3d& u, double blur) const {
  if (u.x() <= 0.0) return BackLobePattern(u, blur);
  const double k_h = pattern_k_h_;
  const double k_v = pattern_k_v_;
  const double theta = std::atan2(u.y(), u.x());
  const double epsilon = std::asin(std::clamp(u.z(), -1.0, 1.0));
  const double wide_h = 1.0 + k_h * blur;
  const double wide_v = 1.0 + k_v * blur;
  const double sidelobe = SidelobePattern(theta);
  if (sidelobe <= 0.0) {
    return std::exp(-0.5 * (k_h * theta * theta / wide_h + k_v * epsilon * epsilon / wide_v)) /
           std::sqrt(wide_h * wide_v);
  }
  // The sidelobes' pedestal is far wider than any blur: added unblurred to the main lobe's
  // two-way power, the one-way the square root of the sum.
  const double main_h = std::exp(-k_h * theta * theta / wide_h) / wide_h;
  return std::sqrt(main_h + sidelobe) * std::exp(-0.5 * k_v * epsilon * epsilon / wide_v) /
         std::sqrt(wide_v);
}

double BeamSynthesizer::OneWayPatternBound(const Eigen::Vector3d& u) const {
  const double across = u.x() * u.x() + u.y() * u.y();
  if (u.x() <= 0.0) {
    if (back_level_ <= 0.0) return 0.0;
    if (across <= 0.0) return back_level_;
    return back_level_ * ExpBound(0.5 * back_k_ * (u.y() * u.y() / across + u.z() * u.z()));
  }
  if (across <= 0.0) return sidelobe_level_ > 0.0 ? std::sqrt(1.0 + sidelobe_level_) : 1.0;
  // Within their extent the sidelobes' pedestal S adds to the two-way main lobe's power, at most
  // 1 + S; past it there is the main lobe alone.
  if (sidelobe_level_ > 0.0 && u.y() * u.y() <= sidelobe_extent_sin2_ * across) {
    return std::sqrt(1.0 + sidelobe_level_) * ExpBound(0.5 * pattern_k_v_ * u.z() * u.z());
  }
  return ExpBound(0.5 * (pattern_k_h_ * u.y() * u.y() / across + pattern_k_v_ * u.z() * u.z()));
}

double BeamSynthesizer::SidelobePattern(double theta) const {
  // Without sidelobes θ_s² is 0 too: return before 0/0 on the axis.
  if (sidelobe_level_ <= 0.0 || !(std::abs(theta) <= sidelobe_extent_rad_)) return 0.0;
  const double falloff = sidelobe_width2_ / (sidelobe_width2_ + theta * theta);
  return sidelobe_level_ * falloff * falloff;
}

double BeamSynthesizer::DrawRays(const Eigen::Matrix3d& R_world_beam, Rng& rng,
                                 std::vector<Eigen::Vector3f>& directions,
                                 std::vector<double>& patterns) const {
  const Acoustics& a = sensor_.acoustics;
  directions.resize(PrimaryRays(a));
  patterns.resize(directions.size());
  double weight_sum = 0.0;
  const Eigen::Vector3d ahead = R_world_beam.col(0);
  const Eigen::Vector3d left = R_world_beam.col(1);
  const Eigen::Vector3d up = R_world_beam.col(2);
  constexpr unsigned kSlotMask = kJitterSlots - 1;
  static_assert((kJitterSlots & kSlotMask) == 0, "slots are picked by masking a draw's bits");
  for (int i = 0, r = 0; i < a.rays_horizontal; ++i) {
    const JitterSlot* stratum_h = &horizontal_slots_[static_cast<std::size_t>(i) * kJitterSlots];
    for (int j = 0; j < a.rays_vertical; ++j, ++r) {
      const std::uint64_t draw = rng.Next();
      const JitterSlot& h = stratum_h[(draw >> 32) & kSlotMask];
      const JitterSlot& v =
          vertical_slots_[static_cast<std::size_t>(j) * kJitterSlots + ((draw >> 48) & kSlotMask)];
      const double pattern = h.weight * v.weight;
      weight_sum += pattern;
      patterns[static_cast<std::size_t>(r)] = pattern;
      directions[static_cast<std::size_t>(r)] =
          (v.cos * (h.cos * ahead + h.sin * left) + v.sin * up).cast<float>();
    }
  }
  // Further strata after the main lobe's, drawn as theirs are: `h_strata` horizontal ones of
  // `h_slots` on the side `side` of the horizontal axis `axis`, each split into `v_strata` of
  // `v_slots`; their weights added to the sum if `counted`.
  std::size_t r = MainLobeRays(a);
  const auto draw_strata = [&](const std::vector<JitterSlot>& h_slots, int h_strata,
                               const std::vector<JitterSlot>& v_slots, int v_strata,
                               const Eigen::Vector3d& axis, double side, bool counted) {
    for (int i = 0; i < h_strata; ++i) {
      const JitterSlot* stratum_h = &h_slots[static_cast<std::size_t>(i) * kJitterSlots];
      for (int j = 0; j < v_strata; ++j, ++r) {
        const std::uint64_t draw = rng.Next();
        const JitterSlot& h = stratum_h[(draw >> 32) & kSlotMask];
        const JitterSlot& v =
            v_slots[static_cast<std::size_t>(j) * kJitterSlots + ((draw >> 48) & kSlotMask)];
        const double pattern = h.weight * v.weight;
        if (counted) weight_sum += pattern;
        patterns[r] = pattern;
        directions[r] = (v.cos * (h.cos * axis + side * h.sin * left) + v.sin * up).cast<float>();
      }
    }
  };
  // The sidelobes', if PrimaryRays counted any: left of the main lobe's rays, then right.
  if (a.sidelobe_extent_deg > 0.0) {
    for (const double side : {1.0, -1.0}) {
      draw_strata(sidelobe_horizontal_slots_, a.sidelobe_rays_horizontal, sidelobe_vertical_slots_,
                  a.sidelobe_rays_vertical, ahead, side, true);
    }
  }
  // The back lobe's, if PrimaryRays counted any, about the axis behind; their weights stay out
  // of the sum (Acoustics::back_lobe_width_deg).
  if (a.back_lobe_width_deg > 0.0) {
    draw_strata(back_horizontal_slots_, a.back_lobe_rays, back_vertical_slots_, a.back_lobe_rays,
                -ahead, 1.0, false);
  }
  return weight_sum;
}

namespace {

// A mirrored ray of a beam's multipath, between bounces: the hit it last made, from where, along
// which direction, the path so far and the product of the specular fractions met. Unfolded
// (each reflection undone, so the path is seen from the sonar as a straight line to the image
// of where it ends): `unfold` maps the current direction back to the sonar's frame and `image`
// is the last mirror point's image relative to the sonar. `blur` sums, over the rough mirrors
// met, σ², σ²·s and σ²·s² (s the path length at the mirror): the spread of the way back.
struct MirrorPath {
  Eigen::Vector3f from;
  Eigen::Vector3f direction;
  Hit hit;
  double path = 0.0;
  double specular = 1.0;
  double pattern = 0.0;
  Eigen::Matrix3f unfold = Eigen::Matrix3f::Identity();
  Eigen::Vector3f image = Eigen::Vector3f::Zero();
  std::array<double, 3> blur{};
};

// A straight return to the sonar, heard at `range` with strength `weight` unless its occlusion
// ray finds a surface in the way.
struct StraightReturn {
  double range = 0.0;
  double weight = 0.0;
  double glint = 0.0;  // its glint's part, apart (GlintDeposit)
};

// Adds echoes to a beam's bins: an echo of strength `strength` (before range losses) from range
// `range` [m] lasts while the pulse passes it, so it is heard at every range in [r, r + L), and
// each bin gets the power times the fraction of the bin that span covers; with a second trip,
// the echo also goes to the trip's impulse response, over [r, r + 1 bin). Built per step as a
// local, its scalars copied in: held through a reference they would be reloaded after every
// store to the bins.
class EchoDeposit {
 public:
  EchoDeposit(const BeamSynthesizer& synthesizer, const mapping::SensorGeometry& geometry,
              double pulse_length_m, bool second_trip, PulseSpreader& spreader,
              std::vector<double>& impulse)
      : synthesizer_(synthesizer),
        pulse_bins_(pulse_length_m / geometry.bin_size_m),
        bins_per_m_(1.0 / geometry.bin_size_m),
        bins_(static_cast<std::size_t>(geometry.num_bins)),
        second_trip_(second_trip),
        spreader_(spreader),
        impulse_(impulse) {}

  // Inlined, with the range loss from its table (RangeLossFromTable): a call per ray cost more
  // than the work (synthesis_bench).
  [[gnu::always_inline]] void operator()(double range, double strength) {
    const double start = range * bins_per_m_;
    const double power = strength * synthesizer_.RangeLossFromTable(range);
    spreader_.Add(start, start + pulse_bins_, power);
    // The second trip's impulse response: the echo over [start, start + 1) bins, shared by the
    // two bins it covers (the last bin's share past it dropped).
    if (second_trip_ && start < static_cast<double>(bins_)) {
      const auto k = static_cast<std::size_t>(start);
      const double after = start - static_cast<double>(k);
      impulse_[k] += power * (1.0 - after);
      if (k + 1 < bins_) impulse_[k + 1] += power * after;
    }
  }

 private:
  const BeamSynthesizer& synthesizer_;
  double pulse_bins_;
  double bins_per_m_;
  std::size_t bins_;
  bool second_trip_;
  PulseSpreader& spreader_;
  std::vector<double>& impulse_;
};

// A beam's one-way pattern towards a world direction (unit), R_beam_world taking world
// directions into the beam's frame (BeamSynthesizer::OneWayPatternTowards).
struct OneWayPattern {
  Eigen::Matrix3d R_beam_world;
  const BeamSynthesizer& synthesizer;

  double operator()(const Eigen::Vector3d& towards, double blur = 0.0) const {
    return synthesizer.OneWayPatternTowards(R_beam_world * towards, blur);
  }
};

}  // namespace

// Synthesize()'s working memory, one per thread, kept between beams: a beam allocates only its
// output.
struct BeamSynthesizer::Scratch {
  std::vector<Eigen::Vector3f> directions;
  std::vector<Eigen::Vector3f> vehicle_directions;  // the same in the vehicle's frame
  std::vector<std::optional<Hit>> vehicle_hits;
  std::vector<double> patterns;
  std::vector<std::optional<Hit>> hits;
  std::vector<MirrorPath> paths;
  std::vector<MirrorPath> next_paths;
  std::vector<Ray> rays;
  std::vector<StraightReturn> returns;
  std::vector<bool> occluded;
  PulseSpreader spreader;
  PulseSpreader vehicle_spreader;  // the vehicle's echoes, apart from the scene's (FormLevels)
  PulseSpreader glint_spreader;    // the scene's glints, apart from its diffuse echoes (FormLevels)
  std::vector<double> echo_power;
  std::vector<double> apart_power;    // the vehicle's or the glints' (FormLevels)
  std::vector<double> impulse_power;  // the second trip's: each echo over one bin
  std::vector<double> speckle;
  std::vector<double> powers;
  std::vector<double> self_reflection;
  std::vector<std::uint64_t> sector_seeds;
};

// One beam's synthesis: what its steps share, each step a method. Synthesize() runs them in
// the order declared; each takes what the ones before it left in the job and the scratch.
class BeamSynthesizer::BeamJob {
 public:
  BeamJob(const BeamSynthesizer& synthesizer, double head_angle_rad,
          const Eigen::Isometry3d& T_world_sonar, std::uint64_t seed, Scratch& scratch,
          SynthesizedBeam& out)
      : s_(synthesizer),
        g_(synthesizer.sensor_.geometry),
        a_(synthesizer.sensor_.acoustics),
        bins_(static_cast<std::size_t>(g_.num_bins)),
        max_range_(g_.MaxRangeM()),
        head_angle_rad_(head_angle_rad),
        rng_(seed),
        scratch_(scratch),
        out_(out),
        T_world_sonar_(T_world_sonar),
        R_world_beam_(
            T_world_sonar.linear() *
            Eigen::AngleAxisd(head_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix()),
        origin_(T_world_sonar.translation().cast<float>()) {
    for (PulseSpreader* spreader :
         {&scratch_.spreader, &scratch_.vehicle_spreader, &scratch_.glint_spreader}) {
      if (spreader->Bins() != bins_) spreader->Reset(bins_);  // AddTo() leaves it empty
    }
    if (s_.second_trip_ > 0.0) scratch_.impulse_power.assign(bins_, 0.0);
    scratch_.echo_power.assign(bins_, 0.0);
  }

  // The echo's own randomness (ray jitter, speckle) is the ping's, or, with a correlation
  // length, the place's: the same for every ping from the same azimuth, tilt and position cell.
  // The place's speckle is its scatterers': each head-step-wide azimuth sector has its own,
  // which every beam whose pattern covers it hears (SectorSpeckle).
  void SeedPlace();
  // The aperture's rays and their first hits, traced as one coherent bundle: each hit's echo,
  // and the mirror paths that go on from it.
  void TracePrimaries();
  // The vehicle's parts along the primaries (TracePrimaries' hits in `scratch_.hits`): a ray
  // that meets one before the scene ends there, its hit the part's (normal in the world frame).
  void MeetVehicle();
  // The mirror paths, one bounce at a time (see above the definition).
  void TraceMultipath();
  // The echo's bins, its skirts, second trip, speckle, reverberation, self-reflection and
  // noise, and the 8-bit levels; the noise-free power kept if asked.
  void FormLevels(EchoPower echo_power);

 private:
  EchoDeposit Deposit() {
    return {s_,
            g_,
            a_.pulse_length_m,
            s_.second_trip_ > 0.0,
            scratch_.spreader,
            scratch_.impulse_power};
  }
  // The vehicle's echoes: the pulse alone, no second trip (FormLevels adds them after the
  // scene's skirts, second trip and reverberation).
  EchoDeposit VehicleDeposit() {
    return {s_, g_, a_.pulse_length_m, false, scratch_.vehicle_spreader, scratch_.impulse_power};
  }
  // The scene's glints: the pulse and its skirts, no second trip or reverberation (FormLevels).
  EchoDeposit GlintDeposit() {
    return {s_, g_, a_.pulse_length_m, false, scratch_.glint_spreader, scratch_.impulse_power};
  }

  const BeamSynthesizer& s_;
  const mapping::SensorGeometry& g_;
  const Acoustics& a_;
  std::size_t bins_;
  double max_range_;
  double head_angle_rad_;
  Rng rng_;
  Scratch& scratch_;
  SynthesizedBeam& out_;
  const Eigen::Isometry3d& T_world_sonar_;
  Eigen::Matrix3d R_world_beam_;
  Eigen::Vector3f origin_;
  std::optional<Rng> place_rng_;
  // The place's generator if there is one, else the ping's (SeedPlace()).
  Rng* echo_rng_ = &rng_;
  // The primary rays' pattern weights' sum (TracePrimaries()).
  double weight_sum_ = 0.0;
};

void BeamSynthesizer::BeamJob::SeedPlace() {
  std::vector<std::uint64_t>& sector_seeds = scratch_.sector_seeds;
  const bool own = a_.speckle_own_share > 0.0;
  const int sector_reach = static_cast<int>((s_.sector_weights_.size() - (own ? 1 : 0)) / 2);
  sector_seeds.resize(s_.sector_weights_.size());
  if (a_.speckle_correlation_m <= 0.0) return;
  const double step = g_.step_angle_rad;
  const long long turn = std::llround(2.0 * std::numbers::pi / step);
  const Eigen::Vector3d axis = R_world_beam_.col(0);
  const long long azimuth = std::llround(std::atan2(axis.y(), axis.x()) / step);
  const long long tilt = std::llround(std::asin(std::clamp(axis.z(), -1.0, 1.0)) / step);
  std::array<std::uint64_t, 3> cells{};
  for (int i = 0; i < 3; ++i) {
    const double cell = std::floor(T_world_sonar_.translation()[i] / a_.speckle_correlation_m);
    cells[static_cast<std::size_t>(i)] =
        static_cast<std::uint64_t>(static_cast<std::int64_t>(cell));
  }
  const auto place_of = [&](long long sector) {
    std::uint64_t place =
        DeriveSeed(s_.place_seed_, static_cast<std::uint64_t>(((sector % turn) + turn) % turn));
    place = DeriveSeed(place, static_cast<std::uint64_t>(tilt));
    for (const std::uint64_t cell : cells) place = DeriveSeed(place, cell);
    return place;
  };
  place_rng_.emplace(place_of(azimuth));
  echo_rng_ = &*place_rng_;
  for (int d = -sector_reach; d <= sector_reach; ++d) {
    sector_seeds[static_cast<std::size_t>(d + sector_reach)] =
        DeriveSeed(place_of(azimuth + d), 0x737065636bULL);  // "speck"
  }
  if (own) sector_seeds.back() = DeriveSeed(place_of(azimuth), 0x6f776eULL);  // "own"
}

void BeamSynthesizer::BeamJob::MeetVehicle() {
  // The vehicle's frame: T_world_sonar = T_world_vehicle · T_vehicle_sonar.
  const Eigen::Isometry3d& T_vehicle_sonar = g_.T_vehicle_sonar;
  const Eigen::Matrix3f R_vehicle_world =
      (T_vehicle_sonar.linear() * T_world_sonar_.linear().transpose()).cast<float>();
  const std::vector<Eigen::Vector3f>& directions = scratch_.directions;
  std::vector<Eigen::Vector3f>& in_vehicle = scratch_.vehicle_directions;
  in_vehicle.resize(directions.size());
  for (std::size_t r = 0; r < directions.size(); ++r) {
    in_vehicle[r] = R_vehicle_world * directions[r];
  }
  std::vector<std::optional<Hit>>& parts = scratch_.vehicle_hits;
  parts.resize(directions.size());
  s_.vehicle_tracer_->IntersectBundle(T_vehicle_sonar.translation().cast<float>(), in_vehicle,
                                      static_cast<float>(max_range_), parts);
  out_.traced_rays += directions.size();
  std::vector<std::optional<Hit>>& hits = scratch_.hits;
  for (std::size_t r = 0; r < directions.size(); ++r) {
    const std::optional<Hit>& part = parts[r];
    if (!part || (hits[r] && hits[r]->distance <= part->distance)) continue;
    hits[r] = Hit{.distance = part->distance,
                  .normal = R_vehicle_world.transpose() * part->normal,
                  .mesh = s_.vehicle_first_mesh_ + part->mesh};
  }
}

void BeamSynthesizer::BeamJob::TracePrimaries() {
  const std::size_t rays = PrimaryRays(a_);
  const std::size_t main_lobe_rays = MainLobeRays(a_);
  std::vector<Eigen::Vector3f>& directions = scratch_.directions;
  std::vector<double>& patterns = scratch_.patterns;
  weight_sum_ = s_.DrawRays(R_world_beam_, *echo_rng_, directions, patterns);
  std::vector<std::optional<Hit>>& hits = scratch_.hits;
  hits.resize(rays);
  s_.tracer_.IntersectBundle(origin_, directions, static_cast<float>(max_range_), hits);
  out_.traced_rays += rays;
  if (s_.vehicle_tracer_) MeetVehicle();
  std::vector<MirrorPath>& paths = scratch_.paths;
  paths.clear();
  EchoDeposit deposit = Deposit();
  EchoDeposit vehicle_deposit = VehicleDeposit();
  EchoDeposit glint_deposit = GlintDeposit();
  for (std::size_t r = 0; r < rays; ++r) {
    const auto& hit = hits[r];
    if (!hit) continue;
    const Eigen::Vector3f& direction = directions[r];
    const double pattern = patterns[r];
    const double range = std::max<double>(hit->distance, g_.bin_size_m);
    const bool on_vehicle = hit->mesh >= s_.vehicle_first_mesh_;
    if (!on_vehicle && r < main_lobe_rays &&
        (!out_.truth.first_hit_range_m || range < *out_.truth.first_hit_range_m)) {
      out_.truth.first_hit_range_m = range;
      out_.truth.first_hit_mesh = hit->mesh;
    }
    const Material& material = s_.materials_by_mesh_[hit->mesh];
    const double cos_incidence = std::abs(hit->normal.dot(direction));
    // Straight back: the mirror direction makes 2θ with it, cos 2θ = 2 cos²θ - 1.
    const double diffuse =
        pattern * material.reflectivity * CosPower(cos_incidence, material.backscatter_exponent);
    const double glint = pattern * Glint(material, 2.0 * cos_incidence * cos_incidence - 1.0);
    if (on_vehicle) {
      vehicle_deposit(range, diffuse + glint);
    } else {
      deposit(range, diffuse);
      if (glint > 0.0) glint_deposit(range, glint);
    }
    if (a_.max_bounces > 0 && material.specular > 0.0 && !on_vehicle) {
      paths.push_back({.from = origin_,
                       .direction = direction,
                       .hit = *hit,
                       .path = hit->distance,
                       .pattern = pattern});
    }
  }
}

// Multipath, one bounce at a time for all the beam's rays (each bounce's mirrored rays one
// stream, their occlusion rays another): a ray with two-way pattern weight `pattern` goes on in
// the mirror direction with the specular fraction of its energy, up to max_bounces times. At
// each later hit P_k, after a path of length L from the sonar, two returns:
//  - back through the same mirrors: range L, weight pattern · s² · ρ cosⁿ, where s is the
//    product of the specular fractions so far and pattern the two-way pattern of the way out
//    and back (return_pattern);
//  - straight back to the sonar if P_k is in view (an occlusion ray) and in the receive pattern
//    (the back lobe's too): range R = (L + d)/2 with d = |P_k - sonar|, weight 2 · √pattern ·
//    p(P_k) · s · ρ (cos_i cos_s)^(n/2) · (R/d)^(S/10); p is the one-way pattern towards P_k,
//    the factor 2 counts the reverse path (sonar → P_k → mirrors → sonar), equal by
//    reciprocity, and (R/d)^(S/10) turns the monostatic spreading at R into the last leg's own.
void BeamSynthesizer::BeamJob::TraceMultipath() {
  const OneWayPattern one_way_pattern{R_world_beam_.transpose(), s_};
  // The two-way pattern of the way out and back along a mirror path ending at p's hit. Through
  // perfect mirrors the echo comes back along the way out: the ray's own two-way pattern.
  // Through rough ones the way back is a path of its own, each rough mirror tilting it
  // independently: it arrives from the direction of the end point's image, off by a 2-D
  // Gaussian angle of variance Σ σ² (1 - s/L)² per axis (a tilt at path length s moves the
  // image seen from the sonar by (L - s)/L of it), and the receive pattern is averaged over it.
  auto return_pattern = [&](const MirrorPath& p) {
    if (p.blur[0] <= 0.0) return p.pattern;
    const Eigen::Vector3f image = p.image + p.unfold * (p.hit.distance * p.direction);
    const double inverse = 1.0 / p.path;
    const double blur =
        std::max(p.blur[0] - 2.0 * p.blur[1] * inverse + p.blur[2] * inverse * inverse, 0.0);
    return std::sqrt(p.pattern) * one_way_pattern(image.cast<double>().normalized(), blur);
  };
  const Eigen::Vector3d sonar = T_world_sonar_.translation();
  const double spreading_db = a_.spreading_db_per_decade;
  const double max_range = max_range_;
  EchoDeposit deposit = Deposit();
  EchoDeposit glint_deposit = GlintDeposit();
  Rng& echo_rng = *echo_rng_;
  std::vector<MirrorPath>& paths = scratch_.paths;
  std::vector<MirrorPath>& next_paths = scratch_.next_paths;
  std::vector<std::optional<Hit>>& hits = scratch_.hits;
  std::vector<Ray>& stream = scratch_.rays;
  std::vector<StraightReturn>& returns = scratch_.returns;
  for (int bounce = 1; bounce <= a_.max_bounces && !paths.empty(); ++bounce) {
    next_paths.clear();
    stream.clear();
    // Each path is read where it was and written where it goes: read back from a copy just
    // made, its fields stalled on store forwarding (perf annotate: a sixth of this loop's time).
    for (const MirrorPath& was : paths) {
      const Material& mirror = s_.materials_by_mesh_[was.hit.mesh];
      const double specular = was.specular * mirror.specular;
      if (specular <= 0.0 || was.path >= 2.0 * max_range) continue;
      MirrorPath& p = next_paths.emplace_back(was);
      p.specular = specular;
      const Eigen::Vector3f step = was.hit.distance * was.direction;
      const Eigen::Vector3f from = was.from + step;
      p.from = from;
      if (s_.rough_mirrors_) {
        p.image = was.image + was.unfold * step;
        p.unfold = was.unfold - 2.0f * (was.unfold * was.hit.normal) * was.hit.normal.transpose();
      }
      if (const double sigma = mirror.specular_spread_rad; sigma > 0.0) {
        const double variance = sigma * sigma;
        p.blur[0] = was.blur[0] + variance;
        p.blur[1] = was.blur[1] + variance * was.path;
        p.blur[2] = was.blur[2] + variance * was.path * was.path;
      }
      const Eigen::Vector3f direction = s_.SpreadMirror(
          (was.direction - 2.0f * was.direction.dot(was.hit.normal) * was.hit.normal).normalized(),
          was.hit.normal, mirror, echo_rng);
      p.direction = direction;
      stream.push_back(
          {from + 1e-4f * direction, direction, static_cast<float>(2.0 * max_range - was.path)});
    }
    hits.resize(stream.size());
    s_.tracer_.IntersectStream(stream, hits);
    out_.traced_rays += stream.size();

    paths.clear();
    stream.clear();
    returns.clear();
    for (std::size_t q = 0; q < next_paths.size(); ++q) {
      if (!hits[q]) continue;
      const MirrorPath& was = next_paths[q];
      const Hit& hit = *hits[q];
      const double path = was.path + hit.distance;
      MirrorPath& p = paths.emplace_back(was);
      p.hit = hit;
      p.path = path;
      const Material& m = s_.materials_by_mesh_[hit.mesh];
      const double cos_in = std::abs(hit.normal.dot(was.direction));
      if (path <= max_range) {
        const double way = return_pattern(p) * was.specular * was.specular;
        deposit(path, way * m.reflectivity * CosPower(cos_in, m.backscatter_exponent));
        if (const double glint = way * Glint(m, 2.0 * cos_in * cos_in - 1.0); glint > 0.0) {
          glint_deposit(path, glint);
        }
      }
      const Eigen::Vector3f at = was.from + hit.distance * was.direction;
      const Eigen::Vector3d back = sonar - at.cast<double>();
      const double d = back.norm();
      const double range = 0.5 * (path + d);
      if (range > max_range || d < g_.bin_size_m) continue;
      // Culled on the largest its law can give: ρ for the diffuse part, g for the glint. First
      // on a bound of the receive pattern, which spares most returns from ahead its
      // trigonometry and culls only what the pattern itself would (0.999 leaves rounding a
      // margin); the weight keeps its own order of products, so its bits do not change.
      const Eigen::Vector3d u = one_way_pattern.R_beam_world * (-back / d);
      const double way_out = 2.0 * std::sqrt(was.pattern);  // both ways round the path
      const double largest = std::max(m.reflectivity, m.glint);
      if (way_out * was.specular * s_.OneWayPatternBound(u) * largest < 0.999 * kNegligibleWeight) {
        continue;
      }
      const double weight = way_out * s_.OneWayPatternTowards(u) * was.specular;
      if (weight * largest < kNegligibleWeight) continue;
      const Eigen::Vector3f to_sonar = (back / d).cast<float>();
      const double cos_out = std::abs(hit.normal.dot(to_sonar));
      double glint = 0.0;  // towards the sonar from the mirror direction, if m glints
      if (m.glint > 0.0) {
        const Eigen::Vector3f mirror =
            was.direction - 2.0f * was.direction.dot(hit.normal) * hit.normal;
        glint = Glint(m, static_cast<double>(mirror.dot(to_sonar)));
      }
      stream.push_back({at + 1e-4f * to_sonar, to_sonar, static_cast<float>(d) - 2e-4f});
      const double last_leg = std::pow(range / d, spreading_db / 10.0);
      returns.push_back({range,
                         weight * m.reflectivity *
                             CosPower(cos_in * cos_out, 0.5 * m.backscatter_exponent) * last_leg,
                         weight * glint * last_leg});
    }
    s_.tracer_.OccludedStream(stream, scratch_.occluded);
    out_.traced_rays += stream.size();
    for (std::size_t q = 0; q < returns.size(); ++q) {
      if (scratch_.occluded[q]) continue;
      deposit(returns[q].range, returns[q].weight);
      if (returns[q].glint > 0.0) glint_deposit(returns[q].range, returns[q].glint);
    }
  }
}

void BeamSynthesizer::BeamJob::FormLevels(EchoPower echo_power) {
  std::vector<double>& echo = scratch_.echo_power;
  scratch_.spreader.AddTo(echo);

  if (const auto axis =
          s_.tracer_.Intersect(origin_, (R_world_beam_ * Eigen::Vector3d::UnitX()).cast<float>(),
                               static_cast<float>(max_range_))) {
    out_.truth.axis_hit_range_m = axis->distance;
  }
  ++out_.traced_rays;

  out_.beam.intensities.resize(bins_);
  const double gain = std::pow(10.0, a_.gain_db / 10.0);
  for (double& power : echo) power /= weight_sum_;
  s_.AddPulseSkirts(echo);
  if (s_.second_trip_ > 0.0) {
    for (double& power : scratch_.impulse_power) power /= weight_sum_;
    s_.AddSecondTrip(echo, scratch_.impulse_power);
  }
  std::vector<double>& speckle = scratch_.speckle;
  if (a_.speckle) {
    speckle.resize(bins_);
    if (place_rng_) {
      SectorSpeckle(speckle, s_.speckle_window_, s_.sector_weights_, scratch_.sector_seeds,
                    a_.speckle_looks);
    } else {
      CorrelatedSpeckle(speckle, s_.speckle_window_, *echo_rng_, a_.speckle_looks);
    }
  }
  s_.AddReverberation(echo);
  // Echoes heard apart from the scene's diffuse ones, after its second trip and reverberation:
  // a spreader's bins, with the pulse's skirts if `skirts`.
  const auto add_apart = [&](PulseSpreader& spreader, bool skirts) {
    std::vector<double>& apart = scratch_.apart_power;
    apart.assign(bins_, 0.0);
    spreader.AddTo(apart);
    for (double& power : apart) power /= weight_sum_;
    if (skirts) s_.AddPulseSkirts(apart);
    for (std::size_t k = 0; k < bins_; ++k) echo[k] += apart[k];
  };
  // A glint is the sonar's mirror image, sound that came straight back: it has the pulse's
  // skirts like any echo, but feeds no reverberation and no second trip (the real tank is quiet
  // behind walls met squarely: docs/fidelity.md, behind the walls).
  if (s_.scene_glints_) add_apart(scratch_.glint_spreader, true);
  // The vehicle's echoes are heard as they are: the real log's show no skirts, second trip or
  // reverberation (behind the SHAD's own echo at 0.3 m its beams at head angle 0° are silent
  // from 0.55 m to the floor at 1.45 m), so those are the tank's answers to its own echoes.
  if (s_.vehicle_tracer_) add_apart(scratch_.vehicle_spreader, false);
  // The powers first, then their levels: no 8-bit store inside the loop that draws the noise.
  // The self-reflection is the sonar's own, not the place's: added after the speckle.
  std::vector<double>& self_reflection = scratch_.self_reflection;
  s_.SelfReflection(head_angle_rad_, rng_, self_reflection);
  std::vector<double>& powers = scratch_.powers;
  powers.resize(bins_);
  for (std::size_t k = 0; k < bins_; ++k) {
    double signal = gain * echo[k];
    if (a_.speckle) signal *= speckle[k];
    if (k < self_reflection.size()) signal += self_reflection[k];
    powers[k] = signal + s_.noise_at_bin_[k] * rng_.Exponential();
  }
  // The receiver's level jitter, the ping's whatever the echoes are: five 12-bit picks per draw,
  // bin k's own and, if neighbouring bins correlate, bin k + 1's too (a z_k + b z_k+1).
  if (const std::vector<double>& jitter = s_.level_jitter_factors_; !jitter.empty()) {
    static_assert(kLevelJitters == 1 << 12, "12 bits per pick");
    std::uint64_t bits = 0;
    int picks_left = 0;
    const auto pick = [&] {
      if (picks_left == 0) {
        bits = rng_.Next();
        picks_left = 5;
      }
      const std::uint64_t i = bits & (kLevelJitters - 1);
      bits >>= 12;
      --picks_left;
      return i;
    };
    if (const std::vector<double>& next = s_.level_jitter_next_factors_; next.empty()) {
      for (double& power : powers) power *= jitter[pick()];
    } else {
      std::uint64_t own = pick();
      for (double& power : powers) {
        const std::uint64_t shared = pick();
        power *= jitter[own] * next[shared];
        own = shared;
      }
    }
  }
  const AdSteps quantise{.thresholds = s_.ad_thresholds_.data(),
                         .bucket_steps = s_.ad_bucket_steps_.data(),
                         .reported = s_.ad_reported_.data(),
                         .first_bucket = s_.ad_first_bucket_,
                         .bucket_shift = s_.ad_bucket_shift_,
                         .top = s_.ad_top_reading_};
  std::uint8_t* const levels = out_.beam.intensities.data();
  for (std::size_t k = 0; k < bins_; ++k) levels[k] = quantise(powers[k]);
  // The receiver off while the head transmits: after the draws, so the other bins' are the same.
  for (std::size_t k = 0; k < bins_; ++k) {
    if (static_cast<double>(k) * g_.bin_size_m >= a_.blanking_range_m) break;
    levels[k] = 0;
  }
  if (echo_power == EchoPower::kKeep) out_.echo_power = echo;
}

SynthesizedBeam BeamSynthesizer::Synthesize(double time_s, double head_angle_rad,
                                            const Eigen::Isometry3d& T_world_sonar,
                                            std::uint64_t seed, EchoPower echo_power) const {
  SynthesizedBeam out;
  out.beam.time_s = time_s;
  out.beam.head_angle_rad = head_angle_rad;
  out.beam.T_world_sonar = T_world_sonar;
  out.truth.T_world_sonar = T_world_sonar;
  out.beam.bin_size_m = sensor_.geometry.bin_size_m;
  thread_local Scratch scratch;
  BeamJob job(*this, head_angle_rad, T_world_sonar, seed, scratch, out);
  job.SeedPlace();
  job.TracePrimaries();
  job.TraceMultipath();
  job.FormLevels(echo_power);
  return out;
}

}  // namespace sonarbench::sim
