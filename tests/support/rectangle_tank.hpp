#pragma once

#include <algorithm>
#include <cmath>

namespace sonarbench::test {

/// A sonar at the origin in a rectangle of walls at x = -1, x = 3, y = -1.5 and y = 1.5 [m] (a
/// tank seen from a sonar off its centre): how far bearing `theta` [rad] meets them, top-down.
inline double RectangleWallRange(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  double range = 1e9;
  if (c > 1e-12) range = std::min(range, 3.0 / c);
  if (c < -1e-12) range = std::min(range, -1.0 / c);
  if (s > 1e-12) range = std::min(range, 1.5 / s);
  if (s < -1e-12) range = std::min(range, -1.5 / s);
  return range;
}

}  // namespace sonarbench::test
