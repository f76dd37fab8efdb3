#pragma once

#include <cmath>

namespace sonarbench::sim {

/// sin and cos of `x` [rad]. For |x| ≤ 0.8 (a beam's ray angles: at most half of a 35° fan,
/// widened by the aperture scale) their Taylor series to x¹⁷ and x¹⁶, whose truncation (below
/// 0.8¹⁸/18! ≈ 3e-18) is under a double's rounding; otherwise libm's. A libm sincos per ray
/// angle cost as much as the ray's intersection.
struct SinCos {
  double sin;
  double cos;
};

[[nodiscard]] inline SinCos SmallAngleSinCos(double x) {
  if (!(std::abs(x) <= 0.8)) return {std::sin(x), std::cos(x)};
  // Both series as polynomials in y = x², evaluated by Estrin's scheme (pairs, then pairs of
  // pairs) so that the chain of dependent operations is 5 deep, not 9 as in Horner's.
  constexpr double s0 = 1.0, s1 = -1.0 / 6, s2 = 1.0 / 120, s3 = -1.0 / 5040, s4 = 1.0 / 362880,
                   s5 = -1.0 / 39916800, s6 = 1.0 / 6227020800, s7 = -1.0 / 1307674368000,
                   s8 = 1.0 / 355687428096000;
  constexpr double c0 = 1.0, c1 = -1.0 / 2, c2 = 1.0 / 24, c3 = -1.0 / 720, c4 = 1.0 / 40320,
                   c5 = -1.0 / 3628800, c6 = 1.0 / 479001600, c7 = -1.0 / 87178291200,
                   c8 = 1.0 / 20922789888000;
  const double y = x * x;
  const double y2 = y * y;
  const double y4 = y2 * y2;
  const double sin_low = (s0 + s1 * y) + (s2 + s3 * y) * y2;
  const double sin_high = (s4 + s5 * y) + (s6 + s7 * y) * y2 + s8 * y4;
  const double cos_low = (c0 + c1 * y) + (c2 + c3 * y) * y2;
  const double cos_high = (c4 + c5 * y) + (c6 + c7 * y) * y2 + c8 * y4;
  return {x * (sin_low + sin_high * y4), cos_low + cos_high * y4};
}

}  // namespace sonarbench::sim
