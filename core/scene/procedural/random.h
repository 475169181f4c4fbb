#pragma once
// Reproducible randomness and trigonometry for the procedural scenes.
//
// A built-in spec must give bit-identical triangles on every machine and
// compiler. The standard library does not promise that: the engines are
// portable, but std::uniform_real_distribution and friends are
// implementation-defined, and std::sin/std::cos/std::pow are not required to
// be correctly rounded (glibc, musl and MSVC differ in the last bit). So the
// generators draw from SplitMix64 (Steele, Lea & Flood, "Fast splittable
// pseudorandom number generators", OOPSLA 2014; constants as in Vigna's
// public-domain reference) and convert bits to floats explicitly, and the
// trigonometry below uses only +, -, *, / and sqrt, which IEEE 754 rounds
// exactly. (Contracting a*b+c into an FMA would still change the last bit;
// x86-64 builds without -mfma never do it.)
#include "core/util/random.h"

#include <glm/glm.hpp>

#include <cmath>
#include <cstdint>

namespace accelviz::procedural {

// SplitMix64 and hash64 live in core/util/random.h (shared with the ray
// sets, the sweeps, the verification and the robustness lab).
using accelviz::hash64;
using accelviz::SplitMix64;

inline constexpr double kPi = 3.141592653589793238462643383279502884;

/// sin and cos of x (radians) from basic operations only.
/// Cody-Waite reduction by pi/2 with a three-part constant, then Taylor
/// polynomials on [-pi/4, pi/4] (degree 17 for sin, 18 for cos: truncation
/// below 1e-17 there). Accurate to a few ulp of double for |x| < 1e6, far
/// more than the float coordinates need; what matters is that the result is
/// the same everywhere.
struct SinCos {
  double sin;
  double cos;
};
inline SinCos sin_cos(double x) {
  // pi/2 split so that k * kPio2Hi and k * kPio2Mid are exact for |k| < 2^20.
  constexpr double kPio2Hi = 1.5707963267341256e+00;   // 33 significant bits
  constexpr double kPio2Mid = 6.07710050630396597660e-11;  // next 33 bits
  constexpr double kPio2Lo = 2.02226624879595063154e-21;  // remainder
  constexpr double kTwoOverPi = 0.63661977236758134308;
  double kd = x * kTwoOverPi;
  kd = kd >= 0.0 ? static_cast<double>(static_cast<std::int64_t>(kd + 0.5))
                 : -static_cast<double>(static_cast<std::int64_t>(0.5 - kd));
  const double r = ((x - kd * kPio2Hi) - kd * kPio2Mid) - kd * kPio2Lo;
  const double r2 = r * r;
  // Horner forms of the Taylor series, coefficients 1/n! written as quotients
  // that the compiler folds exactly once.
  const double s =
      r * (1.0 + r2 * (-1.0 / 6 + r2 * (1.0 / 120 + r2 * (-1.0 / 5040 + r2 * (1.0 / 362880 +
          r2 * (-1.0 / 39916800 + r2 * (1.0 / 6227020800.0 + r2 * (-1.0 / 1307674368000.0 +
          r2 * (1.0 / 355687428096000.0)))))))));
  const double c =
      1.0 + r2 * (-1.0 / 2 + r2 * (1.0 / 24 + r2 * (-1.0 / 720 + r2 * (1.0 / 40320 + r2 * (-1.0 / 3628800 +
          r2 * (1.0 / 479001600.0 + r2 * (-1.0 / 87178291200.0 + r2 * (1.0 / 20922789888000.0 +
          r2 * (-1.0 / 6402373705728000.0)))))))));
  const std::int64_t k = static_cast<std::int64_t>(kd);
  switch (((k % 4) + 4) % 4) {
    case 0: return {s, c};
    case 1: return {c, -s};
    case 2: return {-s, -c};
    default: return {-c, s};
  }
}

/// Arc tangent of x >= 0 from basic operations and sqrt: halve the angle
/// with atan(x) = 2 atan(x / (1 + sqrt(1 + x^2))) until x <= 1/8, then a
/// Taylor series (terms below 1e-18 at that point).
inline double atan_nonnegative(double x) {
  double scale = 1.0;
  while (x > 0.125) {
    x = x / (1.0 + std::sqrt(1.0 + x * x));
    scale *= 2.0;
  }
  const double x2 = x * x;
  double sum = 0.0;
  for (int k = 19; k >= 1; k -= 2) sum = 1.0 / k - x2 * sum;
  return scale * x * sum;
}

inline double radians(double degrees) { return degrees * (kPi / 180.0); }

/// Cube root of x > 0 by Newton's method from an exact power-of-8 reduction,
/// with a fixed iteration count (std::cbrt is not correctly rounded).
inline double cbrt_positive(double x) {
  double scale = 1.0;
  while (x >= 8.0) x /= 8.0, scale *= 2.0;
  while (x < 1.0) x *= 8.0, scale /= 2.0;
  double y = 1.5;  // x in [1, 8): cube root in [1, 2)
  for (int i = 0; i < 8; ++i) y = y - (y * y * y - x) / (3.0 * y * y);
  return y * scale;
}

}  // namespace accelviz::procedural
