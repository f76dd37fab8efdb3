#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/sim/random.hpp"
#include "sonarbench/sim/ray_tracer.hpp"
#include "sonarbench/sim/scene.hpp"

namespace sonarbench::sim {

/// What the simulator knows about one beam that the sonar does not report.
struct BeamTruth {
  /// Nearest surface any of the beam's rays hit [m], and the mesh it belongs to: the scene's
  /// surfaces only, never the vehicle's parts (a ray a part stops hits nothing behind it).
  std::optional<double> first_hit_range_m;
  std::uint32_t first_hit_mesh = 0;
  /// The scene's first hit along the beam axis, if within range (the vehicle's parts ignored).
  std::optional<double> axis_hit_range_m;
  /// The sonar's true pose, from which the beam was rendered.
  Eigen::Isometry3d T_world_sonar = Eigen::Isometry3d::Identity();
};

/// A simulated beam with its ground truth, plus the echo power before noise and quantisation.
struct SynthesizedBeam {
  mapping::Beam beam;
  BeamTruth truth;
  /// Noise-free echo power per bin [linear, relative to a perfect reflector at 1 m]; empty
  /// unless asked for (EchoPower::kKeep).
  std::vector<double> echo_power;
  /// Rays traced for it: primaries (and their vehicle's parts' bundle), mirrored rays,
  /// occlusion rays and the axis's ray for the truth (for speed reports).
  std::size_t traced_rays = 0;
};

/// Whether a synthesised beam carries its noise-free echo power (for tests and studies of the
/// echo itself). A scenario's beams drop it: 8 bytes per bin that nothing downstream reads.
enum class EchoPower { kKeep, kDrop };

/// Synthesises MSIS beams by tracing stratified-jittered rays across the beam's aperture.
///
/// The aperture is split into rays_horizontal × rays_vertical strata of angle; each ray takes
/// one of kJitterSlots evenly spaced positions within its stratum in each direction, drawn
/// afresh per ray and beam (a grid of 1/32 of a stratum: 0.007° across the default 35° fan).
/// The positions' sines, cosines and pattern factors are tabled at construction, so a ray's
/// direction and weight cost a draw and a few multiplications, not a sin, cos and exp each.
///
/// Each ray carries the beam pattern's two-way power b(θ, ε) = exp(-4 ln2 (θ²/w_h² + ε²/w_v²))
/// (-3 dB at the nominal edges), normalised so that the weights of all rays sum to 1. A ray
/// that hits a surface at range r with incidence angle φ adds
///     b · ρ · cosⁿ(φ) · 10^(-(S·log10 r + α·r - G·log10 r)/10)
/// to every bin that the pulse [r, r + L) overlaps, in proportion to the overlap, where ρ and n
/// are the material's reflectivity and backscatter exponent, S the spreading loss per decade, α
/// the two-way absorption and G the time-varied gain. Speckle multiplies each bin's power by an
/// exponential draw of mean 1, correlated over the range response (the pulse and its skirts:
/// SpeckleWindow; CorrelatedSpeckle) and, when
/// the speckle is the place's, shared by overlapping beams (SectorSpeckle); background noise and
/// the self-reflection profile add power; the level in dB is mapped to 0..255 by the AD window. In
/// a closed place (a tank) each bin's echo is shared with skirts in range around its pulse
/// (AddPulseSkirts), is heard again at the sum of two trips' ranges after the sonar head
/// reflects it back out (AddSecondTrip; the second trip reverberates on its way back as the
/// first trip does) and feeds a reverberation tail heard after it (AddReverberation), all
/// before speckle.
///
/// Parts of the vehicle the sonar hears (Scene::vehicle): its meshes in the vehicle's body
/// frame, where the sonar sits at the sensor's T_vehicle_sonar, and each one's material
/// (diffuse: specular 0).
struct VehicleParts {
  std::vector<TriangleMesh> meshes;
  std::vector<Material> materials;
};

/// Thread-safe: Synthesize() is const and draws only from a generator seeded by its argument.
class BeamSynthesizer {
 public:
  /// With `vehicle` parts, each primary ray is traced against them too (their own BVH, in the
  /// vehicle's frame, so one build serves every pose): a ray that meets a part before the
  /// scene echoes off the part, diffusely, and goes no further. Their echoes are not ground
  /// truth (BeamTruth counts the scene's surfaces only, where the rays reach them) and start
  /// no mirror paths; the multipath's rays pass the vehicle by.
  BeamSynthesizer(const SensorModel& sensor, const RayTracer& tracer,
                  std::vector<Material> materials_by_mesh, std::uint64_t run_seed = 0,
                  const VehicleParts& vehicle = {});

