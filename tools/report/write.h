// SPDX-License-Identifier: MIT
// Writes every report file into a directory: report.md, report.csv, report.json, the SVG
// figures, the sphere PNGs and report.html.
#pragma once

#include <string>
#include <vector>

#include "report/measure.h"

namespace cbrdf::report {

// A few sentences saying what was run, for the top of report.md and report.html.
std::string run_summary(const std::vector<MaterialResult>& results, const Settings& st,
                        double elapsed_s);

Status write_report(const std::vector<MaterialResult>& results, const Settings& st,
                    const std::string& dir, double elapsed_s);

}  // namespace cbrdf::report
