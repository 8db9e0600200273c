// atan2 to within 1.2e-5 rad, for decisions taken far from their threshold: whether a joint's
// angle is clearly inside its limit or cone needs no correctly rounded arctangent (libm's took 4%
// of a pile of ragdolls' step time, most of its calls for such decisions). Where the rough angle
// is within kRoughAngleMargin of the threshold, the caller takes the exact angle (std::atan2), so
// every decision is the one the exact angle gives.
#pragma once

#include <cmath>
#include <limits>
#include <numbers>

namespace tumble {

// Over eight times the approximation's largest error (1.15e-5, tests/test_rough_angles.cc), far
// above its rounding (about 1e-15).
inline constexpr double kRoughAngleMargin = 1e-4;

// Abramowitz and Stegun 4.4.49: atan z on [0, 1] by an odd polynomial of degree nine (they state
// 1e-5; with their seven-digit coefficients we measure 1.15e-5), reached through the octant
// (atan z = pi/2 - atan(1/z), the quadrants by symmetry) with std::atan2's signs of zero
// (atan2(+-0, -0) = +-pi). NaN where an argument is not finite: no decision is taken from it.
inline double rough_atan2(double y, double x) {
  if (!(std::isfinite(x) && std::isfinite(y))) return std::numeric_limits<double>::quiet_NaN();
  const double ax = std::abs(x), ay = std::abs(y);
  const bool steep = ay > ax;
  const double big = steep ? ay : ax, small = steep ? ax : ay;
  double angle = 0;
  if (big > 0) {
    const double z = small / big, z2 = z * z;
    angle =
        z * (0.9998660 + z2 * (-0.3302995 + z2 * (0.1801410 + z2 * (-0.0851330 + z2 * 0.0208351))));
    if (steep) angle = std::numbers::pi / 2 - angle;
  }
  if (std::signbit(x)) angle = std::numbers::pi - angle;
  return std::signbit(y) ? -angle : angle;
}

}  // namespace tumble
