#include "sonarbench/sim/sonar/beam_synthesizer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "beam_job.hpp"
#include "sonarbench/sim/world/random.hpp"

namespace sonarbench::sim {

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
      scene_glints_(
          std::ranges::any_of(materials_by_mesh_, [](const Material& m) { return m.glint > 0.0; })),
      receiver_(sensor),
      pattern_(sensor),
      speckle_(SpeckleSectorsFor(sensor)),
      self_reflection_(sensor, run_seed) {
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
}

void BeamSynthesizer::BeamJob::SeedPlace() {
  std::vector<std::uint64_t>& sector_seeds = scratch_.sector_seeds;
  const bool own = a_.speckle.own_share > 0.0;
  const int sector_reach = static_cast<int>((s_.speckle_.weights.size() - (own ? 1 : 0)) / 2);
  sector_seeds.resize(s_.speckle_.weights.size());
  if (a_.speckle.correlation_m <= 0.0) return;
  const double step = g_.step_angle_rad;
  const long long turn = std::llround(2.0 * std::numbers::pi / step);
  const Eigen::Vector3d axis = R_world_beam_.col(0);
  const long long azimuth = std::llround(std::atan2(axis.y(), axis.x()) / step);
  const long long tilt = std::llround(std::asin(std::clamp(axis.z(), -1.0, 1.0)) / step);
  std::array<std::uint64_t, 3> cells{};
  for (int i = 0; i < 3; ++i) {
    const double cell = std::floor(T_world_sonar_.translation()[i] / a_.speckle.correlation_m);
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
  weight_sum_ = s_.pattern_.DrawRays(R_world_beam_, *echo_rng_, directions, patterns);
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
  EchoDeposit sidelobe_deposit = PathDeposit(0);
  const double bins_per_m = 1.0 / g_.bin_size_m;
  const double pulse_bins = a_.pulse.length_m * bins_per_m;
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
    // The range loss once for every deposit of this return (each echo's power after it).
    const double loss = s_.receiver_.RangeLossFromTable(range);
    if (on_vehicle) {
      vehicle_deposit.AddPower(range, (diffuse + glint) * loss);
    } else {
      deposit.AddPower(range, diffuse * loss);
      if (glint > 0.0) glint_deposit.AddPower(range, glint * loss);
      if (labels_ && r < main_lobe_rays) {
        const double start = range * bins_per_m;
        scratch_.labels.AddDirect(start, start + pulse_bins, (diffuse + glint) * loss, hit->mesh,
                                  static_cast<float>(range), direction);
      } else if (labels_) {
        sidelobe_deposit.AddPower(range, (diffuse + glint) * loss);
      }
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

void BeamSynthesizer::BeamJob::FormLevels(EchoPower echo_power) {
  TraceAxis();
  SumEchoes();
  DrawPowers();
  out_.beam.intensities.resize(bins_);
  std::uint8_t* const levels = out_.beam.intensities.data();
  s_.receiver_.Convert(scratch_.powers, levels);
  // The receiver off while the head transmits: after the draws, so the other bins' are the same.
  for (std::size_t k = 0; k < bins_; ++k) {
    if (static_cast<double>(k) * g_.bin_size_m >= a_.noise.blanking_range_m) break;
    levels[k] = 0;
  }
  if (echo_power == EchoPower::kKeep) out_.echo_power = scratch_.echo_power;
}

void BeamSynthesizer::BeamJob::TraceAxis() {
  if (const auto axis =
          s_.tracer_.Intersect(origin_, (R_world_beam_ * Eigen::Vector3d::UnitX()).cast<float>(),
                               static_cast<float>(max_range_))) {
    out_.truth.axis_hit_range_m = axis->distance;
  }
  ++out_.traced_rays;
}

void BeamSynthesizer::BeamJob::SumEchoes() {
  std::vector<double>& echo = scratch_.echo_power;
  scratch_.spreader.AddTo(echo);
  for (double& power : echo) power /= weight_sum_;
  AddPulseSkirts(s_.sensor_, echo);
  if (labels_) LabelScenePaths();
  if (HasSecondTrip(a_)) {
    for (double& power : scratch_.impulse_power) power /= weight_sum_;
    if (labels_) scratch_.labels.before = echo;
    AddSecondTrip(s_.sensor_, s_.receiver_, echo, scratch_.impulse_power);
    if (labels_) LabelAdded(EchoPath::kSecondTrip);
  }
  DrawSpeckle();
  if (labels_) scratch_.labels.before = echo;
  AddReverberation(s_.sensor_, echo);
  if (labels_) LabelAdded(EchoPath::kReverberation);
  // A glint is the sonar's mirror image, sound that came straight back: it has the pulse's
  // skirts like any echo, but feeds no reverberation and no second trip (the real tank is quiet
  // behind walls met squarely: docs/fidelity.md, behind the walls).
  if (s_.scene_glints_) AddApart(scratch_.glint_spreader, true);
  // The vehicle's echoes are heard as they are: the real log's show no skirts, second trip or
  // reverberation (behind the SHAD's own echo at 0.3 m its beams at head angle 0° are silent
  // from 0.55 m to the floor at 1.45 m), so those are the tank's answers to its own echoes.
  if (s_.vehicle_tracer_) {
    AddApart(scratch_.vehicle_spreader, false);
    if (labels_) LabelPower(EchoPath::kVehicle) = scratch_.apart_power;  // what AddApart added
  }
}

// Echoes heard apart from the scene's diffuse ones, after its second trip and reverberation: a
// spreader's bins, with the pulse's skirts if `skirts`.
void BeamSynthesizer::BeamJob::AddApart(PulseSpreader& spreader, bool skirts) {
  std::vector<double>& apart = scratch_.apart_power;
  apart.assign(bins_, 0.0);
  spreader.AddTo(apart);
  for (double& power : apart) power /= weight_sum_;
  if (skirts) AddPulseSkirts(s_.sensor_, apart);
  std::vector<double>& echo = scratch_.echo_power;
  for (std::size_t k = 0; k < bins_; ++k) echo[k] += apart[k];
}

void BeamSynthesizer::BeamJob::DrawSpeckle() {
  if (!a_.speckle.on) return;
  std::vector<double>& speckle = scratch_.speckle;
  speckle.resize(bins_);
  if (place_rng_) {
    SectorSpeckle(speckle, s_.speckle_.window, s_.speckle_.weights, scratch_.sector_seeds,
                  a_.speckle.looks);
  } else {
    CorrelatedSpeckle(speckle, s_.speckle_.window, *echo_rng_, a_.speckle.looks);
  }
}

// The powers first, then their levels: no 8-bit store inside the loop that draws the noise. The
// self-reflection is the sonar's own, not the place's: added after the speckle.
void BeamSynthesizer::BeamJob::DrawPowers() {
  const double gain = std::pow(10.0, a_.gain.gain_db / 10.0);
  const std::vector<double>& echo = scratch_.echo_power;
  const std::vector<double>& speckle = scratch_.speckle;
  std::vector<double>& self_reflection = scratch_.self_reflection;
  s_.self_reflection_.Draw(head_angle_rad_, rng_, self_reflection);
  const std::span<const double> noise_at_bin = s_.receiver_.NoiseAtBin();
  std::vector<double>& powers = scratch_.powers;
  powers.resize(bins_);
  for (std::size_t k = 0; k < bins_; ++k) {
    double signal = gain * echo[k];
    if (a_.speckle.on) signal *= speckle[k];
    if (k < self_reflection.size()) signal += self_reflection[k];
    const double noise = noise_at_bin[k] * rng_.Exponential();
    powers[k] = signal + noise;
    if (labels_) LabelPower(EchoPath::kNoise)[k] = noise;
  }
  if (labels_) FinishLabels(self_reflection);
  // The receiver's level jitter, the ping's whatever the echoes are.
  s_.receiver_.Jitter(powers, rng_);
}

SynthesizedBeam BeamSynthesizer::Synthesize(double time_s, double head_angle_rad,
                                            const Eigen::Isometry3d& T_world_sonar,
                                            std::uint64_t seed, EchoPower echo_power,
                                            Labels labels) const {
  SynthesizedBeam out;
  SynthesizeInto(time_s, head_angle_rad, T_world_sonar, seed, echo_power, labels, out);
  return out;
}

void BeamSynthesizer::SynthesizeInto(double time_s, double head_angle_rad,
                                     const Eigen::Isometry3d& T_world_sonar, std::uint64_t seed,
                                     EchoPower echo_power, Labels labels,
                                     SynthesizedBeam& out) const {
  std::vector<std::uint8_t> intensities = std::move(out.beam.intensities);
  std::vector<double> power = std::move(out.echo_power);
  std::vector<BinLabel> bin_labels = std::move(out.labels);
  out = SynthesizedBeam{};
  intensities.clear();
  power.clear();
  // Kept at their size with labels: FinishLabels writes every field of every bin's.
  if (labels != Labels::kKeep) bin_labels.clear();
  out.beam.intensities = std::move(intensities);
  out.echo_power = std::move(power);
  out.labels = std::move(bin_labels);
  out.beam.time_s = time_s;
  out.beam.head_angle_rad = head_angle_rad;
  out.beam.T_world_sonar = T_world_sonar;
  out.truth.T_world_sonar = T_world_sonar;
  out.beam.bin_size_m = sensor_.geometry.bin_size_m;
  thread_local Scratch scratch;
  BeamJob job(*this, head_angle_rad, T_world_sonar, seed, scratch, out, labels);
  job.SeedPlace();
  job.TracePrimaries();
  job.TraceMultipath();
  job.FormLevels(echo_power);
}

}  // namespace sonarbench::sim
