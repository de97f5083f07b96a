// SPDX-License-Identifier: MIT
/// @file
/// Rusinkiewicz half/difference coordinates and the MERL bin mapping.
///
/// Directions are unit vectors in the local shading frame (z = surface normal). Angles in radians.
/// The MERL grid: theta_h bin i sits at theta_h = (i/90)^2 * 90 deg (non-linear), theta_d bin j at
/// j deg, phi_d bin k at k deg, phi_d in [0, 180) by reciprocity (phi_d and phi_d + pi are one
/// bin).
#pragma once

#include <cstddef>

#include "cbrdf/brdf_table.h"

namespace cbrdf {

/// A direction or point: unit vectors in the local frame, z the surface normal.
struct Vec3 {
  /** Components. */
  ///@{
  double x = 0, y = 0, z = 0;
  ///@}
};

/// The dot product.
inline double dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

/// Rusinkiewicz's half/difference angles of a direction pair (radians).
struct HalfDiff {
  /** Angles. */
  ///@{
  double theta_h = 0, phi_h = 0, theta_d = 0, phi_d = 0;
  ///@}
};

/// (wi, wo) -> (theta_h, phi_h, theta_d, phi_d). phi_h, phi_d in (-pi, pi].
HalfDiff to_half_diff(const Vec3& wi, const Vec3& wo);
/// The inverse: the pair (wi, wo) with these coordinates.
void from_half_diff(const HalfDiff& hd, Vec3* wi, Vec3* wo);

/** Bin indices exactly as the reference MERL reader (BRDFRead.cpp) computes them, clamped to the
    grid. */
///@{
int theta_h_index(double theta_h);
int theta_d_index(double theta_d);
int phi_d_index(double phi_d);  ///< folds phi_d < 0 by + pi (reciprocity)
///@}

/** Continuous positions on the grid: bin i sits at position i exactly (the inverse of the bin
    angle). */
///@{
double theta_h_position(double theta_h);  ///< sqrt(theta_h / 90deg) * 90
double theta_d_position(double theta_d);  ///< theta_d / 1deg
double phi_d_position(double phi_d);      ///< folded to [0, pi), / 1deg
///@}

/** The angle a bin (or fractional position) sits at. */
///@{
double theta_h_of(double position);  ///< (position / 90)^2 * pi / 2
double theta_d_of(double position);
double phi_d_of(double position);
///@}

/// Continuous MERL grid position of a direction pair (theta_h and theta_d positions, and phi_d
/// folded to [0, 180)): the same as the *_position functions of to_half_diff's angles, computed
/// from an orthonormal frame around h with one acos per angle and no other trigonometry.
struct GridPosition {
  /** Positions (bin i at i). */
  ///@{
  double theta_h = 0, theta_d = 0, phi_d = 0;
  ///@}
};
/// The grid position of (wi, wo); see GridPosition.
GridPosition grid_position(const Vec3& wi, const Vec3& wo);

/// Nearest-bin MERL index of a direction pair, identical to the reference reader's lookup.
std::size_t nearest_bin(const Vec3& wi, const Vec3& wo);

/** RGB physical value at a direction pair from a table: nearest bin (the reference behaviour), or
    trilinear between the bins around the continuous position (theta_h and theta_d clamped at the
    grid's ends, phi_d periodic with period 180 bins). Not-measured bins read as 0 in both. */
///@{
void lookup_nearest(const BrdfTable& table, const Vec3& wi, const Vec3& wo, double rgb[3]);
void lookup_linear(const BrdfTable& table, const Vec3& wi, const Vec3& wo, double rgb[3]);
///@}

/// True when a bin's grid direction pair has wi or wo at or below the horizon: the configurations a
/// MERL file marks not measured. Evaluated at the bin's grid angles with phi_h = 0.
bool bin_below_horizon(int theta_h, int theta_d, int phi_d);

}  // namespace cbrdf
