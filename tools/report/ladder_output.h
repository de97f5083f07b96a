// SPDX-License-Identifier: MIT
// The ladder in the report: its tables (mean per method and setting, the targets, lossless
// against xz), its figures (bytes on a log scale against tone-mapped PSNR, the mean and one per
// material) and ladder.csv / ladder.json. Empty when the report ran without --ladder.
#pragma once

#include <string>
#include <vector>

#include "report/ladder.h"
#include "report/plots.h"
#include "report/tables.h"

namespace cbrdf::report {

std::vector<TextTable> ladder_tables(const std::vector<LadderMaterial>& ladders);
std::vector<Figure> ladder_figures(const std::vector<LadderMaterial>& ladders);
std::string ladder_csv(const std::vector<LadderMaterial>& ladders);
std::string ladder_json(const std::vector<LadderMaterial>& ladders);

// The ladders of the materials that have one, in order.
std::vector<LadderMaterial> ladders_of(const std::vector<MaterialResult>& results);

}  // namespace cbrdf::report
