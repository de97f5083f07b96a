// SPDX-License-Identifier: MIT
// The polynomial arctangent of the grid position (position.h): plain arithmetic and selects, so
// that eval and a batch's vectorized loop form it alike.
#pragma once

#include <numbers>

namespace cbrdf::internal {
// Internal linkage, as when these were one file's: each including file inlines them as it
// judges best, without an out-of-line copy to share.
namespace {

// atan(x) for |x| <= 7/16: fdlibm's s_atan.c polynomial (relative error below 3e-16).
template <class T>
inline T atan_core(T x) {
  const T z = x * x, w = z * z;
  const T s1 =
      z *
      (T(3.33333333333329318027e-01) +
       w * (T(1.42857142725034663711e-01) +
            w * (T(9.09088713343650656196e-02) +
                 w * (T(6.66107313738753120669e-02) +
                      w * (T(4.97687799461593236017e-02) + w * T(1.62858201153657823623e-02))))));
  const T s2 =
      w * (T(-1.99999999998764832476e-01) +
           w * (T(-1.11111104054623557880e-01) +
                w * (T(-7.69187620504482999495e-02) +
                     w * (T(-5.83357013379057348645e-02) + w * T(-3.65315727442169155270e-02)))));
  return x - x * (s1 + s2);
}

// atan2(a, b) for a, b >= 0 (0 when both are): one division and one polynomial, the argument
// reduced to |x| <= tan(pi/8) by atan(a/b) = pi/4 + atan((a - b) / (a + b)) and
// atan(a/b) = pi/2 - atan(b/a). Relative error below 1e-15 (tests/encoder/model_eval_test.cc).
template <class T>
inline T atan2_first_quadrant(T a, T b) {
  constexpr T kTanPi8 = T(0.41421356237309504880);
  constexpr T kPi4 = T(std::numbers::pi / 4), kPi2 = T(std::numbers::pi / 2);
  // Selected without branches: the case is data dependent, so a branch mispredicts often.
  const bool above = a > kTanPi8 * b, below_far = !(b > kTanPi8 * a);
  const bool mid = above && !below_far, far = above && below_far;
  const T num = mid ? a - b : (far ? -b : a);
  const T den = mid ? a + b : (far ? a : b);
  const T base = mid ? kPi4 : (far ? kPi2 : T(0));
  // A select, not an early return, so that loops over blocks of pairs vectorize (eval_batch).
  const T r = base + atan_core(num / den);
  return den > 0 ? r : T(0);
}

}  // namespace
}  // namespace cbrdf::internal
