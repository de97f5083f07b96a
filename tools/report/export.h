// SPDX-License-Identifier: MIT
// Machine-readable report files: every figure of every row, for scripts.
#pragma once

#include <string>
#include <vector>

#include "report/measure.h"

namespace cbrdf::report {

// One line per row, a header line first; numbers in full precision.
std::string to_csv(const std::vector<MaterialResult>& results);
// {"settings": {...}, "rows": [...], "polar": [...], "gains": [...], "frontier": {...}}: gains
// at 1x, 2x and 4x the paper setting's bytes (frontier.h), the frontier's labels per material.
std::string to_json(const std::vector<MaterialResult>& results, const Settings& st,
                    double elapsed_s);
// frontier.csv: the Pareto frontier of the sweep per material and of the means (scope "mean"),
// one point a line by increasing bytes.
std::string frontier_csv(const std::vector<MaterialResult>& results, const Settings& st);

}  // namespace cbrdf::report
