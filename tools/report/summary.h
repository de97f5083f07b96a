// SPDX-License-Identifier: MIT
// The report's answer: per material the paper's setting, the best measured setting within its
// bytes and within a quarter of them. It opens report.md and report.html and closes stdout.
#pragma once

#include <string>
#include <vector>

#include "report/frontier.h"
#include "report/measure.h"
#include "report/tables.h"

namespace cbrdf::report {

// The small budget of the answer: a quarter of the paper setting's bytes.
inline constexpr double kSmallBudgetFactor = 0.25;

// One material's answer. The candidates are the sweep's settings and the paper's setting itself.
struct MaterialAnswer {
  std::string material;
  bool has_paper = false;
  RdPoint paper;
  bool has_same = false, has_small = false;
  RdPoint same;   // best within the paper setting's bytes
  RdPoint small;  // best within kSmallBudgetFactor of them
};
MaterialAnswer material_answer(const MaterialPoints& m);

// Per material, the three settings with bytes and tone-mapped PSNR, then the means.
TextTable answer_table(const std::vector<MaterialResult>& results);

// One paragraph: the means behind answer_table(), the settings chosen most often, and what to
// add to the sweep when it held nothing to compare.
std::string answer_paragraph(const std::vector<MaterialResult>& results, const Settings& st);

// The end of stdout: answer_table() as text, answer_paragraph(), the command that encodes with the
// setting chosen most often within the paper's bytes, and where the full report is (`html_path`
// empty: none was written).
std::string closing_summary(const std::vector<MaterialResult>& results, const Settings& st,
                            const std::string& html_path);

}  // namespace cbrdf::report
