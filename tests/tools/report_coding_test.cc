// SPDX-License-Identifier: MIT
// `cbrdf report --format-version auto,1.2`: two codings of the same fits side by side, the
// frontier at byte budgets (frontier.h's compare_at_budget) and the report's tables and figure of
// both; on hand-made measurements (no fitting).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "report/frontier.h"
#include "report/plots.h"
#include "report/sweep.h"
#include "report/tables.h"
#include "test_support.h"

namespace cbrdf::report {
namespace {

RdPoint point(const std::string& label, double bytes, double tm, double linear) {
  RdPoint p{label, bytes, tm, 1.0};
  p.psnr_linear = linear;
  return p;
}

TEST(CompareAtBudget, BestWithinTheBudgetPerMaterialThenPairedMeans) {
  // Two materials. The new coding halves the bytes of the old one's two settings.
  const std::vector<std::vector<RdPoint>> old = {
      {point("small", 2000, 38, 50), point("large", 6000, 41, 55)},
      {point("small", 2400, 36, 48), point("large", 7000, 40, 54)},
  };
  const std::vector<std::vector<RdPoint>> fresh = {
      {point("small", 1000, 37.9, 49.5), point("large", 3000, 41.1, 55.2)},
      {point("small", 1200, 36.2, 48.0), point("large", 3500, 40.0, 53.0)},
  };
  // 1 KB: only the first material has a new setting, and no old one fits.
  CodingBudget b = compare_at_budget(fresh, old, 1000);
  EXPECT_EQ(b.materials, 2);
  EXPECT_EQ(b.fresh_qualifying, 1);
  EXPECT_EQ(b.old_qualifying, 0);
  EXPECT_EQ(b.paired, 0);
  EXPECT_DOUBLE_EQ(b.fresh_psnr, 37.9);
  EXPECT_DOUBLE_EQ(b.fresh_linear, 49.5);
  EXPECT_TRUE(std::isnan(b.old_psnr));
  EXPECT_TRUE(std::isnan(b.gain_db));
  // 2.5 KB: new "small" for both; old "small" for both.
  b = compare_at_budget(fresh, old, 2500);
  EXPECT_EQ(b.paired, 2);
  EXPECT_NEAR(b.gain_db, ((37.9 - 38) + (36.2 - 36)) / 2, 1e-12);
  EXPECT_NEAR(b.min_gain_db, 37.9 - 38, 1e-12);
  EXPECT_NEAR(b.linear_gain_db, ((49.5 - 50) + (48.0 - 48)) / 2, 1e-12);
  EXPECT_NEAR(b.min_linear_gain_db, -0.5, 1e-12);
  // 3.2 KB: new "large" for the first material (the best within), "small" for the second.
  b = compare_at_budget(fresh, old, 3200);
  EXPECT_NEAR(b.fresh_psnr, (41.1 + 36.2) / 2, 1e-12);
  EXPECT_NEAR(b.gain_db, ((41.1 - 38) + (36.2 - 36)) / 2, 1e-12);
  // 20 KB: everything fits; the linear loss of the second material shows as the smallest gain.
  b = compare_at_budget(fresh, old, 20000);
  EXPECT_NEAR(b.old_psnr, (41 + 40) / 2.0, 1e-12);
  EXPECT_NEAR(b.min_linear_gain_db, 53.0 - 54, 1e-12);
}

Row copula(const std::string& material, int slices, int bits, double bytes_new, double tm_new,
           double bytes_old, double tm_old) {
  Row r;
  r.material = material;
  r.model = "frank";
  r.kind = kKindCopula;
  r.slices = slices, r.bits = bits;
  r.in_sweep = true;
  r.paper = CodecSetting{"frank", slices, bits, 1} == paper_setting();
  r.input_bytes = 34992012;
  r.bytes = bytes_new;
  r.psnr_tonemapped = tm_new;
  r.psnr_linear = tm_new + 12;
  r.encode_s = 2.0;
  r.codings = {{"auto", bytes_new, tm_new + 12, tm_new, 2.0},
               {"1.2", bytes_old, tm_old + 12, tm_old, 1.6}};
  return r;
}

const TextTable* find_table(const std::vector<TextTable>& tables, const std::string& id) {
  for (const TextTable& t : tables) {
    if (t.id == id) return &t;
  }
  return nullptr;
}

TEST(ReportCodings, TablesAndFigureShowBothCodings) {
  Settings st;
  st.sweep.slices = {3, 6};
  st.sweep.bits = {8, 12};
  st.baselines = Baselines{false, false, false, false, false};
  st.codings = {"auto", "1.2"};
  std::vector<MaterialResult> results(2);
  results[0].name = "a";
  results[0].rows = {
      copula("a", 3, 8, 800, 38.5, 1300, 38.4), copula("a", 3, 12, 1500, 38.6, 3000, 38.6),
      copula("a", 6, 8, 1600, 41.0, 2600, 41.0), copula("a", 6, 12, 2900, 41.2, 5900, 41.2)};
  results[1].name = "b";
  results[1].rows = {
      copula("b", 3, 8, 900, 37.3, 1400, 37.3), copula("b", 3, 12, 1700, 37.6, 3400, 37.6),
      copula("b", 6, 8, 1800, 40.0, 2800, 40.1), copula("b", 6, 12, 3100, 40.2, 6100, 40.2)};
  const std::vector<TextTable> tables = report_tables(results, st);
  const TextTable* f = find_table(tables, "coding-frontier");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(f->rows.size(), std::size(kCodingBudgets));
  EXPECT_NE(std::find(f->header.begin(), f->header.end(), "auto PSNR tm dB"), f->header.end());
  EXPECT_NE(std::find(f->header.begin(), f->header.end(), "1.2 PSNR tm dB"), f->header.end());
  // 1 KB: both materials have their s3 b8 in auto and nothing in 1.2; below 38 dB on average.
  const std::vector<std::string>& kb1 = f->rows.front();
  EXPECT_EQ(kb1[0], "1.0 KB");
  EXPECT_EQ(kb1[1], "2/2");
  EXPECT_EQ(kb1[2], "37.90");  // (38.5 + 37.3) / 2
  EXPECT_EQ(kb1[4], "0/2");
  EXPECT_EQ(kb1.back(), "no: 38 dB at 1 KB");
  // 2 KB: auto has s6 b8 for both (41.0, 40.0); 1.2 has s3 b8 (38.4, 37.3).
  const std::vector<std::string>& kb2 = f->rows[2];
  EXPECT_EQ(kb2[0], "2.0 KB");
  EXPECT_EQ(kb2[2], "40.50");
  EXPECT_EQ(kb2[5], "37.85");
  EXPECT_EQ(kb2[7], "+2.65");
  EXPECT_EQ(kb2.back(), "yes");
  // 20 KB: both at their s6 b12; no gain.
  EXPECT_EQ(f->rows.back()[7], "+0.00");
  EXPECT_EQ(f->rows.back().back(), "no: gain");

  const TextTable* s = find_table(tables, "coding-settings");
  ASSERT_NE(s, nullptr);
  ASSERT_EQ(s->rows.size(), 4u);
  EXPECT_EQ(s->rows[0][0], "frank s3 b8");
  EXPECT_EQ(s->rows[0][1], "850");        // auto bytes
  EXPECT_EQ(s->rows[0][2], "1350");       // 1.2 bytes
  EXPECT_EQ(s->rows[0].back(), "1.25x");  // encode 2.0 / 1.6 s

  bool figure = false;
  for (const Figure& fig : report_figures(results, st)) {
    if (fig.file != "frontier_codings.svg") continue;
    figure = true;
    EXPECT_NE(fig.svg.find("coding auto"), std::string::npos);
    EXPECT_NE(fig.svg.find("coding 1.2"), std::string::npos);
  }
  EXPECT_TRUE(figure);

  // One coding: no side-by-side tables or figure.
  st.codings = {"auto"};
  for (MaterialResult& m : results) {
    for (Row& r : m.rows) r.codings.clear();
  }
  const std::vector<TextTable> single = report_tables(results, st);
  EXPECT_EQ(find_table(single, "coding-frontier"), nullptr);
  EXPECT_EQ(find_table(single, "coding-settings"), nullptr);
  for (const Figure& fig : report_figures(results, st)) EXPECT_NE(fig.file, "frontier_codings.svg");
}

TEST(ReportCodings, FormatVersionListIsChecked) {
  // Refused before anything is measured: exit 2 and a message naming the value and what is valid.
  for (const char* bad : {"1.1", "auto,", "1.2,1.2", "1.3;1.2"}) {
    const testing::CommandResult r =
        testing::run_cli(std::string("report --builtin --format-version '") + bad + "' -q");
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_NE(r.err.find("--format-version"), std::string::npos) << bad << ": " << r.err;
  }
}

}  // namespace
}  // namespace cbrdf::report
