// SPDX-License-Identifier: MIT
// Trilinear lookup in a measured MERL table for rendering: the 8 bins around the continuous grid
// position (theta_h index, theta_d, phi_d; coords.h), weighted by distance, skipping not-measured
// bins and renormalising the remaining weights. Near the horizon some of the 8 neighbours are not
// measured; reading them as 0 (cbrdf::lookup_linear) darkens grazing angles, skipping them does
// not. All 8 not measured: 0.
#pragma once

#include "cbrdf/brdf_table.h"
#include "cbrdf/coords.h"

namespace cbrdf::render {

// Bin i of each axis sits at position i (coords.h's *_position functions): theta_h and theta_d
// clamp at the grid's ends, phi_d wraps with period 180 bins. Per channel.
void lookup_trilinear_measured(const BrdfTable& table, const Vec3& wi, const Vec3& wo,
                               double rgb[3]);

// The same at a continuous grid position (for tests and callers that already have one).
void lookup_trilinear_measured(const BrdfTable& table, const GridPosition& g, double rgb[3]);

}  // namespace cbrdf::render
