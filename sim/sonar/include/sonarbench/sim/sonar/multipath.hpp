#pragma once

#include <Eigen/Core>
#include <vector>

#include "sonarbench/sim/world/random.hpp"
#include "sonarbench/sim/world/scene.hpp"

// Multipath: the mirror paths a beam's rays take (BeamSynthesizer traces them, multipath.cpp).
namespace sonarbench::sim {

/// How a rough mirror (Material::specular_spread_rad) spreads the rays it reflects.
class MirrorSpread {
 public:
  MirrorSpread();

  /// The direction a ray reflected by `material` takes, for the exact mirror direction `mirror`
  /// (unit) off a surface of normal `normal`: `mirror` itself for a perfect mirror; otherwise
  /// tilted by atan(σ·g), σ the material's spread and g a standard 2-D Gaussian offset (one
  /// draw from `rng`), kept on the mirror's side of the surface. Unit length.
  [[nodiscard]] Eigen::Vector3f Spread(const Eigen::Vector3f& mirror, const Eigen::Vector3f& normal,
                                       const Material& material, Rng& rng) const;

  /// Tabled 2-D Gaussian offsets: 64 Rayleigh radii × 64 evenly spaced directions.
  static constexpr int kSpreadOffsets = 64 * 64;

 private:
  /// `unit` tilted by atan(σ·g) across it, g one of the tabled offsets. Unit length.
  [[nodiscard]] Eigen::Vector3f Tilt(const Eigen::Vector3f& unit, float sigma, Rng& rng) const;

  std::vector<Eigen::Vector2f> offsets_;
};

}  // namespace sonarbench::sim
