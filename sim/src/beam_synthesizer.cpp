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
  double weight_sum = 0.0;
  for (int i = 0; i < a.rays_horizontal; ++i) {
    for (int j = 0; j < a.rays_vertical; ++j) {
      const double theta = ((i + rng.Uniform()) / a.rays_horizontal - 0.5) * width_h;
      const double epsilon = ((j + rng.Uniform()) / a.rays_vertical - 0.5) * width_v;
      const double pattern = std::exp(-k_h * theta * theta - k_v * epsilon * epsilon);
      weight_sum += pattern;
      const Eigen::Vector3f direction =
          (R_world_beam * mapping::SonarRayDirection(theta, epsilon)).cast<float>();
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
      // One specular bounce: the mirrored ray's first hit echoes back along the same path, so it
      // is heard at range d1 + d2, through two specular reflections at the first surface.
      if (material.specular > 0.0) {
        const Eigen::Vector3f mirrored =
            (direction - 2.0f * direction.dot(hit->normal) * hit->normal).normalized();
        const Eigen::Vector3f from = origin + hit->distance * direction + 1e-4f * mirrored;
        const auto second =
            tracer_.Intersect(from, mirrored, static_cast<float>(max_range - range));
        if (second) {
          const Material& far = materials_by_mesh_[second->mesh];
          const double cos_far = std::abs(second->normal.dot(mirrored));
          deposit(range + second->distance, pattern * material.specular * material.specular *
                                                far.reflectivity *
                                                CosPower(cos_far, far.backscatter_exponent));
        }
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