  /// One beam at head angle `head_angle_rad` from a sonar at `T_world_sonar`. `seed` drives its
  /// background noise and, unless the acoustics' speckle_correlation_m is set (then the run seed
  /// and the place do), its ray jitter and speckle. The beam's bytes do not depend on
  /// `echo_power`.
  [[nodiscard]] SynthesizedBeam Synthesize(double time_s, double head_angle_rad,
                                           const Eigen::Isometry3d& T_world_sonar,
                                           std::uint64_t seed,
                                           EchoPower echo_power = EchoPower::kKeep) const;

  /// A beam's primary rays, for a beam whose frame (x along its axis, z up the fan) is
  /// `R_world_beam`: rays_horizontal × rays_vertical, one per stratum, then the sidelobes' and
  /// the back lobe's (if any, PrimaryRays), each at a jitter slot in both directions picked by
  /// one draw from `rng`. Writes their world directions and two-way pattern weights; returns
  /// the sum of the main lobe's and the sidelobes' weights (the beam's normalisation).
  double DrawRays(const Eigen::Matrix3d& R_world_beam, Rng& rng,
                  std::vector<Eigen::Vector3f>& directions, std::vector<double>& patterns) const;

  /// The sidelobes' share of the two-way horizontal pattern at θ [rad] off the axis
  /// (Acoustics::sidelobe_extent_deg): S (θ_s² / (θ_s² + θ²))² within the extent, else 0.
  [[nodiscard]] double SidelobePattern(double theta) const;

  /// The back lobe's one-way pattern (Acoustics::back_lobe_width_deg) towards `u`, a unit
  /// direction in the beam's frame (x along its axis) with u.x ≤ 0; with `blur` > 0 its mean
  /// over a 2-D Gaussian offset of that variance per axis [rad²]. 0 without a back lobe.
  [[nodiscard]] double BackLobePattern(const Eigen::Vector3d& u, double blur) const;

  /// The beam's one-way pattern towards `u`, a unit direction in its frame (x along its axis, z
  /// up the fan): ahead (u.x > 0) the main lobe's exp(-k θ²/2) in each direction, k the two-way
  /// pattern's exponent and θ the azimuth or the elevation, with the sidelobes' pedestal added
  /// to the two-way horizontal power if there are any; behind, BackLobePattern. With `blur` > 0,
  /// its mean over a 2-D Gaussian offset of that variance per axis [rad²]: exp(-k θ² / (2 (1 +
  /// k τ²))) / √(1 + k τ²) per direction.
  [[nodiscard]] double OneWayPatternTowards(const Eigen::Vector3d& u, double blur = 0.0) const;

  /// An upper bound on OneWayPatternTowards(u), unblurred, that needs no trigonometry, for
  /// culling: the pattern's Gaussian exponent with sin²θ = u_y² / (u_x² + u_y²) for θ² and u_z²
  /// for ε² (each no larger), e^-x bounded by 2^-⌊x log₂e⌋ (within a factor of 2); ahead with
  /// sidelobes and within their extent, √(1 + S) for their level S times the elevation's bound.
  [[nodiscard]] double OneWayPatternBound(const Eigen::Vector3d& u) const;

  /// Maps a level [dB] to the 8-bit intensity the sonar would report: the AD window's step,
  /// under the receiver's ceiling (Acoustics::ad_knee, ad_ceiling), rounded to the converter's
  /// reading (Acoustics::ad_levels) and reported on the 0-255 scale.
  [[nodiscard]] std::uint8_t Quantise(double level_db) const;

  /// The same for a linear power: the value reported for the number of the converter's readings
  /// whose lower edge the power reaches, from a table indexed by the power's exponent and top
  /// mantissa bits, then a compare with the next reading's threshold; no logarithm taken.
  [[nodiscard]] std::uint8_t QuantisePower(double power) const;

  /// The range loss 10^(-((S - G)·log10 r + α·r)/10) at range `range_m` [m], exactly.
  [[nodiscard]] double RangeLoss(double range_m) const;

