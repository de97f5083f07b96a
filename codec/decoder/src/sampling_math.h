// SPDX-License-Identifier: MIT
// The sampler's trigonometry without libm calls: acos, sincos and atan2 written as straight-line
// polynomials and selects (fdlibm's and Cephes' coefficients, a few ulp), so that a loop of them
// vectorizes and one draw computes the same bits alone (sample()) as in a vector lane
// (sample_batch()). Every function is branch-free: both sides of a select are evaluated.
#pragma once

#include <cmath>
#include <numbers>

// GCC and clang's builtins are the instructions, with no errno path, even without
// -fno-math-errno; elsewhere the standard functions, which round the same (IEEE sqrt and fabs).
#if defined(__GNUC__) || defined(__clang__)
#define CBRDF_SAMPLING_SQRT(x) __builtin_sqrt(x)
#define CBRDF_SAMPLING_FABS(x) __builtin_fabs(x)
#else
#define CBRDF_SAMPLING_SQRT(x) std::sqrt(x)
#define CBRDF_SAMPLING_FABS(x) std::fabs(x)
#endif

namespace cbrdf::internal {

constexpr double kPi = std::numbers::pi;
constexpr double kPio2Hi = 1.57079632679489655800e+00;  // pi / 2 = kPio2Hi + kPio2Lo
constexpr double kPio2Lo = 6.12323399573676603587e-17;

// fdlibm's rational R(t) = (asin(sqrt t) - sqrt t) / sqrt t, for t in [0, 0.25].
inline double asin_ratio(double t) {
  const double p =
      t * (1.66666666666666657415e-01 +
           t * (-3.25565818622400915405e-01 +
                t * (2.01212532134862925881e-01 +
                     t * (-4.00555345006794114027e-02 +
                          t * (7.91534994289814532176e-04 + t * 3.47933107596021167570e-05)))));
  const double q =
      1.0 + t * (-2.40339491173441421878e+00 +
                 t * (2.02094576023350569471e+00 +
                      t * (-6.88283971605453293030e-01 + t * 7.70381505559019352791e-02)));
  return p / q;
}

// acos(x) for x in [0, 1] (x outside, NaN included, is clamped into it): fdlibm's two ranges,
// pi/2 - asin(x) below 0.5 and 2 asin(sqrt((1 - x) / 2)) above, sharing one rational.
inline double acos01(double x) {
  x = x > 0.0 ? x : 0.0;
  x = x < 1.0 ? x : 1.0;
  const bool low = x <= 0.5;
  const double t = low ? x * x : (1.0 - x) * 0.5;
  const double r = asin_ratio(t);
  const double s = CBRDF_SAMPLING_SQRT(t);  // low: x itself (unused); both sides are evaluated
  const double near_zero = kPio2Hi - (x - (kPio2Lo - x * r));
  const double near_one = 2.0 * (s + s * r);
  return low ? near_zero : near_one;
}

struct SinCos {
  double s, c;
};

// sin and cos of phi in [0, 2 pi] (a little beyond is fine): phi = q pi/2 + r with |r| <= pi/4
// (Cody-Waite, pi/2 in two parts: q pi/2's first part is exact), then fdlibm's kernels.
inline SinCos sincos_0_2pi(double phi) {
  constexpr double kTwoOverPi = 6.36619772367581382433e-01;
  constexpr double kPio2First = 1.57079632673412561417e+00;  // 33 bits of pi / 2
  constexpr double kPio2FirstTail = 6.07710050650619224932e-11;
  phi = phi > 0.0 ? phi : 0.0;  // NaN too
  phi = phi < 8.0 ? phi : 8.0;
  // q = phi 2 / pi rounded to an integer, in double arithmetic throughout (adding and subtracting
  // 1.5 2^52 rounds): integer quadrants would mix mask widths, which GCC does not vectorize.
  constexpr double kRound = 0x1.8p52;
  const double q = (phi * kTwoOverPi + kRound) - kRound;
  const double r = (phi - q * kPio2First) - q * kPio2FirstTail;
  const double z = r * r;
  const double v = z * r;
  const double sp = 8.33333333332248946124e-03 +
                    z * (-1.98412698298579493134e-04 +
                         z * (2.75573137070700676789e-06 +
                              z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)));
  const double sin_r = r + v * (-1.66666666666666324348e-01 + z * sp);
  const double w = z * z;
  const double cr = z * (4.16666666666666019037e-02 +
                         z * (-1.38888888888741095749e-03 + z * 2.48015872894767294178e-05)) +
                    w * w *
                        (-2.75573143513906633035e-07 +
                         z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11));
  const double hz = 0.5 * z, one_minus_hz = 1.0 - hz;
  const double cos_r = one_minus_hz + (((1.0 - one_minus_hz) - hz) + z * cr);
  // sin(q pi/2 + r) = sq cos r + cq sin r and cos(q pi/2 + r) = cq cos r - sq sin r with
  // (sq, cq) = (sin, cos)(q pi/2) in {0, 1, -1}, exact as triangle waves of q: one product is 0,
  // the other exact, so the sums round nothing (and, unlike quadrant selects, vectorize).
  auto peak = [q](double at) {
    const double t = 1.0 - CBRDF_SAMPLING_FABS(q - at);
    return t > 0.0 ? t : 0.0;
  };
  const double cq = peak(0.0) - peak(2.0) + peak(4.0), sq = peak(1.0) - peak(3.0) + peak(5.0);
  return {sq * cos_r + cq * sin_r, cq * cos_r - sq * sin_r};
}

// Cephes' atan(t) for t in [0, 1]: above 0.66 through (t - 1) / (t + 1) and pi/4.
inline double atan01(double t) {
  const bool high = t > 0.66;
  const double x = high ? (t - 1.0) / (t + 1.0) : t;
  const double z = x * x;
  const double p = (((-8.750608600031904122785e-01 * z - 1.615753718733365076637e+01) * z -
                     7.500855792314704667340e+01) *
                        z -
                    1.228866684490136173410e+02) *
                       z -
                   6.485021904942025371773e+01;
  const double q = ((((z + 2.485846490142306297962e+01) * z + 1.650270098316988542046e+02) * z +
                     4.328810604912902668951e+02) *
                        z +
                    4.853903996359136964868e+02) *
                       z +
                   1.945506571482613964425e+02;
  const double a = x * (z * p / q) + x;
  return high ? 0.78539816339744827900 + (a + 0.5 * kPio2Lo) : a;
}

// atan2(y, x) moved into [0, 2 pi) (atan2's result plus 2 pi where it is negative); 0 at the
// origin and for NaN input.
inline double atan2_0_2pi(double y, double x) {
  const double ax = x < 0.0 ? -x : x, ay = y < 0.0 ? -y : y;
  const bool steep = ay > ax;
  const double num = steep ? ax : ay, den = steep ? ay : ax;
  const double t = den > 0.0 ? num / den : 0.0;
  const double a = atan01(t);
  const double first = steep ? (kPio2Hi - a) + kPio2Lo : a;           // in [0, pi/2]
  const double half = x < 0.0 ? (kPi - first) + 2 * kPio2Lo : first;  // in [0, pi]
  return y < 0.0 ? (2 * kPi - half) + 4 * kPio2Lo : half;
}

}  // namespace cbrdf::internal
