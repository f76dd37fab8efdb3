#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "sonarbench/io/yaml_reader.hpp"
#include "sonarbench/mapping/sensor_geometry.hpp"

namespace sonarbench::sim {

/// What only the simulator needs of the sonar: how echoes form and are digitised. Echo power is
/// relative to a perfect reflector (reflectivity 1) filling the beam at normal incidence and 1 m;
/// `gain_db` scales echoes into receiver-output dB, the reference of every other level here.
struct Acoustics {
  /// Stratified-jittered ray samples across the horizontal and vertical aperture per beam.
  int rays_horizontal = 4;
  int rays_vertical = 160;
  /// Rays cover this multiple of the nominal (-3 dB) beam width, horizontally and vertically,
  /// weighted by the pattern: beyond 1 they also hear the pattern's skirts (at 2, down to the
  /// two-way Gaussian's -12 dB).
  double aperture_scale_horizontal = 1.0;
  double aperture_scale_vertical = 1.0;
  /// The horizontal pattern's sidelobes: with `sidelobe_extent_deg` [deg] > 0 the sonar also
  /// hears, weakly, what lies that far either side of its axis. The two-way horizontal pattern
  /// is then exp(-4 ln2 θ²/w_h²) + S (θ_s² / (θ_s² + θ²))² out to the extent (0 past it), S =
  /// 10^(sidelobe_db/10) and θ_s = `sidelobe_width_deg` [deg]: a pedestal S under the main lobe
  /// whose level falls 12 dB per octave of angle past θ_s, as a uniform aperture's sidelobe
  /// peaks do (sinc⁴). Sampled by `sidelobe_rays_horizontal` strata on each side, from the
  /// main lobe's rays' edge (aperture_scale_horizontal · w_h / 2) out to the extent, each split
  /// into `sidelobe_rays_vertical` strata up the fan; the first-hit truth stays the main lobe's.
  /// 0, the default: no sidelobes (no rays). The vertical pattern keeps none.
  double sidelobe_extent_deg = 0.0;
  double sidelobe_db = -30.0;
  double sidelobe_width_deg = 5.0;
  int sidelobe_rays_horizontal = 4;
  int sidelobe_rays_vertical = 40;
  /// A back lobe: with `back_lobe_width_deg` [deg] > 0 the transducer also sends and hears,
  /// weakly, behind it. Its one-way pattern there is B exp(-θ²/2σ²), θ the angle off the axis
  /// behind, B = 10^(back_lobe_db/10) and σ = `back_lobe_width_deg`; an echo sent and heard
  /// behind is B² down, one sent ahead and heard behind (a mirror path's last leg) B. Sampled by
  /// `back_lobe_rays` × `back_lobe_rays` strata over min(3σ, 90°) either side of that axis in
  /// both directions, each weighted by its solid angle. The echoes it adds are not counted in
  /// the beam's normalisation (a back lobe does not dim what lies ahead), and the first-hit
  /// truth stays the main lobe's. 0, the default: no back lobe (no rays).
  double back_lobe_width_deg = 0.0;
  double back_lobe_db = -30.0;
  int back_lobe_rays = 8;
  /// Net geometric loss of an area-scattering echo [dB per decade of range] (two-way spherical
  /// spreading, 40 dB, less the growth of the ensonified area, 20 dB).
  double spreading_db_per_decade = 20.0;
  /// Two-way absorption [dB/m].
  double absorption_db_per_m = 0.2;
  /// Time-varied gain the sonar applies [dB per decade of range].
  double tvg_db_per_decade = 20.0;
  /// Receiver gain applied to echoes [dB].
  double gain_db = 0.0;
  /// Range extent of the transmitted pulse, c·τ/2 [m].
  double pulse_length_m = 0.0375;
  /// Skirts in range around the pulse (a receiver filter's or the pulse's own rise and fall;
  /// the tank's scene fits them to its log without telling those from the tank's own): every
  /// echo is also heard before and after its pulse, falling exponentially
  /// with range away from it, e-folding over `pulse_skirt_length_m` [m] (0: no skirts, the
  /// default), the two skirts holding `pulse_skirt_db` [dB] of the power the pulse itself keeps
  /// (the echo's power is shared between them, not added to). See
  /// BeamSynthesizer::AddPulseSkirts.
  double pulse_skirt_length_m = 0.0;
  double pulse_skirt_db = -20.0;
  /// Mean background noise power at the receiver output [dB], the same at every range.
  double noise_level_db = -40.0;
  /// Background noise that enters the receiver before its time-varied gain [dB]: its mean power
  /// at the output where that gain is 0 dB (1 m), rising with range as the gain does
  /// (tvg_db_per_decade), on top of noise_level_db; the two are one draw of exponential power
  /// with the sum as its mean. -100 or less, the default: none.
  double noise_before_tvg_db = -100.0;
  /// The receiver is off while the head transmits: the bins that begin within this range [m] of
  /// the transducer read 0, noise and all. 0, the default: none.
  double blanking_range_m = 0.0;
  /// The receiver's own noise on its output level [dB, standard deviation]: every bin's level,
  /// echo and background alike, moves by a normal draw of this size from ping to ping,
  /// independently bin by bin (each bin's power times 10^(σ z / 10); a log detector's output
  /// noise). Drawn per ping even when the echoes are the place's (speckle_correlation_m), so a
  /// static sonar's bright bins still vary a little from sweep to sweep, as the real log's do.
  /// 0, the default: none (not drawn). See BeamSynthesizer::kLevelJitters.
  double level_jitter_db = 0.0;
  /// The correlation of neighbouring bins' level jitter within a ping [0, 0.5]: bin k's draw
  /// is a z_k + b z_k+1, the z independent standard normals, a² + b² = 1 and a b this, so each
  /// bin's jitter keeps its σ, neighbouring bins share one draw and bins two or more apart none
  /// (a receiver whose bandwidth spans two samples). 0, the default: independent bin by bin.
  double level_jitter_bin_correlation = 0.0;
  /// Specular reflections a ray follows after its first hit (0: no multipath). Every hit after
  /// one echoes back along its path and, when the sonar is in view and in the beam's lobe, also
  /// straight to the sonar (see BeamSynthesizer).
  int max_bounces = 1;
  /// Multiplicative speckle: echo power scaled by an exponential draw of mean 1 (Rayleigh
  /// amplitude).
  bool speckle = true;
  /// How far [m] the sonar moves before its echoes decorrelate. 0: every ping draws its ray
  /// jitter and speckle afresh. Positive: both come from a stream seeded by the run seed, the
  /// beam's world azimuth and tilt in head steps and the sonar's position in cells of this size,
  /// so a static sonar hears the same echoes sweep after sweep, as the real tank log does, and
  /// only the background noise varies; a moving one decorrelates cell by cell. The speckle is
  /// then drawn per head-step azimuth sector and shared by the beams whose pattern covers it.
  double speckle_correlation_m = 0.0;
  /// Independent looks averaged in each bin's speckle factor (1, the default: one). A bin's
  /// power is then the mean of this many independent speckle factors, each as the one look is
  /// (same correlation in range and across beams), so the factor is gamma-distributed of mean
  /// 1 and shape `speckle_looks`: fewer deep fades, the level's spread in dB down from 5.6 dB
  /// (one look) to 3.5 (two), 2.7 (three), 2.3 (four). Where a receiver's bin averages echoes
  /// that fade independently (frequencies across a chirp's band, samples more than a
  /// resolution cell apart); the tank's scene fits it. Needs speckle: true.
  int speckle_looks = 1;
  /// The range [m] over which a bin's speckle is one coherent sum (BeamSynthesizer::
  /// SpeckleWindow: bins that far apart share no scatterers). 0, the default: the range
  /// response's extent, the pulse and one e-folding of each of its skirts. A scene sets it where
  /// its log's fine texture says otherwise.
  double speckle_window_m = 0.0;
  /// With the place's speckle (speckle_correlation_m > 0), how far across azimuth [deg] the
  /// place's scattering stays alike: neighbouring head-step sectors' scatterers are correlated,
  /// sector amplitudes d steps apart by exp(-|d| · step / this) (each sector a sum of
  /// independent ones with weights e-folding over this angle), so that the echoes' texture runs
  /// along arcs of about this angle rather than changing from beam to beam as the pattern's
  /// overlap alone makes it. 0, the default: independent sectors. Needs speckle_correlation_m.
  double speckle_angular_correlation_deg = 0.0;
  /// With the place's speckle, the share of its power [0, 1) each head step hears on its own,
  /// shared with no other: the transducer turns about an axis its face is off, so neighbouring
  /// head steps hear the scatterers they share from phase centres a fraction of a wavelength
  /// apart, and their coherent sums differ by more than the pattern's overlap makes them. Frozen
  /// per head step like the rest of the place's speckle (the head comes back to the same angle
  /// each sweep). Neighbouring beams' speckle then correlates by (1 - this)² times what the
  /// sectors alone give. 0, the default: none. Needs speckle_correlation_m.
  double speckle_own_share = 0.0;
  /// The reverberation of a closed place (a tank): every echo feeds a diffuse tail heard after
  /// it, decaying exponentially with range, e-folding over `reverberation_length_m` [m] (0: no
  /// tail, the default), holding in all `reverberation_db` [dB] of the echo's power. A
  /// phenomenological stand-in for the diffuse paths the ray tracer does not follow (see
  /// BeamSynthesizer).
  double reverberation_length_m = 0.0;
  double reverberation_db = -20.0;
  /// The second trip: the echo reflected back out by the sonar head and vehicle, heard again
  /// from the same surfaces at the sum of the two ranges (a wall at r rings again at 2r, as the
  /// real tank log does at 4.5-5 m). Its level [dB]: the head's reflection loss plus the
  /// reference echo's level against the transmission, one number fitted to a log. -100, the
  /// default, is none (not computed). See BeamSynthesizer::AddSecondTrip.
  double second_trip_db = -100.0;
  /// Level mapped to intensity 0, and the span [dB] mapped onto 0..255 (the Micron's ADLow/ADSpan).
  double ad_low_db = -40.0;
  double ad_span_db = 40.0;
  /// The receiver's ceiling [intensity, 0-255]: where the AD window would put a level at x
  /// above `ad_knee`, the sonar reports knee + w·tanh((x - knee) / w), w = ad_ceiling - knee, so
  /// levels far over the knee crowd towards the ceiling and never pass it (a detector that
  /// saturates smoothly); ad_knee = ad_ceiling is a hard clip. 255 and 255, the defaults: none
  /// but the 8 bits' own. See BeamSynthesizer::Quantise.
  double ad_knee = 255.0;
  double ad_ceiling = 255.0;
  /// The steps [2-255] the sonar's AD converter divides the AD window into: its reading is the
  /// window's level (after the ceiling) rounded to a step of 255 / ad_levels intensity units,
  /// reading k reported as floor(k · 255 / ad_levels), so only ad_levels + 1 of the 256 values
  /// occur. 255, the default: every value. See BeamSynthesizer::Quantise.
  int ad_levels = 255;
  /// Mean self-reflection (vehicle body and transducer ringing) power per bin from bin 0, at the
  /// receiver output [dB]; bins past the end of the list get none. It is the sonar's own: not
  /// the place's, so no speckle multiplies it, but it varies by these (BeamSynthesizer::
  /// SelfReflection), each bin's level by a normal draw in dB, averaged with the next
  /// bin's (neighbouring bins' draws correlate by ½), its mean power kept:
  ///  - `self_reflection_ping_spread_db` [dB, standard deviation]: from ping to ping, in the
  ///    bins whose centre lies within `self_reflection_ringing_range_m` [m] (the transducer's
  ///    ringing; 0, the default: the whole profile); past it the profile is the vehicle's own
  ///    echoes, static;
  ///  - `self_reflection_angle_spread_db` [dB, standard deviation]: from head angle to head angle,
  ///    the same every sweep (the head's and the vehicle's own, in the sonar's frame), alike over
  ///    `self_reflection_angle_correlation_deg` [deg] of head angle (each head step's draw a sum of
  ///    independent ones with weights e-folding over that angle, as
  ///    speckle_angular_correlation_deg; 0: independent steps).
  /// 0, the defaults: the profile as it is, every ping.
  std::vector<double> self_reflection_db;
  double self_reflection_ping_spread_db = 0.0;
  double self_reflection_ringing_range_m = 0.0;
  double self_reflection_angle_spread_db = 0.0;
  double self_reflection_angle_correlation_deg = 0.0;

