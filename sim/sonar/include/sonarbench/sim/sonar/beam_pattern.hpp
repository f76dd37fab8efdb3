#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "sonarbench/sim/world/random.hpp"
#include "sonarbench/sim/world/sensor_model.hpp"

namespace sonarbench::sim {

/// The beam's pattern and the rays that sample it. Directions `u` are unit vectors in the beam's
/// frame (x along its axis, z up the fan); angles in radians; patterns are power factors, 1 on
/// the axis. Two-way main lobe b(θ, ε) = exp(-k_h θ² - k_v ε²), k = 4 ln2 / w² for the nominal
/// widths w (docs/physics.md, the beam pattern).
class BeamPattern {
 public:
  explicit BeamPattern(const SensorModel& sensor);

  /// A beam's primary rays for a beam whose frame is `R_world_beam`: rays_horizontal ×
  /// rays_vertical, one per stratum, then the sidelobes' and the back lobe's (PrimaryRays), each
  /// at one of kJitterSlots positions in its stratum per direction, picked by one draw from
  /// `rng`. Writes their world directions and two-way pattern weights; returns the sum of the
  /// main lobe's and the sidelobes' weights (the beam's normalisation).
  double DrawRays(const Eigen::Matrix3d& R_world_beam, Rng& rng,
                  std::vector<Eigen::Vector3f>& directions, std::vector<double>& patterns) const;

  /// The sidelobes' share of the two-way horizontal pattern at θ off the axis: S (θ_s² / (θ_s² +
  /// θ²))² within Acoustics::sidelobe_extent_deg, else 0.
  [[nodiscard]] double SidelobePattern(double theta) const;

  /// The back lobe's one-way pattern towards `u` (u.x ≤ 0); with `blur` > 0 its mean over a 2-D
  /// Gaussian offset of that variance per axis [rad²]. 0 without a back lobe.
  [[nodiscard]] double BackLobePattern(const Eigen::Vector3d& u, double blur) const;

  /// The one-way pattern towards `u`: ahead, the main lobe's exp(-k θ²/2) per direction with the
  /// sidelobes' pedestal added to the two-way horizontal power; behind, BackLobePattern. With
  /// `blur` > 0, its mean over a 2-D Gaussian offset of that variance per axis [rad²].
  [[nodiscard]] double OneWayPatternTowards(const Eigen::Vector3d& u, double blur = 0.0) const;

  /// An upper bound on OneWayPatternTowards(u), unblurred, without trigonometry (for culling):
  /// within a factor of 2 of the Gaussian's bound, √(1 + S) within the sidelobes' extent.
  [[nodiscard]] double OneWayPatternBound(const Eigen::Vector3d& u) const;

  /// Jitter positions per stratum and direction.
  static constexpr int kJitterSlots = 32;

 private:
  /// A ray angle's sine, cosine and one-direction factor of the two-way pattern.
  struct JitterSlot {
    double sin = 0.0;
    double cos = 1.0;
    double weight = 1.0;
  };
  void TabulateBackLobe(double aperture_h, double aperture_v);

  Acoustics acoustics_;
  double pattern_k_h_ = 0.0;
  double pattern_k_v_ = 0.0;
  /// Stratum i's slot a at [i · kJitterSlots + a]: horizontal angles θ, vertical angles ε.
  std::vector<JitterSlot> horizontal_slots_;
  std::vector<JitterSlot> vertical_slots_;
  /// The sidelobes, if any: S, θ_s² [rad²], the extent and sin² of it (a little over, for
  /// OneWayPatternBound), and their strata's slots (one side, from the main lobe's edge out).
  double sidelobe_level_ = 0.0;
  double sidelobe_width2_ = 0.0;
  double sidelobe_extent_rad_ = 0.0;
  double sidelobe_extent_sin2_ = 0.0;
  std::vector<JitterSlot> sidelobe_horizontal_slots_;
  std::vector<JitterSlot> sidelobe_vertical_slots_;
  /// The back lobe, if any: B, 1/σ² [rad⁻²], and its strata's slots.
  double back_level_ = 0.0;
  double back_k_ = 0.0;
  std::vector<JitterSlot> back_horizontal_slots_;
  std::vector<JitterSlot> back_vertical_slots_;
};

}  // namespace sonarbench::sim
