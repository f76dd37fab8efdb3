#include "sonarbench/sim/sonar/multipath.hpp"

#include <cmath>
#include <numbers>

#include "beam_job.hpp"

namespace sonarbench::sim {

MirrorSpread::MirrorSpread() {
  // A standard 2-D Gaussian offset has a Rayleigh radius, P(radius ≤ ρ) = 1 - exp(-ρ²/2), and a
  // uniform direction: radius quantiles times evenly spaced directions.
  offsets_.reserve(kSpreadOffsets);
  for (int i = 0; i < 64; ++i) {
    const double radius = std::sqrt(-2.0 * std::log(1.0 - (i + 0.5) / 64.0));
    for (int j = 0; j < 64; ++j) {
      const double angle = 2.0 * std::numbers::pi * (j + 0.5) / 64.0;
      offsets_.emplace_back(static_cast<float>(radius * std::cos(angle)),
                            static_cast<float>(radius * std::sin(angle)));
    }
  }
}

Eigen::Vector3f MirrorSpread::Tilt(const Eigen::Vector3f& unit, float sigma, Rng& rng) const {
  static_assert((kSpreadOffsets & (kSpreadOffsets - 1)) == 0, "offsets are picked by a mask");
  const Eigen::Vector2f tilt = sigma * offsets_[(rng.Next() >> 32) & (kSpreadOffsets - 1)];
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

Eigen::Vector3f MirrorSpread::Spread(const Eigen::Vector3f& mirror, const Eigen::Vector3f& normal,
                                     const Material& material, Rng& rng) const {
  if (material.specular_spread_rad <= 0.0) return mirror;
  Eigen::Vector3f spread = Tilt(mirror, static_cast<float>(material.specular_spread_rad), rng);
  // A direction into the surface is mirrored back out of it.
  const float side = spread.dot(normal);
  if ((side > 0.0f) != (mirror.dot(normal) > 0.0f)) spread -= 2.0f * side * normal;
  return spread;
}

// Multipath, one bounce at a time for all the beam's rays (each bounce's mirrored rays one
// stream, their occlusion rays another): a ray with two-way pattern weight `pattern` goes on in
// the mirror direction with the specular fraction of its energy, up to max_bounces times. At
// each later hit P_k, after a path of length L from the sonar, two returns:
//  - back through the same mirrors: range L, weight pattern · s² · ρ cosⁿ, where s is the
//    product of the specular fractions so far and pattern the two-way pattern of the way out
//    and back (ReturnPattern);
//  - straight back to the sonar if P_k is in view (an occlusion ray) and in the receive pattern
//    (the back lobe's too): range R = (L + d)/2 with d = |P_k - sonar|, weight 2 · √pattern ·
//    p(P_k) · s · ρ (cos_i cos_s)^(n/2) · (R/d)^(S/10); p is the one-way pattern towards P_k,
//    the factor 2 counts the reverse path (sonar → P_k → mirrors → sonar), equal by
//    reciprocity, and (R/d)^(S/10) turns the monostatic spreading at R into the last leg's own.
void BeamSynthesizer::BeamJob::TraceMultipath() {
  const OneWayPattern one_way_pattern{R_world_beam_.transpose(), s_.pattern_};
  for (int bounce = 1; bounce <= a_.max_bounces && !scratch_.paths.empty(); ++bounce) {
    MirrorPaths();
    HearMirrorPaths(one_way_pattern);
    HearStraightReturns();
  }
}

// The two-way pattern of the way out and back along a mirror path ending at p's hit. Through
// perfect mirrors the echo comes back along the way out: the ray's own two-way pattern.
// Through rough ones the way back is a path of its own, each rough mirror tilting it
// independently: it arrives from the direction of the end point's image, off by a 2-D
// Gaussian angle of variance Σ σ² (1 - s/L)² per axis (a tilt at path length s moves the
// image seen from the sonar by (L - s)/L of it), and the receive pattern is averaged over it.
double BeamSynthesizer::BeamJob::ReturnPattern(const MirrorPath& p,
                                               const OneWayPattern& one_way_pattern) const {
  if (p.blur[0] <= 0.0) return p.pattern;
  const Eigen::Vector3f image = p.image + p.unfold * (p.hit.distance * p.direction);
  const double inverse = 1.0 / p.path;
  const double blur =
      std::max(p.blur[0] - 2.0 * p.blur[1] * inverse + p.blur[2] * inverse * inverse, 0.0);
  return std::sqrt(p.pattern) * one_way_pattern(image.cast<double>().normalized(), blur);
}

void BeamSynthesizer::BeamJob::MirrorPaths() {
  const double max_range = max_range_;
  std::vector<MirrorPath>& paths = scratch_.paths;
  std::vector<MirrorPath>& next_paths = scratch_.next_paths;
  std::vector<Ray>& stream = scratch_.rays;
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
    const Eigen::Vector3f direction = s_.mirror_spread_.Spread(
        (was.direction - 2.0f * was.direction.dot(was.hit.normal) * was.hit.normal).normalized(),
        was.hit.normal, mirror, *echo_rng_);
    p.direction = direction;
    stream.push_back(
        {from + 1e-4f * direction, direction, static_cast<float>(2.0 * max_range - was.path)});
  }
  scratch_.hits.resize(stream.size());
  s_.tracer_.IntersectStream(stream, scratch_.hits);
  out_.traced_rays += stream.size();
}

void BeamSynthesizer::BeamJob::HearMirrorPaths(const OneWayPattern& one_way_pattern) {
  const double max_range = max_range_;
  EchoDeposit deposit = Deposit();
  EchoDeposit glint_deposit = GlintDeposit();
  EchoDeposit label_deposit = PathDeposit(1);
  std::vector<MirrorPath>& paths = scratch_.paths;
  const std::vector<MirrorPath>& next_paths = scratch_.next_paths;
  const std::vector<std::optional<Hit>>& hits = scratch_.hits;
  paths.clear();
  scratch_.rays.clear();
  scratch_.returns.clear();
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
      const double way = ReturnPattern(p, one_way_pattern) * was.specular * was.specular;
      const double diffuse = way * m.reflectivity * CosPower(cos_in, m.backscatter_exponent);
      deposit(path, diffuse);
      const double glint = way * Glint(m, 2.0 * cos_in * cos_in - 1.0);
      if (glint > 0.0) glint_deposit(path, glint);
      if (labels_) label_deposit(path, diffuse + glint);
    }
    QueueStraightReturn(was, hit, m, path, cos_in, one_way_pattern);
  }
}