  bool operator==(const Acoustics&) const = default;
};

/// A sensor model file: `geometry` for the mapper, `acoustics` for the simulator.
struct SensorModel {
  std::string name;
  mapping::SensorGeometry geometry;
  Acoustics acoustics;
};

/// Loads a sensor model YAML file; throws InputError naming the file and key on bad input.
[[nodiscard]] SensorModel LoadSensorModel(const std::string& path);
/// Primary rays per beam: the main lobe's rays_horizontal × rays_vertical and, with sidelobes,
/// their 2 × sidelobe_rays_horizontal × sidelobe_rays_vertical.
[[nodiscard]] std::size_t MainLobeRays(const Acoustics& a);
[[nodiscard]] std::size_t PrimaryRays(const Acoustics& a);

/// Reads the keys of an `acoustics` mapping that are present into `a` (absent ones keep their
/// value), without rejecting unknown keys: the caller does, once.
void ReadAcoustics(YamlReader& node, Acoustics& a);
/// Reports on `node` (an acoustics mapping) a key that `merged`, the settings in force once that
/// mapping is applied, sets without what it needs: speckle_angular_correlation_deg without the
/// place's speckle, speckle_looks over 1 without speckle, a self-reflection spread without a
/// self-reflection profile, self_reflection_angle_correlation_deg without its spread, a
/// receiver knee over its ceiling, sidelobes that end inside the main lobe's rays (`geometry`'s
/// beam width).
void CheckAcoustics(YamlReader& node, const Acoustics& merged,
                    const mapping::SensorGeometry& geometry);
/// Reads a sensor model from an already-open reader (the root of a sensor model file).
[[nodiscard]] SensorModel ReadSensorModel(YamlReader& root);

}  // namespace sonarbench::sim
