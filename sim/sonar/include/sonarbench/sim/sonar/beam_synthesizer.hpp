#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "sonarbench/mapping/beam.hpp"
#include "sonarbench/sim/sonar/beam_pattern.hpp"
#include "sonarbench/sim/sonar/bin_labels.hpp"
#include "sonarbench/sim/sonar/multipath.hpp"
#include "sonarbench/sim/sonar/receiver.hpp"
#include "sonarbench/sim/sonar/self_reflection.hpp"
#include "sonarbench/sim/sonar/speckle.hpp"
#include "sonarbench/sim/world/random.hpp"
#include "sonarbench/sim/world/ray_tracer.hpp"
#include "sonarbench/sim/world/scene.hpp"

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
  /// Each bin's truth (BinLabel); empty unless asked for (Labels::kKeep).
  std::vector<BinLabel> labels;
  /// Rays traced for it: primaries (and their vehicle's parts' bundle), mirrored rays,
  /// occlusion rays and the axis's ray for the truth (for speed reports).
  std::size_t traced_rays = 0;
};

/// Whether a synthesised beam carries its noise-free echo power (for tests and studies of the
/// echo itself). A scenario's beams drop it: 8 bytes per bin that nothing downstream reads.
enum class EchoPower { kKeep, kDrop };

/// Whether a synthesised beam carries its bins' truth (BinLabel): a dataset's labels.
enum class Labels { kKeep, kDrop };

/// Parts of the vehicle the sonar hears (Scene::vehicle): its meshes in the vehicle's body
/// frame, where the sonar sits at the sensor's T_vehicle_sonar, and each one's material
/// (diffuse: specular 0).
struct VehicleParts {
  std::vector<TriangleMesh> meshes;
  std::vector<Material> materials;
};

/// Synthesises MSIS beams: stratified-jittered rays across the beam's pattern (BeamPattern),
/// traced against the scene and the vehicle's parts, each hit's echo deposited over the pulse
/// with the range loss (Receiver), the mirror paths' echoes (multipath), the echo spread in
/// range (range_spread), speckle, self-reflection, noise and the converter's 8-bit levels.
/// The model and its equations: docs/physics.md.
///
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
  /// `echo_power` or `labels`.
  [[nodiscard]] SynthesizedBeam Synthesize(double time_s, double head_angle_rad,
                                           const Eigen::Isometry3d& T_world_sonar,
                                           std::uint64_t seed,
                                           EchoPower echo_power = EchoPower::kKeep,
                                           Labels labels = Labels::kDrop) const;
  /// The same into `out`, every field overwritten and its vectors' memory reused: a caller that
  /// keeps `out` from beam to beam allocates once.
  void SynthesizeInto(double time_s, double head_angle_rad, const Eigen::Isometry3d& T_world_sonar,
                      std::uint64_t seed, EchoPower echo_power, Labels labels,
                      SynthesizedBeam& out) const;

  /// The vehicle parts' BVH, in the vehicle's frame, or null without parts (for recording its
  /// queries: RayTracer::Record).
  [[nodiscard]] const RayTracer* VehicleTracer() const { return vehicle_tracer_.get(); }

  /// The parts it composes.
  [[nodiscard]] const BeamPattern& pattern() const { return pattern_; }
  [[nodiscard]] const Receiver& receiver() const { return receiver_; }
  [[nodiscard]] const SpeckleSectors& speckle() const { return speckle_; }
  [[nodiscard]] const MirrorSpread& mirror_spread() const { return mirror_spread_; }

 private:
  /// Synthesize()'s per-thread working memory and its steps (beam_job.hpp).
  struct Scratch;
  class BeamJob;

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
  /// Whether any material is a rough mirror: only then do mirror paths track their image.
  bool rough_mirrors_ = false;
  /// Whether any of the scene's materials glints: only then are glints kept apart.
  bool scene_glints_ = false;
  Receiver receiver_;
  BeamPattern pattern_;
  SpeckleSectors speckle_;
  SelfReflection self_reflection_;
  MirrorSpread mirror_spread_;
};

}  // namespace sonarbench::sim
