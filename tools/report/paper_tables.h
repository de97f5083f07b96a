// SPDX-License-Identifier: MIT
// The paper's Table 1 (PSNR) and Table 2 (storage) beside ours, when its three materials
// (blue-metallic-paint, nickel, yellow-matte-plastic) are among the report's, matched by name.
#pragma once

#include <vector>

#include "report/measure.h"
#include "report/tables.h"

namespace cbrdf::report {

// The paper's Frank copula storage: its empirical marginals as doubles, "40.4KB" (KiB).
inline constexpr double kPaperFrankBytes = 40.4 * 1024;
// The "few KB" budget of the comparison.
inline constexpr double kFewKbBytes = 4 * 1024;

// Two tables (ids "paper-psnr", "paper-storage") with a column per paper material present in
// `results` (in the paper's order); none when no paper material is present.
std::vector<TextTable> paper_tables(const std::vector<MaterialResult>& results);

}  // namespace cbrdf::report
