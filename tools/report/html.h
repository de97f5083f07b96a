// SPDX-License-Identifier: MIT
// report.html: the tables, the figures and the per-material sphere renders on one page.
#pragma once

#include <string>
#include <vector>

#include "report/plots.h"
#include "report/tables.h"

namespace cbrdf::report {

// Image file names of a material's sphere renders (paper's Figure 4).
std::string sphere_file(const std::string& material, const char* which);  // reference, ...

// The page opens with `answer` (one paragraph) and the kLeadFigure, then `summary` (what was run),
// the tables, the other figures and the materials. It links every figure by its file name and
// every material's sphere_file() PNGs. A script
// sets data-loaded="ok" on <body> once every image has loaded with a non-zero size (and
// "broken" otherwise), so a headless browser can check the page.
std::string report_html(const std::vector<MaterialResult>& results, const Settings& st,
                        const std::vector<TextTable>& tables, const std::vector<Figure>& figures,
                        const std::string& summary, const std::string& answer);

}  // namespace cbrdf::report
