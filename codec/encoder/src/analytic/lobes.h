// SPDX-License-Identifier: MIT
// Evaluation of single analytic lobes from the geometry of a direction pair.
#pragma once

#include "cbrdf/analytic.h"
#include "cbrdf/coords.h"

namespace cbrdf::internal {

// Everything the lobes need about (wi, wo), computed once per pair and symmetric in wi and wo so
// that every lobe is reciprocal to rounding.
struct PairGeometry {
  double cos_i = 0, cos_o = 0;    // wi.z, wo.z (both > 0)
  double tan2_i = 0, tan2_o = 0;  // tan^2 of the directions' polar angles
  double cos_h = 0, tan2_h = 0;   // half vector's polar angle
  double cos_d = 0;               // wi . h = wo . h
  double h_len2 = 0;              // |wi + wo|^2 = 4 cos^2(theta_d)
};

// Returns false when wi or wo is at or below the horizon (the BRDF is 0 there).
bool pair_geometry(const Vec3& wi, const Vec3& wo, PairGeometry* g);

// Adds the lobe's value to rgb.
void add_lobe(const Lobe& lobe, const PairGeometry& g, double rgb[3]);

}  // namespace cbrdf::internal
