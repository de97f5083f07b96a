// Machine-readable report files: every figure of every row, for scripts.
#pragma once

#include <string>
#include <vector>

#include "report/measure.h"

namespace cbrdf::report {

// One line per row, a header line first; numbers in full precision.
std::string to_csv(const std::vector<MaterialResult>& results);
// {"settings": {...}, "rows": [...], "polar": [...]}.
std::string to_json(const std::vector<MaterialResult>& results, const Settings& st,
                    double elapsed_s);

}  // namespace cbrdf::report