  /// The same from a table over [0, max range] at 1/16 of a bin, linearly interpolated from 8
  /// bins out (relative error under 1e-4 for |S - G| ≤ 20 dB per decade, where an AD step is
  /// 3.7%); exact nearer and beyond the table.
  [[nodiscard]] double RangeLossFromTable(double range_m) const;

  /// Spreads a beam's noise-free echo power per bin over the pulse's skirts (in place): with
  /// S = 10^(pulse_skirt_db/10) and q = exp(-bin / pulse_skirt_length_m), bin k becomes
  ///     (P_k + Σ_{j≠k} P_j · S (1 - q) / (2q) · q^|k-j|) / (1 + S),
  /// so the echo in bin j keeps 1 / (1 + S) of its power and is heard in the bins on both sides
  /// of it, falling by q per bin, its two skirts holding S / (1 + S) in all (before the beam's
  /// ends cut them): the echo's power is redistributed, not added to. Nothing changes when
  /// pulse_skirt_length_m is 0.
  void AddPulseSkirts(std::vector<double>& echo_power) const;

  /// Adds the place's reverberation to a beam's noise-free echo power per bin (in place): bin k
  /// gains Σ_{j<k} P_j · R · (1 - q) · q^(k-1-j), with q = exp(-bin / reverberation_length_m)
  /// and R = 10^(reverberation_db/10), so the echo in bin j feeds a tail that starts in the next
  /// bin, falls by q per bin and holds R · P_j in all (before the beam's end cuts it). Echoes
  /// feed it, the tail does not. Nothing changes when reverberation_length_m is 0.
  void AddReverberation(std::vector<double>& echo_power) const;

  /// Adds the second trip (Acoustics::second_trip_db) to a beam's noise-free echo power per bin
  /// (in place), from the first trip's: `echo_power`, its echoes spread over the pulse, and
  /// `impulse_power`, the same echoes each spread over one bin instead (the surfaces' response
  /// without the pulse). The echo the head reflects goes out again and comes back from the same
  /// surfaces: one trip to range r and one to r' are heard at r + r', so with the time-varied
  /// gain g(r) = r^(G/10) taken off each trip and put back at the sum,
  ///     P2(R) = T · g(R) · Σ_{r + r' = R} (P(r) / g(r)) · (h(r') / g(r')),
  /// T = 10^(second_trip_db/10). Per bin, r = (i + ½) bins for bin i, and the pair (i, j), whose
  /// ranges span [i + j, i + j + 2) bins, gives half to bin i + j and half to i + j + 1. Bins i
  /// under 1e-6 of the largest P/g are skipped, and j runs from the first to the last bin with
  /// h/g over 1e-6 of its largest; the sum stops at the last bin. In a place that reverberates
  /// the way back reverberates as the way out does: P2 gets its own tail (AddReverberation)
  /// before it is added, and with the echo it joins, the way out's. Nothing changes at -100 dB
  /// (the default).
  void AddSecondTrip(std::vector<double>& echo_power, std::span<const double> impulse_power) const;

  /// Speckle factors for consecutive range bins: factor k is |Σ g_j|² / L over the L bins
  /// j = k - L + 1 .. k, the g_j independent circular complex Gaussians of unit power (an
  /// amplitude √E, E exponential, and one of kSpecklePhases evenly spaced phases). A bin's echo
  /// is the coherent sum of the scatterers the pulse covers, so each factor is exponential of
  /// mean 1 (Rayleigh amplitude) and the factors of bins m apart share L - m of their
  /// scatterers: their correlation is (1 - m/L)² for m < L, 0 beyond. L = 1 draws one
  /// exponential per bin. `window` (L) ≥ 1; the first factor's window is drawn in full. With
  /// `looks` N > 1 (Acoustics::speckle_looks), the mean of N such factors drawn one look after
  /// the other: gamma-distributed of mean 1 and shape N, correlated in range as one look is.
  static void CorrelatedSpeckle(std::span<double> factors, int window, Rng& rng, int looks = 1);

