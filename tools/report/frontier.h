// SPDX-License-Identifier: MIT
// The rate-distortion frontier of the sweep, per material and on average, and what it gains over
// the paper's setting (Frank, 6 uniform slices, one component) at a byte budget.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

// Plain data only (no Row): the unit tests compile frontier.cc on its own, without the tools.
namespace cbrdf::report {

struct RdPoint {
  std::string label;
  double bytes = 0;
  double psnr = 0;  // tone-mapped sphere PSNR, dB
  double encode_s = 0;
  double psnr_linear = std::numeric_limits<double>::quiet_NaN();  // linear sphere PSNR, dB
};

// Indices of the Pareto frontier of `points` (fewer bytes and higher PSNR are better), by
// increasing bytes. A point is dropped when another has no more bytes and no lower PSNR and
// differs in either; of identical points the first is kept. Non-finite points are ignored.
std::vector<std::size_t> pareto_frontier(const std::vector<RdPoint>& points);

// The point with the highest PSNR among those with at most `max_bytes` (fewer bytes, then the
// first met, break ties); nullptr when none fits. Non-finite PSNRs never qualify.
const RdPoint* best_within(const std::vector<RdPoint>& points, double max_bytes);

// One material's codec settings: the sweep's, and the paper's setting (which may be one of them).
struct MaterialPoints {
  std::string material;
  bool has_paper = false;
  RdPoint paper;
  std::vector<RdPoint> sweep;
};

// One material at one budget: the sweep setting with the highest PSNR among those with at most
// `factor` times the bytes of the material's paper-setting row (fewer bytes break ties).
struct MaterialGain {
  std::string material;
  bool has_paper = false;   // the material has a paper-setting row
  bool qualifying = false;  // some sweep setting fits the budget
  std::string best;         // its label
  double paper_bytes = 0, paper_psnr = 0;
  double gain_db = 0;       // best PSNR - paper PSNR
  double bytes_ratio = 0;   // best bytes / paper bytes
  double encode_ratio = 0;  // best encode time / paper encode time
};
MaterialGain material_gain(const MaterialPoints& m, double factor);

// The mean over materials at one budget, over the materials with a qualifying setting.
struct BudgetGain {
  double factor = 1;
  int materials = 0;   // materials in the report
  int qualifying = 0;  // of which had a paper row and a sweep setting within the budget
  double mean_gain_db = 0, min_gain_db = 0, max_gain_db = 0;
  double mean_bytes_ratio = 0, mean_encode_ratio = 0;
  std::vector<MaterialGain> per_material;  // every material, in report order
};
BudgetGain budget_gain(const std::vector<MaterialPoints>& materials, double factor);

// The budgets the report shows, and the targets for the mean gain (NaN: none).
inline constexpr double kBudgetFactors[] = {1.0, 2.0, 4.0};
double target_gain_db(double factor);

// Two codings of the same settings side by side (`cbrdf report --format-version auto,1.2`): per
// material, each coding's best point within an absolute byte budget (best_within), then means.
// `fresh` and `old` hold one point list per material, in the same material order.
struct CodingBudget {
  double budget = 0;  // bytes
  int materials = 0;
  int fresh_qualifying = 0, old_qualifying = 0;  // materials with a point within the budget
  // Means over each coding's own qualifying materials (NaN: none).
  double fresh_psnr = 0, old_psnr = 0, fresh_linear = 0, old_linear = 0;
  // Over the materials where both codings qualify (paired): mean and smallest of fresh - old,
  // tone-mapped and linear (NaN: none).
  int paired = 0;
  double gain_db = 0, min_gain_db = 0, linear_gain_db = 0, min_linear_gain_db = 0;
};
CodingBudget compare_at_budget(const std::vector<std::vector<RdPoint>>& fresh,
                               const std::vector<std::vector<RdPoint>>& old, double budget);

// The budgets of the side-by-side frontier (bytes; 1 KB = 1000 bytes) and the targets: the
// new coding at least +1.0 dB tone-mapped above the old at every budget, linear PSNR at most 0.3 dB
// lower, and at least 38 dB at 1 KB.
inline constexpr double kCodingBudgets[] = {1000, 1500, 2000,  3000,  4000,  5000,
                                            6000, 8000, 10000, 12000, 15000, 20000};
inline constexpr double kCodingTargetGainDb = 1.0;
inline constexpr double kCodingMaxLinearLossDb = 0.3;
inline constexpr double kCodingOneKbTargetDb = 38.0;

}  // namespace cbrdf::report
