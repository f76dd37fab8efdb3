#include "sonarbench/sim/beam_synthesizer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <optional>
#include <vector>

#include "sonarbench/sim/fast_math.hpp"
#include "sonarbench/sim/random.hpp"

namespace sonarbench::sim {

BeamSynthesizer::BeamSynthesizer(const SensorModel& sensor, const RayTracer& tracer,
                                 std::vector<Material> materials_by_mesh, std::uint64_t run_seed)
    : sensor_(sensor),
      tracer_(tracer),
      materials_by_mesh_(std::move(materials_by_mesh)),
      place_seed_(DeriveSeed(run_seed, 0x706c616365ULL)) {
  for (const double db : sensor_.acoustics.self_reflection_db) {
    self_reflection_power_.push_back(std::pow(10.0, db / 10.0));
  }
  // Quantise rounds half up: step q begins where the level reaches q - 0.5 AD steps.
  const Acoustics& a = sensor_.acoustics;
  ad_thresholds_[0] = 0.0;
  for (int q = 1; q < 256; ++q) {
    const double level_db = a.ad_low_db + (q - 0.5) / 255.0 * a.ad_span_db;
    ad_thresholds_[static_cast<std::size_t>(q)] = std::pow(10.0, level_db / 10.0);
  }
  // Buckets of positive doubles by their exponent and top mantissa bits: with 2^m per octave,
  // a bucket spans 3.01/2^m dB; m is chosen so that spans half an AD step, or less.
  const double step_db = a.ad_span_db / 255.0;
  int mantissa_bits = 0;
  while (mantissa_bits < 20 &&
         10.0 * std::log10(2.0) / std::ldexp(1.0, mantissa_bits) > 0.5 * step_db) {
    ++mantissa_bits;
  }
  ad_bucket_shift_ = 52 - mantissa_bits;
  ad_first_bucket_ = std::bit_cast<std::uint64_t>(ad_thresholds_[1]) >> ad_bucket_shift_;
  const std::uint64_t last_bucket =
      std::bit_cast<std::uint64_t>(ad_thresholds_[255]) >> ad_bucket_shift_;
  ad_bucket_steps_.resize(last_bucket - ad_first_bucket_ + 1);
  unsigned q = 0;
  for (std::uint64_t b = ad_first_bucket_; b <= last_bucket; ++b) {
    const double start = std::bit_cast<double>(b << ad_bucket_shift_);
    while (q < 255 && start >= ad_thresholds_[q + 1]) ++q;
    ad_bucket_steps_[b - ad_first_bucket_] = static_cast<std::uint8_t>(q);
  }

  range_step_m_ = sensor_.geometry.bin_size_m / 16.0;
  const auto steps =
      static_cast<std::size_t>(std::ceil(sensor_.geometry.MaxRangeM() / range_step_m_));
  range_loss_.resize(steps + 2);
  for (std::size_t k = 0; k < range_loss_.size(); ++k) {
    range_loss_[k] = RangeLoss(static_cast<double>(k) * range_step_m_);
  }
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

double BeamSynthesizer::RangeLossFromTable(double range_m) const {
  const double x = range_m / range_step_m_;
  // From 8 bins out (128 steps) to the table's last interval. The interpolation's relative
  // error is at most h²/8 · f''/f, with f''/f = s(s+1)/r² + 2sα/r + α² for f = r^-s·e^-αr:
  // under 5e-5 at 8 bins for |s| ≤ 2 (|S - G| ≤ 20 dB per decade). Nearer, exactly.
  if (!(x >= 128.0 && x < static_cast<double>(range_loss_.size() - 1))) return RangeLoss(range_m);
  const auto k = static_cast<std::size_t>(x);
  const double f = x - static_cast<double>(k);
  return range_loss_[k] + f * (range_loss_[k + 1] - range_loss_[k]);
}

std::uint8_t BeamSynthesizer::QuantisePower(double power) const {
  // The largest q with ad_thresholds_[q] <= power (the thresholds increase; q = 0 below them):
  // the table gives it at the start of the power's bucket, and the power may pass the next
  // threshold or two within the bucket. Exact whatever the bucket width; narrow buckets make
  // the loop rare.
  if (!(power >= ad_thresholds_[1])) return 0;
  if (power >= ad_thresholds_[255]) return 255;
  const std::uint64_t bucket =
      (std::bit_cast<std::uint64_t>(power) >> ad_bucket_shift_) - ad_first_bucket_;
  unsigned q = ad_bucket_steps_[bucket];
  while (power >= ad_thresholds_[q + 1]) ++q;
  return static_cast<std::uint8_t>(q);
}

namespace {

// Bistatic returns weaker than this (relative to a perfect reflector filling the beam) are not
// worth the occlusion ray: 60 dB below the strongest echo, far under the AD window's 40 dB.
constexpr double kNegligibleWeight = 1e-6;

// cosⁿ, with the exponents scenes use most spared a pow().
double CosPower(double c, double n) {
  if (n == 1.0) return c;
  if (n == 0.5) return std::sqrt(c);
  if (n == 2.0) return c * c;
  return std::pow(c, n);
}

}  // namespace

std::uint8_t BeamSynthesizer::Quantise(double level_db) const {
  const Acoustics& a = sensor_.acoustics;
  const double scaled = std::round((level_db - a.ad_low_db) / a.ad_span_db * 255.0);
  return static_cast<std::uint8_t>(std::clamp(scaled, 0.0, 255.0));
}

SynthesizedBeam BeamSynthesizer::Synthesize(double time_s, double head_angle_rad,
                                            const Eigen::Isometry3d& T_world_sonar,
                                            std::uint64_t seed) const {
  const mapping::SensorGeometry& g = sensor_.geometry;
  const Acoustics& a = sensor_.acoustics;
  const auto bins = static_cast<std::size_t>(g.num_bins);
  const double max_range = g.MaxRangeM();
  Rng rng(seed);

  SynthesizedBeam out;
  out.beam.time_s = time_s;
  out.beam.head_angle_rad = head_angle_rad;
  out.beam.T_world_sonar = T_world_sonar;
  out.truth.T_world_sonar = T_world_sonar;
  out.beam.bin_size_m = g.bin_size_m;
  out.echo_power.assign(bins, 0.0);

  const Eigen::Matrix3d R_world_beam =
      T_world_sonar.linear() *
      Eigen::AngleAxisd(head_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3f origin = T_world_sonar.translation().cast<float>();
  // The echo's own randomness (ray jitter, speckle) is the ping's, or, with a correlation
  // length, the place's: the same for every ping from the same azimuth, tilt and position cell.
  std::optional<Rng> place_rng;
  if (a.speckle_correlation_m > 0.0) {
    const auto step = [&](double angle) {
      return static_cast<std::uint64_t>(std::llround(angle / g.step_angle_rad));
    };
    const Eigen::Vector3d axis = R_world_beam.col(0);
    std::uint64_t place = DeriveSeed(place_seed_, step(std::atan2(axis.y(), axis.x())));
    place = DeriveSeed(place, step(std::asin(std::clamp(axis.z(), -1.0, 1.0))));
    for (int i = 0; i < 3; ++i) {
      const double cell = std::floor(T_world_sonar.translation()[i] / a.speckle_correlation_m);
      place = DeriveSeed(place, static_cast<std::uint64_t>(static_cast<std::int64_t>(cell)));
    }
    place_rng.emplace(place);
  }
  Rng& echo_rng = place_rng ? *place_rng : rng;
  const double width_h = a.aperture_scale * g.beam_width_horizontal_rad;
  const double width_v = a.aperture_scale * g.beam_width_vertical_rad;
  const double k_h =
      4.0 * std::log(2.0) / (g.beam_width_horizontal_rad * g.beam_width_horizontal_rad);
  const double k_v = 4.0 * std::log(2.0) / (g.beam_width_vertical_rad * g.beam_width_vertical_rad);
  const double pulse_bins = a.pulse_length_m / g.bin_size_m;

  // Adds an echo of strength `strength` (before range losses) from range `range` [m]: the echo
  // of a point lasts while the pulse passes it, so it is heard at every range in [r, r + L), and
  // each bin gets the power times the fraction of the bin that span covers.
  // The range loss from its table (RangeLossFromTable).
  auto deposit = [&](double range, double strength) {
    const double power = strength * RangeLossFromTable(range);
    const double start = range / g.bin_size_m;
    const double end = start + pulse_bins;
    for (auto k = static_cast<std::size_t>(start); k < bins && static_cast<double>(k) < end; ++k) {
      const double overlap =
          std::min(static_cast<double>(k + 1), end) - std::max(static_cast<double>(k), start);
      out.echo_power[k] += power * overlap;
    }
  };
  // The one-way pattern at a direction in the beam frame, or 0 outside the half-space ahead.
  const Eigen::Matrix3d R_beam_world = R_world_beam.transpose();
  auto one_way_pattern = [&](const Eigen::Vector3d& towards) {
    const Eigen::Vector3d u = R_beam_world * towards;
    if (u.x() <= 0.0) return 0.0;
    const double theta = std::atan2(u.y(), u.x());
    const double epsilon = std::asin(std::clamp(u.z(), -1.0, 1.0));
    return std::exp(-0.5 * (k_h * theta * theta + k_v * epsilon * epsilon));
  };
  const Eigen::Vector3d sonar = T_world_sonar.translation();
  const double spreading_db = a.spreading_db_per_decade;
  // Multipath of a ray with two-way pattern weight `pattern` whose first hit is `first`: the ray
  // goes on in the mirror direction with the specular fraction of its energy, up to max_bounces
  // times. At each later hit P_k, after a path of length L from the sonar, two returns:
  //  - back along the same path (through the same mirrors both ways): range L, weight
  //    pattern · s² · ρ cosⁿ, where s is the product of the specular fractions so far;
  //  - straight back to the sonar if P_k is in view (an occlusion ray) and in the receive lobe:
  //    range R = (L + d)/2 with d = |P_k - sonar|, weight 2 · √pattern · p(P_k) · s · ρ (cos_i
  //    cos_s)^(n/2) · (R/d)^(S/10); p is the one-way pattern towards P_k, the factor 2 counts
  //    the reverse path (sonar → P_k → mirrors → sonar), equal by reciprocity, and (R/d)^(S/10)
  //    turns the monostatic spreading at R into the last leg's own.
  auto multipath = [&](const Eigen::Vector3f& first_direction, const Hit& first, double pattern) {
    Eigen::Vector3f direction = first_direction;
    Hit hit = first;
    Eigen::Vector3f from = origin;
    double path = hit.distance;
    double specular = 1.0;
    for (int bounce = 1; bounce <= a.max_bounces; ++bounce) {
      specular *= materials_by_mesh_[hit.mesh].specular;
      if (specular <= 0.0 || path >= 2.0 * max_range) return;
      from += hit.distance * direction;
      direction = (direction - 2.0f * direction.dot(hit.normal) * hit.normal).normalized();
      ++out.traced_rays;
      const auto next = tracer_.Intersect(from + 1e-4f * direction, direction,
                                          static_cast<float>(2.0 * max_range - path));
      if (!next) return;
      hit = *next;
      path += hit.distance;
      const Material& m = materials_by_mesh_[hit.mesh];
      const double cos_in = std::abs(hit.normal.dot(direction));
      if (path <= max_range) {
        deposit(path, pattern * specular * specular * m.reflectivity *
                          CosPower(cos_in, m.backscatter_exponent));
      }
      const Eigen::Vector3f at = from + hit.distance * direction;
      const Eigen::Vector3d back = sonar - at.cast<double>();
      const double d = back.norm();
      const double range = 0.5 * (path + d);
      if (range > max_range || d < g.bin_size_m) continue;
      const double receive = one_way_pattern(-back / d);
      const double weight = 2.0 * std::sqrt(pattern) * receive * specular * m.reflectivity;
      if (weight < kNegligibleWeight) continue;
      const Eigen::Vector3f to_sonar = (back / d).cast<float>();
      ++out.traced_rays;
      if (tracer_.Occluded(at + 1e-4f * to_sonar, to_sonar, static_cast<float>(d) - 2e-4f)) {
        continue;
      }
      const double cos_out = std::abs(hit.normal.dot(to_sonar));
      deposit(range, weight * CosPower(cos_in * cos_out, 0.5 * m.backscatter_exponent) *
                         std::pow(range / d, spreading_db / 10.0));
    }
  };
  // The aperture's rays, stratified and jittered (two draws per ray, in this order), their
  // two-way pattern weights, then their first hits, traced as one coherent bundle.
  const auto rays = static_cast<std::size_t>(a.rays_horizontal) * a.rays_vertical;
  std::vector<Eigen::Vector3f> directions(rays);
  std::vector<double> patterns(rays);
  double weight_sum = 0.0;
  for (int i = 0, r = 0; i < a.rays_horizontal; ++i) {
    for (int j = 0; j < a.rays_vertical; ++j, ++r) {
      const double theta = ((i + echo_rng.Uniform()) / a.rays_horizontal - 0.5) * width_h;
      const double epsilon = ((j + echo_rng.Uniform()) / a.rays_vertical - 0.5) * width_v;
      const double pattern = std::exp(-k_h * theta * theta - k_v * epsilon * epsilon);
      weight_sum += pattern;
      patterns[static_cast<std::size_t>(r)] = pattern;
      const SinCos h = SmallAngleSinCos(theta);
      const SinCos v = SmallAngleSinCos(epsilon);
      directions[static_cast<std::size_t>(r)] =
          (R_world_beam * Eigen::Vector3d(h.cos * v.cos, h.sin * v.cos, v.sin)).cast<float>();
    }
  }
  std::vector<std::optional<Hit>> hits(rays);
  tracer_.IntersectBundle(origin, directions, static_cast<float>(max_range), hits);
  out.traced_rays += rays;
  for (std::size_t r = 0; r < rays; ++r) {
    const auto& hit = hits[r];
    if (!hit) continue;
    const Eigen::Vector3f& direction = directions[r];
    const double pattern = patterns[r];
    const double range = std::max<double>(hit->distance, g.bin_size_m);
    if (!out.truth.first_hit_range_m || range < *out.truth.first_hit_range_m) {
      out.truth.first_hit_range_m = range;
      out.truth.first_hit_mesh = hit->mesh;
    }
    const Material& material = materials_by_mesh_[hit->mesh];
    const double cos_incidence = std::abs(hit->normal.dot(direction));
    deposit(range, pattern * material.reflectivity *
                       CosPower(cos_incidence, material.backscatter_exponent));
    if (a.max_bounces > 0 && material.specular > 0.0) {
      multipath(direction, *hit, pattern);
    }
  }
  for (double& p : out.echo_power) p /= weight_sum;

  if (const auto axis =
          tracer_.Intersect(origin, (R_world_beam * Eigen::Vector3d::UnitX()).cast<float>(),
                            static_cast<float>(max_range))) {
    out.truth.axis_hit_range_m = axis->distance;
  }

  out.beam.intensities.resize(bins);
  const double noise_power = std::pow(10.0, a.noise_level_db / 10.0);
  const double gain = std::pow(10.0, a.gain_db / 10.0);
  for (std::size_t k = 0; k < bins; ++k) {
    double signal = gain * out.echo_power[k];
    if (k < self_reflection_power_.size()) signal += self_reflection_power_[k];
    if (a.speckle) signal *= echo_rng.Exponential();
    const double power = signal + noise_power * rng.Exponential();
    out.beam.intensities[k] = QuantisePower(power);
  }
  return out;
}

}  // namespace sonarbench::sim
