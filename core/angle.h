#pragma once
#include <cmath>
#include <numbers>

namespace fleetmap::core {

// Wraps an angle in radians to (-pi, pi].
inline double normalize_angle(double a) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  a = std::fmod(a, kTwoPi);
  if (a <= -std::numbers::pi) a += kTwoPi;
  if (a > std::numbers::pi) a -= kTwoPi;
  return a;
}

inline constexpr double deg2rad(double deg) { return deg * std::numbers::pi / 180.0; }
inline constexpr double rad2deg(double rad) { return rad * 180.0 / std::numbers::pi; }

}  // namespace fleetmap::core