void BeamSynthesizer::BeamJob::QueueStraightReturn(const MirrorPath& was, const Hit& hit,
                                                   const Material& m, double path, double cos_in,
                                                   const OneWayPattern& one_way_pattern) {
  const Eigen::Vector3d sonar = T_world_sonar_.translation();
  const Eigen::Vector3f at = was.from + hit.distance * was.direction;
  const Eigen::Vector3d back = sonar - at.cast<double>();
  const double d = back.norm();
  const double range = 0.5 * (path + d);
  if (range > max_range_ || d < g_.bin_size_m) return;
  // Culled on the largest its law can give: ρ for the diffuse part, g for the glint. First
  // on a bound of the receive pattern, which spares most returns from ahead its
  // trigonometry and culls only what the pattern itself would (0.999 leaves rounding a
  // margin); the weight keeps its own order of products, so its bits do not change.
  const Eigen::Vector3d u = one_way_pattern.R_beam_world * (-back / d);
  const double way_out = 2.0 * std::sqrt(was.pattern);  // both ways round the path
  const double largest = std::max(m.reflectivity, m.glint);
  if (way_out * was.specular * s_.pattern_.OneWayPatternBound(u) * largest <
      0.999 * kNegligibleWeight) {
    return;
  }
  const double weight = way_out * s_.pattern_.OneWayPatternTowards(u) * was.specular;
  if (weight * largest < kNegligibleWeight) return;
  const Eigen::Vector3f to_sonar = (back / d).cast<float>();
  const double cos_out = std::abs(hit.normal.dot(to_sonar));
  double glint = 0.0;  // towards the sonar from the mirror direction, if m glints
  if (m.glint > 0.0) {
    const Eigen::Vector3f mirror =
        was.direction - 2.0f * was.direction.dot(hit.normal) * hit.normal;
    glint = Glint(m, static_cast<double>(mirror.dot(to_sonar)));
  }
  scratch_.rays.push_back({at + 1e-4f * to_sonar, to_sonar, static_cast<float>(d) - 2e-4f});
  const double last_leg = std::pow(range / d, a_.gain.spreading_db_per_decade / 10.0);
  scratch_.returns.push_back(
      {range,
       weight * m.reflectivity * CosPower(cos_in * cos_out, 0.5 * m.backscatter_exponent) *
           last_leg,
       weight * glint * last_leg});
}

void BeamSynthesizer::BeamJob::HearStraightReturns() {
  EchoDeposit deposit = Deposit();
  EchoDeposit glint_deposit = GlintDeposit();
  EchoDeposit label_deposit = PathDeposit(1);
  const std::vector<StraightReturn>& returns = scratch_.returns;
  s_.tracer_.OccludedStream(scratch_.rays, scratch_.occluded);
  out_.traced_rays += scratch_.rays.size();
  for (std::size_t q = 0; q < returns.size(); ++q) {
    if (scratch_.occluded[q]) continue;
    deposit(returns[q].range, returns[q].weight);
    if (returns[q].glint > 0.0) glint_deposit(returns[q].range, returns[q].glint);
    if (labels_) label_deposit(returns[q].range, returns[q].weight + returns[q].glint);
  }
}

}  // namespace sonarbench::sim
