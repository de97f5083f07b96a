// SPDX-License-Identifier: MIT
// The continuous grid position of a direction pair (theta_h, theta_d, phi_d on the MERL grid),
// from the pair's coordinates by four square roots and three polynomial arctangents (trig.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "eval/interp_tables.h"
#include "eval/trig.h"

namespace cbrdf::internal {
// Internal linkage, as when these were one file's: each including file inlines them as it
// judges best, without an out-of-line copy to share.
namespace {

// position() in three steps around its square roots, so that a batch can take the roots in loops
// of their own (a square root that may set errno keeps a loop from vectorizing): the squared
// lengths; theta_d, phi_d and the argument of theta_h's root; the clamped positions.
template <class T>
struct Squares {
  T rho2, len2, chord2;  // |H_xy|^2, |H|^2, |D|^2
};

template <class T>
inline Squares<T> position_squares(T ix, T iy, T iz, T ox, T oy, T oz) {
  const T hx = ix + ox, hy = iy + oy, hz = iz + oz;
  const T ex = ix - ox, ey = iy - oy, ez = iz - oz;
  const T rho2 = hx * hx + hy * hy;
  return {rho2, rho2 + hz * hz, ex * ex + ey * ey + ez * ez};
}

// From the roots rho = |H_xy|, len = |H|, chord = |D|: theta_h * 2 / pi (to take the root of),
// theta_d and phi_d in degrees, clamped (a NaN to 0).
template <class T>
inline Position<T> position_angles(T ix, T iy, T iz, T ox, T oy, T oz, T rho2, T rho, T len,
                                   T chord) {
  constexpr T kDeg = T(180 / std::numbers::pi), kPi = T(std::numbers::pi);
  const T hx = ix + ox, hy = iy + oy, hz = iz + oz;
  const T ex = ix - ox, ey = iy - oy, ez = iz - oz;
  const T theta_h = atan2_first_quadrant(rho, hz);
  const T theta_d = atan2_first_quadrant(chord, len);
  // From D, not wi: D is orthogonal to h (wi and wo have one length), so its azimuth in the frame
  // is wi's, without the cancellation of wi's large component along h when theta_d is small.
  // Where h is the normal: the frame of phi_h = 0, as grid_position takes it (selects, as above).
  const bool tilted = rho2 > std::numeric_limits<T>::min();
  const T dx = tilted ? (ex * hx + ey * hy) * hz - ez * rho2 : ex;
  const T dy = tilted ? (ey * hx - ex * hy) * len : ey;
  const T alpha = atan2_first_quadrant(std::abs(dy), std::abs(dx));
  // atan2(dy, dx) folded to [0, pi]: alpha where dx and dy have one sign, pi - alpha elsewhere.
  const T phi = (dx >= 0) == (dy >= 0) ? alpha : kPi - alpha;
  Position<T> g;
  g.h = theta_h * T(2 / std::numbers::pi);
  g.d = std::min(T(kThetaDBins - 1), std::max(T(0), theta_d * kDeg));
  g.p = std::min(T(kPhiDBins), std::max(T(0), phi * kDeg));
  return g;
}

// theta_h's position from the root of position_angles' h: sqrt(theta_h / 90deg) * 90, clamped.
template <class T>
inline T position_h(T root) {
  return std::min(T(kThetaHBins - 1), std::max(T(0), root * T(kThetaHBins)));
}

// Grid position of a direction pair with wi.z, wo.z > 0 (unit vectors). With H = wi + wo and
// D = wi - wo: tan theta_h = |H_xy| / H_z, tan theta_d = |D| / |H|, and phi_d the angle of D (so
// of wi) in the difference frame (grid_position's), its components scaled by |H_xy| |H| > 0:
//   dx = (D_xy . H_xy) H_z - D_z |H_xy|^2,  dy = (D_y H_x - D_x H_y) |H|,
// folded to [0, pi) by reciprocity. Swapping wi and wo leaves H and |D| as they are and negates
// D, bit for bit, so dx and dy change sign exactly and the fold gives the same phi_d.
template <class T>
inline Position<T> position(T ix, T iy, T iz, T ox, T oy, T oz) {
  const Squares<T> q = position_squares(ix, iy, iz, ox, oy, oz);
  Position<T> g = position_angles(ix, iy, iz, ox, oy, oz, q.rho2, std::sqrt(q.rho2),
                                  std::sqrt(q.len2), std::sqrt(q.chord2));
  g.h = position_h(std::sqrt(g.h));
  return g;
}

}  // namespace
}  // namespace cbrdf::internal
