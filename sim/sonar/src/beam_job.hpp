#pragma once

// BeamSynthesizer's private parts: one beam's job, its working memory and the echoes it
// deposits; shared by beam_synthesizer.cpp and multipath.cpp.

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "sonarbench/sim/sonar/beam_pattern.hpp"
#include "sonarbench/sim/sonar/beam_synthesizer.hpp"
#include "sonarbench/sim/sonar/pulse_spreader.hpp"
#include "sonarbench/sim/sonar/range_spread.hpp"
#include "sonarbench/sim/sonar/receiver.hpp"

namespace sonarbench::sim {

// A bistatic return whose weight, one ray's, is under this is not worth the occlusion ray. A
// perfect reflector filling the beam sums all its rays' pattern weights (about 420 for the
// Micron's 640), so one such return lies about 86 dB under that echo, and a beam's few thousand
// of them together about 50 dB: under the AD window's 40 dB.
constexpr double kNegligibleWeight = 1e-6;

// cosⁿ, with the exponents scenes use most spared a pow().
inline double CosPower(double c, double n) {
  if (n == 1.0) return c;
  if (n == 0.5) return std::sqrt(c);
  if (n == 2.0) return c * c;
  return std::pow(c, n);
}

// A rough mirror's glint towards a receiver whose direction makes cos_alpha with the mirror
// direction (Material::glint): g exp(-α²/2σ²); 0 without one.
inline double Glint(const Material& m, double cos_alpha) {
  if (m.glint <= 0.0) return 0.0;
  const double alpha = std::acos(std::clamp(cos_alpha, -1.0, 1.0));
  const double z = alpha / m.specular_spread_rad;
  return m.glint * std::exp(-0.5 * z * z);
}

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
  EchoDeposit(const Receiver& receiver, const mapping::SensorGeometry& geometry,
              double pulse_length_m, bool second_trip, PulseSpreader& spreader,
              std::vector<double>& impulse)
      : receiver_(receiver),
        pulse_bins_(pulse_length_m / geometry.bin_size_m),
        bins_per_m_(1.0 / geometry.bin_size_m),
        bins_(static_cast<std::size_t>(geometry.num_bins)),
        second_trip_(second_trip),
        spreader_(spreader),
        impulse_(impulse) {}

  // Inlined, with the range loss from its table (RangeLossFromTable): a call per ray cost more
  // than the work (synthesis_bench).
  [[gnu::always_inline]] void operator()(double range, double strength) {
    AddPower(range, strength * receiver_.RangeLossFromTable(range));
  }
  // The same for an echo whose range loss is already in `power`.
  [[gnu::always_inline]] void AddPower(double range, double power) {
    const double start = range * bins_per_m_;
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
  const Receiver& receiver_;
  double pulse_bins_;
  double bins_per_m_;
  std::size_t bins_;
  bool second_trip_;
  PulseSpreader& spreader_;
  std::vector<double>& impulse_;
};

// A beam's one-way pattern towards a world direction (unit), R_beam_world taking world
// directions into the beam's frame (BeamPattern::OneWayPatternTowards).
struct OneWayPattern {
  Eigen::Matrix3d R_beam_world;
  const BeamPattern& pattern;

  double operator()(const Eigen::Vector3d& towards, double blur = 0.0) const {
    return pattern.OneWayPatternTowards(R_beam_world * towards, blur);
  }
};

// One scene mesh's main-lobe direct returns in a beam, for the labels: their power per bin,
// and per start bin (the bin the return's range falls in) the strongest's power after the range
// loss and its point relative to the sonar (world frame, m). Reset when a beam gives it a slot
// (LabelScratch::NewSlot); the spreader emptied by LabelScenePaths.
struct MeshDirect {
  PulseSpreader spreader;
  std::vector<double> power;
  std::vector<double> strongest;
  std::vector<Eigen::Vector3f> point;
};

// The labels' working memory (Labels::kKeep): the scene's echoes off the main lobe's direct
// path (sidelobe, multipath); the direct path's by mesh, each mesh met in the beam given a slot;
// each path's power per bin, and the echo before a step that adds one.
struct LabelScratch {
  std::array<PulseSpreader, 2> spreaders;  // sidelobe, multipath
  std::vector<MeshDirect> meshes;          // by slot
  std::vector<std::int32_t> slot_of_mesh;  // -1: not met in this beam
  std::vector<std::uint32_t> mesh_of_slot;
  std::array<std::vector<double>, kEchoPaths> power;
  std::vector<double> before;

