#include "sonarbench/sim/beam_synthesizer.hpp"

#include <algorithm>
#include <cmath>

#include "sonarbench/sim/random.hpp"

namespace sonarbench::sim {

BeamSynthesizer::BeamSynthesizer(const SensorModel& sensor, const RayTracer& tracer,
                                 std::vector<Material> materials_by_mesh)
    : sensor_(sensor), tracer_(tracer), materials_by_mesh_(std::move(materials_by_mesh)) {
  for (const double db : sensor_.acoustics.self_reflection_db) {
    self_reflection_power_.push_back(std::pow(10.0, db / 10.0));
  }
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
  const double width_h = a.aperture_scale * g.beam_width_horizontal_rad;
  const double width_v = a.aperture_scale * g.beam_width_vertical_rad;
  const double k_h =
      4.0 * std::log(2.0) / (g.beam_width_horizontal_rad * g.beam_width_horizontal_rad);
  const double k_v = 4.0 * std::log(2.0) / (g.beam_width_vertical_rad * g.beam_width_vertical_rad);
  const double pulse_bins = a.pulse_length_m / g.bin_size_m;

  // Adds an echo of strength `strength` (before range losses) from range `range` [m]: the echo
  // of a point lasts while the pulse passes it, so it is heard at every range in [r, r + L), and
  // each bin gets the power times the fraction of the bin that span covers.
  // Range loss 10^(-((S - G)·log10 r + α·r)/10) = exp(-(S - G)/10 · ln r - α·ln10/10 · r).
  const double spreading_exponent = (a.spreading_db_per_decade - a.tvg_db_per_decade) / 10.0;
  const double absorption_per_m = a.absorption_db_per_m * std::log(10.0) / 10.0;
  auto deposit = [&](double range, double strength) {
    const double exponent =
        (spreading_exponent != 0.0 ? spreading_exponent * std::log(range) : 0.0) +
        absorption_per_m * range;
    const double power = strength * std::exp(-exponent);
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
  double weight_sum = 0.0;
  for (int i = 0; i < a.rays_horizontal; ++i) {
    for (int j = 0; j < a.rays_vertical; ++j) {
      const double theta = ((i + rng.Uniform()) / a.rays_horizontal - 0.5) * width_h;
      const double epsilon = ((j + rng.Uniform()) / a.rays_vertical - 0.5) * width_v;
      const double pattern = std::exp(-k_h * theta * theta - k_v * epsilon * epsilon);
      weight_sum += pattern;
      const Eigen::Vector3f direction =
          (R_world_beam * mapping::SonarRayDirection(theta, epsilon)).cast<float>();
      ++out.traced_rays;
      const auto hit = tracer_.Intersect(origin, direction, static_cast<float>(max_range));
      if (!hit) continue;
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
    if (a.speckle) signal *= rng.Exponential();
    const double power = signal + noise_power * rng.Exponential();
    out.beam.intensities[k] = Quantise(10.0 * std::log10(std::max(power, 1e-30)));
  }
  return out;
}

}  // namespace sonarbench::sim
