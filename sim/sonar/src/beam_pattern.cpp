#include "sonarbench/sim/sonar/beam_pattern.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

namespace sonarbench::sim {
namespace {

// An upper bound on exp(-x) within a factor of 2 and without exp(): 2^-⌊x log₂e⌋, built from
// its exponent bits (0 past 2^-1000; infinity for x < 0, where it is not needed).
double ExpBound(double x) {
  const double octaves = std::floor(x * std::numbers::log2e);
  if (!(octaves >= 0.0)) return std::numeric_limits<double>::infinity();
  if (octaves >= 1000.0) return 0.0;
  return std::bit_cast<double>(static_cast<std::uint64_t>(1023 - static_cast<int>(octaves)) << 52);
}

// The slots of `strata` strata: slot a of stratum i at the angle angle_at((i + (a + ½)/slots)
// / strata), with the factor factor(angle).
template <typename Slot, typename AngleAt, typename Factor>
std::vector<Slot> Tabulate(int strata, const AngleAt& angle_at, const Factor& factor) {
  constexpr int kSlots = BeamPattern::kJitterSlots;
  std::vector<Slot> slots;
  for (int i = 0; i < strata; ++i) {
    for (int slot = 0; slot < kSlots; ++slot) {
      const double angle = angle_at((i + (slot + 0.5) / kSlots) / strata);
      slots.push_back({std::sin(angle), std::cos(angle), factor(angle)});
    }
  }
  return slots;
}

// Angles across an aperture [rad] centred on the axis, for fractions 0..1 of it.
auto Centred(double aperture) {
  return [aperture](double fraction) { return (fraction - 0.5) * aperture; };
}

}  // namespace

BeamPattern::BeamPattern(const SensorModel& sensor) : acoustics_(sensor.acoustics) {
  const Acoustics& a = acoustics_;
  const mapping::SensorGeometry& g = sensor.geometry;
  // Slot a of stratum i sits at (i + (a + ½)/slots)/strata of the aperture (scaled by the
  // aperture scale), centred on the axis; its pattern factor is exp(-k · angle²), so the two
  // directions' factors multiply to the two-way pattern.
  pattern_k_h_ = 4.0 * std::log(2.0) / (g.beam_width_horizontal_rad * g.beam_width_horizontal_rad);
  pattern_k_v_ = 4.0 * std::log(2.0) / (g.beam_width_vertical_rad * g.beam_width_vertical_rad);
  if (a.pattern.sidelobe_extent_deg > 0.0) {
    sidelobe_level_ = std::pow(10.0, a.pattern.sidelobe_db / 10.0);
    sidelobe_width2_ = std::pow(a.pattern.sidelobe_width_deg * mapping::kDegToRad, 2);
    sidelobe_extent_rad_ = a.pattern.sidelobe_extent_deg * mapping::kDegToRad;
    // 1e-9 over: past it atan2 can round no azimuth back inside the extent.
    sidelobe_extent_sin2_ = std::pow(std::sin(sidelobe_extent_rad_), 2) * (1.0 + 1e-9);
  }
  const auto horizontal = [&](double angle) {
    return std::exp(-pattern_k_h_ * angle * angle) + SidelobePattern(angle);
  };
  const auto vertical = [&](double angle) { return std::exp(-pattern_k_v_ * angle * angle); };
  const double aperture_h = a.pattern.aperture_scale_horizontal * g.beam_width_horizontal_rad;
  const double aperture_v = a.pattern.aperture_scale_vertical * g.beam_width_vertical_rad;
  horizontal_slots_ =
      Tabulate<JitterSlot>(a.pattern.rays_horizontal, Centred(aperture_h), horizontal);
  vertical_slots_ = Tabulate<JitterSlot>(a.pattern.rays_vertical, Centred(aperture_v), vertical);
  if (a.pattern.sidelobe_extent_deg > 0.0) {
    // A sidelobe ray stands for a stratum wider than a main-lobe ray's in both directions: its
    // pattern factor carries the ratio of their solid angles, so the weights stay the pattern's
    // integral over the rays' strata.
    const double span = sidelobe_extent_rad_ - 0.5 * aperture_h;
    const double area =
        (span / a.pattern.sidelobe_rays_horizontal) / (aperture_h / a.pattern.rays_horizontal) *
        (static_cast<double>(a.pattern.rays_vertical) / a.pattern.sidelobe_rays_vertical);
    sidelobe_horizontal_slots_ = Tabulate<JitterSlot>(
        a.pattern.sidelobe_rays_horizontal,
        [&](double fraction) { return 0.5 * aperture_h + fraction * span; },
        [&](double angle) { return area * horizontal(angle); });
    sidelobe_vertical_slots_ =
        Tabulate<JitterSlot>(a.pattern.sidelobe_rays_vertical, Centred(aperture_v), vertical);
  }
  if (a.pattern.back_lobe_width_deg > 0.0) TabulateBackLobe(aperture_h, aperture_v);
}

void BeamPattern::TabulateBackLobe(double aperture_h, double aperture_v) {
  const Acoustics& a = acoustics_;
  back_level_ = std::pow(10.0, a.pattern.back_lobe_db / 10.0);
  const double sigma = a.pattern.back_lobe_width_deg * mapping::kDegToRad;
  back_k_ = 1.0 / (sigma * sigma);
  // Strata over ±min(3σ, 90°) about the axis behind in both directions. A stratum at
  // elevation ε spans Δφ cos ε · Δε of solid angle; a main-lobe ray stands for Δθ · Δε_main.
  const double span = 2.0 * std::min(3.0 * sigma, 0.5 * std::numbers::pi);
  const double stratum = span / a.pattern.back_lobe_rays;
  const double level = back_level_ * back_level_;
  back_horizontal_slots_ =
      Tabulate<JitterSlot>(a.pattern.back_lobe_rays, Centred(span), [&](double angle) {
        return level * std::exp(-back_k_ * angle * angle) * stratum /
               (aperture_h / a.pattern.rays_horizontal);
      });
  back_vertical_slots_ =
      Tabulate<JitterSlot>(a.pattern.back_lobe_rays, Centred(span), [&](double angle) {
        return std::exp(-back_k_ * angle * angle) * std::cos(angle) * stratum /
               (aperture_v / a.pattern.rays_vertical);
      });
}

double BeamPattern::BackLobePattern(const Eigen::Vector3d& u, double blur) const {
  if (back_level_ <= 0.0) return 0.0;
  const double phi = std::atan2(u.y(), -u.x());
  const double epsilon = std::asin(std::clamp(u.z(), -1.0, 1.0));
  // exp(-k θ²/2) per direction, each averaged over a Gaussian offset of variance `blur`.
  const double wide = 1.0 + back_k_ * blur;
  return back_level_ * std::exp(-0.5 * back_k_ * (phi * phi + epsilon * epsilon) / wide) / wide;
}

double BeamPattern::OneWayPatternTowards(const Eigen::Vector3d& u, double blur) const {
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

double BeamPattern::OneWayPatternBound(const Eigen::Vector3d& u) const {
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

double BeamPattern::SidelobePattern(double theta) const {
  // Without sidelobes θ_s² is 0 too: return before 0/0 on the axis.
  if (sidelobe_level_ <= 0.0 || !(std::abs(theta) <= sidelobe_extent_rad_)) return 0.0;
  const double falloff = sidelobe_width2_ / (sidelobe_width2_ + theta * theta);
  return sidelobe_level_ * falloff * falloff;
}

double BeamPattern::DrawRays(const Eigen::Matrix3d& R_world_beam, Rng& rng,
                             std::vector<Eigen::Vector3f>& directions,
                             std::vector<double>& patterns) const {
  const Acoustics& a = acoustics_;
  directions.resize(PrimaryRays(a));
  patterns.resize(directions.size());
  double weight_sum = 0.0;
  const Eigen::Vector3d ahead = R_world_beam.col(0);
  const Eigen::Vector3d left = R_world_beam.col(1);
  const Eigen::Vector3d up = R_world_beam.col(2);
  constexpr unsigned kSlotMask = kJitterSlots - 1;
  static_assert((kJitterSlots & kSlotMask) == 0, "slots are picked by masking a draw's bits");
  for (int i = 0, r = 0; i < a.pattern.rays_horizontal; ++i) {
    const JitterSlot* stratum_h = &horizontal_slots_[static_cast<std::size_t>(i) * kJitterSlots];
    for (int j = 0; j < a.pattern.rays_vertical; ++j, ++r) {
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
  if (a.pattern.sidelobe_extent_deg > 0.0) {
    for (const double side : {1.0, -1.0}) {
      draw_strata(sidelobe_horizontal_slots_, a.pattern.sidelobe_rays_horizontal,
                  sidelobe_vertical_slots_, a.pattern.sidelobe_rays_vertical, ahead, side, true);
    }
  }
  // The back lobe's, if PrimaryRays counted any, about the axis behind; their weights stay out
  // of the sum (Acoustics::back_lobe_width_deg).
  if (a.pattern.back_lobe_width_deg > 0.0) {
    draw_strata(back_horizontal_slots_, a.pattern.back_lobe_rays, back_vertical_slots_,
                a.pattern.back_lobe_rays, -ahead, 1.0, false);
  }
  return weight_sum;
}

}  // namespace sonarbench::sim
