// SPDX-License-Identifier: MIT
// The near-lossless baseline: every physical value as an IEEE half (round to nearest even), the
// three channel blocks in MERL order, little-endian, then zstd. Physical rather than stored values
// because MERL's stored values (physical * 1500 / scale) overflow the half range at bright
// specular peaks; values above the largest half (65504 1/sr) saturate there. Not-measured bins stay
// negative (the mask survives; their exact values do not).
#pragma once

#include "cbrdf/brdf_table.h"
#include "cbrdf/status.h"
#include "report/lossless.h"

namespace cbrdf::report {

struct Float16Result {
  Compressed compressed;  // times include the float conversions
  BrdfTable decoded;
};

Expected<Float16Result> float16_round_trip(const BrdfTable& table, int zstd_level);

}  // namespace cbrdf::report
