// SPDX-License-Identifier: MIT
/// @file
/// Built-in sample materials written out as MERL tables: measured ones (neural fits of real MERL
/// measurements, data/measured/README.md) for demos and reports that must run without the measured
/// database, and analytic ones (exact BRDFs) for tests and benchmarks.
#pragma once

#include <span>
#include <string_view>

#include "cbrdf/analytic.h"
#include "cbrdf/brdf_table.h"
#include "cbrdf/status.h"

namespace cbrdf {

/// Where a built-in sample comes from.
enum class SampleKind {
  kAnalytic,  ///< an AnalyticBrdf (sample_brdf()), tabulated exactly
  kMeasured,  ///< a neural fit of a real MERL measurement, evaluated on the grid; no analytic form
};

/// "analytic" or "measured".
constexpr std::string_view sample_kind_name(SampleKind kind) {
  return kind == SampleKind::kMeasured ? "measured" : "analytic";
}

/// A built-in sample material (`cbrdf sample --list`).
struct SampleInfo {
  std::string_view name;                    ///< as make_sample() and the command take it
  std::string_view description;             ///< one line
  SampleKind kind = SampleKind::kAnalytic;  ///< analytic or measured
  std::string_view source = {};  ///< measured samples: where the data comes from; else empty
};

/// The built-in samples in a stable order: the measured ones first, then the analytic ones.
std::span<const SampleInfo> sample_materials();

/// The analytic BRDF behind an analytic sample. A measured sample fails with kInvalidArgument
/// saying it has no analytic form; an unknown name fails with kInvalidArgument listing the valid
/// ones.
Expected<AnalyticBrdf> sample_brdf(std::string_view name);

/// Any sample as a MERL table: an analytic one through tabulate(); a measured one by evaluating
/// its embedded network at the same grid angles, with the same not-measured bins (stored -1). The
/// values are bit-for-bit the same for any thread count. Unknown names fail as in sample_brdf().
Expected<BrdfTable> make_sample(std::string_view name);

/// An analytic BRDF at every MERL bin's grid angles (theta_h = (i/90)^2 90 deg, theta_d = j deg,
/// phi_d = k deg, phi_h = 0), with the bins bin_below_horizon() names marked not measured (stored
/// -1) exactly as real MERL files are. Fails when the BRDF does not validate or yields a non-finite
/// value.
Expected<BrdfTable> tabulate(const AnalyticBrdf& brdf);

}  // namespace cbrdf