  /// The same for a beam whose scatterers lie in several azimuth sectors, each sector's own
  /// complex Gaussians drawn, bin by bin, by Rng(sector_seeds[d]) as CorrelatedSpeckle draws
  /// them (n + L - 1 of them, the first L - 1 before bin 0): bin j's amplitude is
  /// Σ_d amplitude_weights[d] · g_j(d), and the factors are |Σ over the window|² / L as above.
  /// With Σ_d weights² = 1 each factor is exponential of mean 1; two beams that share sectors
  /// (a static sonar's neighbouring beams: the sectors are the world's, keyed by head step)
  /// correlate by (Σ_d w_d w'_d)² bin for bin. One sector of weight 1 gives exactly
  /// CorrelatedSpeckle's factors for Rng(sector_seeds[0]) when L > 1. With `looks` N > 1
  /// (Acoustics::speckle_looks), the mean of N such factors, look l > 0 drawn from each
  /// sector's own l-th set of complex Gaussians, by Rng(DeriveSeed(sector_seeds[d], l)): each
  /// factor gamma-distributed of mean 1 and shape N, correlated across beams and range as one
  /// look is.
  static void SectorSpeckle(std::span<double> factors, int window,
                            std::span<const double> amplitude_weights,
                            std::span<const std::uint64_t> sector_seeds, int looks = 1);

  /// Amplitude weights of the head-step-wide azimuth sectors around a beam's own (an odd count
  /// 2R + 1: index R is the beam's; d steps off it, R + d), their squares summing to 1: the
  /// square roots of the two-way horizontal pattern's share of power in each sector, sectors
  /// carrying under 1e-3 of it dropped (R = kPatternReach, zeros beyond the pattern). With
  /// speckle_angular_correlation_deg θ, each sector's scatterers are correlated with their
  /// neighbours' (sector s is Σ_e c_e u_{s+e}, u independent, c_e ∝ exp(-|e| Δ / θ), Δ the head
  /// step), so the weights are the pattern's convolved with c, on the independent sectors u,
  /// less the outermost sectors that hold under 1e-3 of the power in all (at most a turn's).
  [[nodiscard]] const std::vector<double>& SectorWeights() const { return sector_weights_; }

  /// The speckle's correlation window L in bins (CorrelatedSpeckle, SectorSpeckle): the range
  /// response's extent, the pulse length plus one e-folding of each of its skirts
  /// (pulse_length_m + 2 pulse_skirt_length_m), or Acoustics::speckle_window_m when that is
  /// set, rounded, at least 1.
  [[nodiscard]] int SpeckleWindow() const { return speckle_window_; }
  /// Sectors on each side of a beam's own that its pattern's weights cover.
  static constexpr int kPatternReach = 4;

  /// Phases of the speckle's complex Gaussians.
  static constexpr int kSpecklePhases = 1024;

  /// The receiver's level jitter (Acoustics::level_jitter_db) is tabled: the standard normal's
  /// quantiles z_i at (i + ½)/kLevelJitters (up to 3.66), each a power factor 10^(σ z_i / 10),
  /// one picked by 12 random bits per bin (five bins per 64-bit draw of the ping's generator);
  /// with neighbouring bins correlating (Acoustics::level_jitter_bin_correlation), bin k's
  /// factor is the product of its own pick's and, from a second table, pick k + 1's.
  static constexpr int kLevelJitters = 4096;

  /// The self-reflection's power per bin (Acoustics::self_reflection_db, one entry per bin of
  /// the profile) for a ping at `head_angle_rad`: bin k's profile power P_k times
  ///     10^((σ_a A_jk + σ_p (y_k + y_k+1) / √2) / 10) / exp(½ (ln 10 / 10)² (σ_a² + σ_p²)),
  /// σ_a and σ_p the angle and ping spreads, A_jk the head step j's own draw (tabled at
  /// construction from the run seed: the same for every ping at that head step; see
  /// TabulateSelfReflection) and the y_k standard normals drawn from `ping_rng` (r + 1 of them
  /// for the r ringing bins, whose centres lie within self_reflection_ringing_range_m; none
  /// when σ_p is 0). Past the ringing bins σ_p is 0. The divisor keeps P_k the mean power over
  /// head steps and pings.
  void SelfReflection(double head_angle_rad, Rng& ping_rng, std::vector<double>& power) const;

  /// Decibels to nepers of power: 10^(x/10) = exp(x · this).
  static constexpr double kNepersPerDecibel = 0.23025850929940458;

  /// The standard normal's quantile at u in (0, 1), by bisection on Φ(z) = ½ erfc(-z/√2): 64
  /// halvings of [-8, 8] leave an interval under a double's spacing, so z is as exact as erfc.
  [[nodiscard]] static double NormalQuantile(double u);

  /// Jitter positions per stratum and direction.
  static constexpr int kJitterSlots = 32;