  // A main-lobe direct return: `echo`, its power after the range loss, per bin over [start,
  // end) bins, from mesh `mesh` at `range` [m] along the unit `direction` (world frame).
  [[gnu::always_inline]] void AddDirect(double start, double end, double echo, std::uint32_t mesh,
                                        float range, const Eigen::Vector3f& direction) {
    std::int32_t slot = slot_of_mesh[mesh];
    if (slot < 0) slot = NewSlot(mesh);
    MeshDirect& m = meshes[static_cast<std::size_t>(slot)];
    m.spreader.Add(start, end, echo);
    if (!(start < static_cast<double>(m.strongest.size()))) return;
    const auto k = static_cast<std::size_t>(start);
    if (echo > m.strongest[k]) {
      m.strongest[k] = echo;
      m.point[k] = range * direction;
    }
  }
  std::int32_t NewSlot(std::uint32_t mesh);
};

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
  LabelScratch labels;
};

// One beam's synthesis: what its steps share, each step a method. Synthesize() runs them in
// the order declared; each takes what the ones before it left in the job and the scratch.
class BeamSynthesizer::BeamJob {
 public:
  BeamJob(const BeamSynthesizer& synthesizer, double head_angle_rad,
          const Eigen::Isometry3d& T_world_sonar, std::uint64_t seed, Scratch& scratch,
          SynthesizedBeam& out, Labels labels)
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
    if (HasSecondTrip(a_)) scratch_.impulse_power.assign(bins_, 0.0);
    scratch_.echo_power.assign(bins_, 0.0);
    if (labels == Labels::kKeep) StartLabels();
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
  // The labels' steps (bin_labels.cpp): their scratch readied; the direct and sidelobe paths'
  // powers; the power a step adds (`scratch_.labels.before` taken before it) as `path`'s; and
  // each bin's label from the paths, the speckle, the self-reflection and the noise.
  void StartLabels();
  void LabelScenePaths();
  void LabelAdded(EchoPath path);
  void FinishLabels(std::span<const double> self_reflection);
  void LabelMeshes();
  [[nodiscard]] std::vector<double>& LabelPower(EchoPath path) {
    return scratch_.labels.power[static_cast<std::size_t>(path)];
  }

  // TraceMultipath's steps: each path mirrored on and traced to its next hit; the echoes heard
  // back along the mirrors, the straight returns collected; those not occluded heard.
  void MirrorPaths();
  void HearMirrorPaths(const OneWayPattern& one_way_pattern);
  // Queues the straight return from a mirror path's hit to the sonar, unless it is out of range
  // or too weak to count: its ray (checked for occlusion later) and its range and weights.
  void QueueStraightReturn(const MirrorPath& was, const Hit& hit, const Material& m, double path,
                           double cos_in, const OneWayPattern& one_way_pattern);
  void HearStraightReturns();
  // The two-way pattern of the way out and back along a mirror path ending at p's hit.
  [[nodiscard]] double ReturnPattern(const MirrorPath& p,
                                     const OneWayPattern& one_way_pattern) const;
  // FormLevels' steps: the axis's truth; the echo's bins with its spreads and the echoes heard
  // apart; the speckle's factors; the powers with self-reflection, noise and jitter.
  void TraceAxis();
  void SumEchoes();
  void AddApart(PulseSpreader& spreader, bool skirts);
  void DrawSpeckle();
  void DrawPowers();

  EchoDeposit Deposit() {
    return {s_.receiver_,          g_, a_.pulse.length_m, HasSecondTrip(a_), scratch_.spreader,
            scratch_.impulse_power};
  }
  // The vehicle's echoes: the pulse alone, no second trip (FormLevels adds them after the
  // scene's skirts, second trip and reverberation).
  EchoDeposit VehicleDeposit() {
    return {s_.receiver_,          g_, a_.pulse.length_m, false, scratch_.vehicle_spreader,
            scratch_.impulse_power};
  }
  // The labels' echoes of one path off the main lobe's direct one (0 sidelobe, 1 multipath):
  // the pulse alone.
  EchoDeposit PathDeposit(std::size_t path) {
    return {s_.receiver_,          g_, a_.pulse.length_m, false, scratch_.labels.spreaders[path],
            scratch_.impulse_power};
  }
  // The scene's glints: the pulse and its skirts, no second trip or reverberation (FormLevels).
  EchoDeposit GlintDeposit() {
    return {s_.receiver_,          g_, a_.pulse.length_m, false, scratch_.glint_spreader,
            scratch_.impulse_power};
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
  // Whether the beam carries its bins' labels.
  bool labels_ = false;
};

}  // namespace sonarbench::sim
