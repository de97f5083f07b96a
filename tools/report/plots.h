// SPDX-License-Identifier: MIT
// The report's figures as SVG text: rate-distortion curves, time against PSNR, PSNR per material
// sorted as the paper's Figure 5, and polar plots as its Figure 3.
#pragma once

#include <string>
#include <vector>

#include "report/measure.h"

namespace cbrdf::report {

struct Figure {
  std::string file;     // e.g. "rd_mean.svg"
  std::string caption;  // one sentence
  std::string svg;
  std::string material;  // empty for figures over all materials
};

// The figure the report opens with: the rate-distortion frontier averaged over the materials.
inline constexpr const char* kLeadFigure = "frontier_mean.svg";
// The frontier line's colour in every frontier figure: used by no other series or page element, so
// that a screenshot can find the figure.
inline constexpr const char* kFrontierColour = "#e6007e";

std::vector<Figure> report_figures(const std::vector<MaterialResult>& results, const Settings& st);

// A file-name-safe form of a material name (letters, digits, '-', '_', '.').
std::string file_stem(const std::string& name);

}  // namespace cbrdf::report