  /// The direction a ray reflected by `material` takes, for the exact mirror direction
  /// `mirror` (unit) off a surface of normal `normal`: `mirror` itself for a perfect mirror;
  /// otherwise tilted by atan(σ·g) towards a direction across it, σ the material's
  /// specular_spread_rad and g a standard 2-D Gaussian offset from kSpreadOffsets tabled ones
  /// (one draw from `rng`), and kept on the mirror's side of the surface. Unit length.
  [[nodiscard]] Eigen::Vector3f SpreadMirror(const Eigen::Vector3f& mirror,
                                             const Eigen::Vector3f& normal,
                                             const Material& material, Rng& rng) const;

  /// The vehicle parts' BVH, in the vehicle's frame, or null without parts (for recording its
  /// queries: RayTracer::Record).
  [[nodiscard]] const RayTracer* VehicleTracer() const { return vehicle_tracer_.get(); }

  /// Tabled 2-D Gaussian offsets: 64 radii (the Rayleigh distribution's quantiles at
  /// (i + ½)/64, up to 3.1 σ) × 64 evenly spaced directions.
  static constexpr int kSpreadOffsets = 64 * 64;

 private:
  /// Synthesize()'s per-thread working memory and its steps (beam_synthesizer.cpp).
  struct Scratch;
  class BeamJob;

  /// `unit` tilted by atan(σ·g) towards a direction across it, g a standard 2-D Gaussian offset
  /// from the kSpreadOffsets tabled ones (one draw from `rng`). Unit length.
  [[nodiscard]] Eigen::Vector3f Tilt(const Eigen::Vector3f& unit, float sigma, Rng& rng) const;

