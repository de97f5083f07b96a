// SPDX-License-Identifier: MIT
// The report's tables, built once and rendered as Markdown (report.md), HTML (report.html) and
// plain text (stdout).
#pragma once

#include <string>
#include <vector>

#include "report/frontier.h"
#include "report/measure.h"

namespace cbrdf::report {

struct TextTable {
  std::string id;     // anchor name, e.g. "psnr"
  std::string title;  // "Table 1: ..."
  std::string nav;    // its name in the page's navigation (empty: the title up to its ':')
  std::string note;   // one paragraph under the title
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

// The labels of the rows compared across models: the primary copula setting, the copula
// baselines at its slices and bits, the analytic fits, float16 and the lossless compressors, in
// the order the report measured them.
std::vector<std::string> compared_labels(const std::vector<MaterialResult>& results,
                                         const Settings& st);
// The sweep's settings' labels in sweep order.
std::vector<std::string> sweep_labels(const Settings& st);

// Mean of a field over the materials for rows with this label (NaN when no row has it).
double mean_of(const std::vector<MaterialResult>& results, const std::string& label,
               double Row::*field);
const Row* find_row(const MaterialResult& m, const std::string& label);

// A material's sweep rows and its paper-setting row as points for frontier.h.
MaterialPoints material_points(const MaterialResult& m);
std::vector<MaterialPoints> material_points(const std::vector<MaterialResult>& results);
// Per material, its sweep and paper-setting rows as points in Settings::codings[coding] (linear
// PSNR included); empty lists without side-by-side codings.
std::vector<std::vector<RdPoint>> coding_points(const std::vector<MaterialResult>& results,
                                                std::size_t coding);
// The sweep's settings with bytes, PSNR and encode time averaged over the materials (sweep order).
std::vector<RdPoint> mean_sweep_points(const std::vector<MaterialResult>& results,
                                       const Settings& st);
// The paper's setting averaged over the materials.
RdPoint mean_paper_point(const std::vector<MaterialResult>& results);

// The gain over the paper's setting at 1x, 2x and 4x its bytes (only when some gain is not zero)
// and the sweep's frontier (only when the sweep holds more than the paper's setting), the paper's
// Tables 1 and 2 beside ours (paper_tables.h), then tables 1 to 3 shaped like the paper's (PSNR,
// storage, time), the sweep, and what accuracy costs in time.
std::vector<TextTable> report_tables(const std::vector<MaterialResult>& results,
                                     const Settings& st);

// One number through printf's `format` for a table cell; a non-finite value prints as
// `non_finite` (cells with nothing to show).
std::string format_value(const char* format, double v, const char* non_finite = "-");

std::string to_markdown(const TextTable& t);
std::string to_html(const TextTable& t);
std::string to_text(const TextTable& t);  // aligned columns for a terminal

}  // namespace cbrdf::report
