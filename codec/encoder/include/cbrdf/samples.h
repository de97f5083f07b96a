// SPDX-License-Identifier: MIT
// Built-in sample materials: analytic BRDFs written out as MERL tables, for tests, demos and
// benchmarks that must run without the measured database.
#pragma once

#include <span>
#include <string_view>

#include "cbrdf/analytic.h"
#include "cbrdf/brdf_table.h"
#include "cbrdf/export.h"
#include "cbrdf/status.h"

namespace cbrdf {

struct SampleInfo {
  std::string_view name;
  std::string_view description;  // one line
};

// The built-in samples, in a stable order.
CBRDF_EXPORT std::span<const SampleInfo> sample_materials();

// The analytic BRDF behind a sample. Unknown names fail with kInvalidArgument listing the valid
// ones.
CBRDF_EXPORT Expected<AnalyticBrdf> sample_brdf(std::string_view name);

// The sample as a MERL table (see tabulate()).
CBRDF_EXPORT Expected<BrdfTable> make_sample(std::string_view name);

// An analytic BRDF at every MERL bin's grid angles (theta_h = (i/90)^2 90 deg, theta_d = j deg,
// phi_d = k deg, phi_h = 0), with the bins bin_below_horizon() names marked not measured (stored
// -1) exactly as real MERL files are. Fails when the BRDF does not validate or yields a non-finite
// value.
CBRDF_EXPORT Expected<BrdfTable> tabulate(const AnalyticBrdf& brdf);

}  // namespace cbrdf