  /// A ray angle's sine, cosine and one-direction factor of the two-way pattern.
  struct JitterSlot {
    double sin = 0.0;
    double cos = 1.0;
    double weight = 1.0;
  };
  SensorModel sensor_;
  const RayTracer& tracer_;
  /// The scene's meshes' materials, then the vehicle parts' (from vehicle_first_mesh_ on).
  std::vector<Material> materials_by_mesh_;
  /// The vehicle parts' BVH, in the vehicle's frame (null without parts); a hit on part i is
  /// mesh vehicle_first_mesh_ + i.
  std::shared_ptr<const RayTracer> vehicle_tracer_;
  std::uint32_t vehicle_first_mesh_ = 0;
  /// Seeds the echoes' randomness per place when the acoustics' speckle_correlation_m is set.
  std::uint64_t place_seed_ = 0;
  /// Whether any material is a rough mirror: only then do mirror paths track their image (the
  /// way back's direction).
  bool rough_mirrors_ = false;
  /// Whether any of the scene's materials (not the vehicle's) glints: only then are its glints
  /// kept apart from its diffuse echoes (FormLevels).
  bool scene_glints_ = false;
  /// The second trip's level T (0: none) and, per bin i, the time-varied gain r^(G/10) at its
  /// centre r = (i + ½) bins and its inverse (AddSecondTrip; the gain also scales the noise that
  /// enters before it, noise_at_bin_).
  double second_trip_ = 0.0;
  std::vector<double> tvg_at_bin_;
  std::vector<double> untvg_at_bin_;
  /// The background noise's mean power per bin: noise_level_db's, plus noise_before_tvg_db's
  /// times the time-varied gain at the bin's centre when there is such noise.
  std::vector<double> noise_at_bin_;
  /// kLevelJitters power factors of the receiver's level jitter, 10^(σ a z_i / 10); empty when
  /// it has none. With neighbouring bins correlating (Acoustics::level_jitter_bin_correlation),
  /// the next bin's draw's share, 10^(σ b z_i / 10), in level_jitter_next_factors_ (else empty).
  std::vector<double> level_jitter_factors_;
  std::vector<double> level_jitter_next_factors_;
  /// The self-reflection's mean power per head step and bin (row j: head step j of a turn, one
  /// row when it has no angle spread), the angle spread and the mean's divisor applied.
  std::vector<double> self_reflection_by_head_;
  int self_reflection_turn_ = 1;
  /// The profile's bins that the ping's spread covers (SelfReflection).
  std::size_t self_reflection_ringing_bins_ = 0;
  /// Fills self_reflection_by_head_: per head step j and bin k, A_jk = Σ_e c_e u_(j+e),k, the
  /// u_jk = (z_jk + z_j,k+1) / √2 from independent standard normals z drawn per head step from
  /// the run seed, c_e ∝ exp(-|e| Δ / θ) (θ the angle correlation, Δ the head step; c = [1]
  /// without one) with Σ c² = 1, cut at half a turn or under 1e-12 of its power left: a
  /// standard normal per head step and bin, neighbouring bins' correlating by ½ and head steps
  /// m apart by Σ_e c_e c_e+m.
  void TabulateSelfReflection(std::uint64_t run_seed);
  /// SpeckleWindow().
  int speckle_window_ = 1;
  /// SectorWeights().
  std::vector<double> sector_weights_;
  /// Convolves sector_weights_ (the pattern's) with the place's angular correlation.
  void CorrelateSectors();
  /// Power at which each reading of the AD converter begins: reading q for power ≥
  /// ad_thresholds_[q] (index 0 unused; infinite past Acoustics::ad_levels).
  std::array<double, 256> ad_thresholds_{};
  /// The 8-bit value reported for reading q: floor(q · 255 / ad_levels) (q itself for 255).
  std::array<std::uint8_t, 256> ad_reported_{};
  /// The highest reading a level can reach under the receiver's ceiling (Acoustics::ad_ceiling).
  std::uint8_t ad_top_reading_ = 255;
  /// Per bucket of powers (the top bits of the double, from the bucket of ad_thresholds_[1]
  /// on), the reading at the bucket's start.
  std::vector<std::uint8_t> ad_bucket_steps_;
  std::uint64_t ad_first_bucket_ = 0;
  int ad_bucket_shift_ = 52;
  /// RangeLoss at every 1/16 of a bin (range_steps_per_m_ steps per metre) from 0.
  std::vector<double> range_loss_;
  double range_steps_per_m_ = 0.0;
  /// The two-way pattern's exponents, 4 ln2 / w² for the nominal widths w: b = exp(-k_h θ² -
  /// k_v ε²).
  double pattern_k_h_ = 0.0;
  double pattern_k_v_ = 0.0;
  /// Stratum i's slot a at [i · kJitterSlots + a]: horizontal angles θ, vertical angles ε.
  std::vector<JitterSlot> horizontal_slots_;
  std::vector<JitterSlot> vertical_slots_;
  /// The sidelobes (Acoustics::sidelobe_extent_deg), if any: S, θ_s² [rad²], the extent [rad],
  /// and their strata's slots (horizontal: one side, from the main lobe's rays' edge out, their
  /// factors times the ratio of a sidelobe stratum's solid angle to a main-lobe one's).
  double sidelobe_level_ = 0.0;
  double sidelobe_width2_ = 0.0;
  double sidelobe_extent_rad_ = 0.0;
  /// sin² of the extent, a little over it: OneWayPatternBound's test for an azimuth past it.
  double sidelobe_extent_sin2_ = 0.0;
  std::vector<JitterSlot> sidelobe_horizontal_slots_;
  std::vector<JitterSlot> sidelobe_vertical_slots_;
  /// The back lobe (Acoustics::back_lobe_width_deg), if any: B, 1/σ² [rad⁻²], and its strata's
  /// slots (factors: the two-way pattern B² exp(-θ²/σ²) split between the two directions, times
  /// the ratio of a stratum's solid angle to a main-lobe one's).
  double back_level_ = 0.0;
  double back_k_ = 0.0;
  std::vector<JitterSlot> back_horizontal_slots_;
  std::vector<JitterSlot> back_vertical_slots_;
  /// kSpreadOffsets standard 2-D Gaussian offsets (SpreadMirror).
  std::vector<Eigen::Vector2f> spread_offsets_;
};

// Inline: the synthesis calls it for every echo.
[[gnu::always_inline]] inline double BeamSynthesizer::RangeLossFromTable(double range_m) const {
  const double x = range_m * range_steps_per_m_;
  // From 8 bins out (128 steps) to the table's last interval. The interpolation's relative
  // error is at most h²/8 · f''/f, with f''/f = s(s+1)/r² + 2sα/r + α² for f = r^-s·e^-αr:
  // under 5e-5 at 8 bins for |s| ≤ 2 (|S - G| ≤ 20 dB per decade). Nearer, exactly.
  if (!(x >= 128.0 && x < static_cast<double>(range_loss_.size() - 1))) return RangeLoss(range_m);
  const auto k = static_cast<std::size_t>(x);
  const double f = x - static_cast<double>(k);
  return range_loss_[k] + f * (range_loss_[k + 1] - range_loss_[k]);
}

}  // namespace sonarbench::sim
