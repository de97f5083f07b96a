// SPDX-License-Identifier: MIT
// `cbrdf report`: the answer it opens and closes with (the paper's setting against the best
// settings within its bytes and a quarter of them), the paper's Tables 1 and 2 beside ours, and
// which frontier tables appear; on hand-made measurements (no fitting).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "cbrdf/encoder.h"
#include "report/paper_tables.h"
#include "report/summary.h"
#include "report/sweep.h"
#include "report/tables.h"

namespace cbrdf::report {
namespace {

const CodecSetting kPaper = paper_setting();

// A copula row of the Frank family; the paper's row when the setting is the paper's.
Row copula(const std::string& material, int slices, int bits, int components, double bytes,
           double tonemapped, bool in_sweep = true) {
  Row r;
  r.material = material;
  r.model = "frank";
  r.kind = kKindCopula;
  r.slices = slices, r.bits = bits, r.components = components;
  r.in_sweep = in_sweep;
  r.paper = CodecSetting{"frank", slices, bits, components} == kPaper;
  r.input_bytes = 34992012;
  r.bytes = bytes;
  r.psnr_tonemapped = tonemapped;
  r.psnr_linear = tonemapped + 15;
  return r;
}

Row paper_row(const std::string& material, double bytes, double tonemapped, bool in_sweep) {
  return copula(material, kPaper.slices, kPaper.bits, kPaper.components, bytes, tonemapped,
                in_sweep);
}

MaterialResult material(const std::string& name, std::vector<Row> rows) {
  MaterialResult m;
  m.name = name;
  m.rows = std::move(rows);
  return m;
}

Settings sweep_settings(std::vector<int> slices, std::vector<int> bits,
                        std::vector<int> components) {
  Settings st;
  st.sweep.slices = std::move(slices);
  st.sweep.bits = std::move(bits);
  st.sweep.components = std::move(components);
  st.baselines = Baselines{false, false, false, false, false};
  return st;
}

const std::vector<std::string>* find_row(const TextTable& t, const std::string& first) {
  for (const auto& row : t.rows) {
    if (!row.empty() && row[0] == first) return &row;
  }
  return nullptr;
}

TEST(Answer, BestWithinThePapersBytesAndAQuarterOfThem) {
  MaterialPoints m;
  m.material = "m";
  m.has_paper = true;
  m.paper = {kPaper.label(), 6000, 50};
  m.sweep = {{"over-budget", 6001, 60}, {"a", 5500, 51}, {"b", 6000, 50.5},
             {"c", 1400, 45},           {"d", 1501, 47}, {"e", 20000, 58}};
  const MaterialAnswer a = material_answer(m);
  ASSERT_TRUE(a.has_paper && a.has_same && a.has_small);
  EXPECT_EQ(a.same.label, "a");
  EXPECT_EQ(a.small.label, "c");  // d is 1 byte over 6000 / 4

  // Nothing in the sweep beats the paper's setting within its bytes: the paper's setting itself,
  // even when the sweep does not hold it. Nothing within a quarter: no pick.
  m.sweep = {{"worse", 5000, 49}, {"bigger", 9000, 55}};
  const MaterialAnswer b = material_answer(m);
  ASSERT_TRUE(b.has_same);
  EXPECT_EQ(b.same.label, kPaper.label());
  EXPECT_FALSE(b.has_small);

  m.has_paper = false;
  const MaterialAnswer c = material_answer(m);
  EXPECT_FALSE(c.has_paper || c.has_same || c.has_small);
}

std::vector<MaterialResult> two_materials() {
  return {material("m1", {copula("m1", 6, 8, 2, 5500, 51), copula("m1", 3, 8, 1, 1400, 45),
                          paper_row("m1", 6000, 50, true), copula("m1", 6, 12, 2, 11000, 53)}),
          material("m2", {copula("m2", 6, 8, 2, 4000, 44), copula("m2", 3, 8, 1, 1200, 40),
                          paper_row("m2", 5000, 42, true), copula("m2", 6, 12, 2, 9000, 46)})};
}

TEST(Answer, TableParagraphAndClosingSummary) {
  const auto results = two_materials();
  const Settings st = sweep_settings({3, 6}, {8, 12}, {1, 2});
  const TextTable t = answer_table(results);
  const std::string md = to_markdown(t);
  EXPECT_NE(md.find("| m1 | 6000 | 50.00 | frank s6 b8 k2 | 5500 | 51.00 (+1.00) | frank s3 b8 | "
                    "1400 | 45.00 (-5.00) |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| m2 | 5000 | 42.00 | frank s6 b8 k2 | 4000 | 44.00 (+2.00) | frank s3 b8 | "
                    "1200 | 40.00 (-2.00) |"),
            std::string::npos)
      << md;
  // Means of bytes and dB over the materials, and the setting chosen most often.
  EXPECT_NE(md.find("| mean | 5500 | 46.00 | most often frank s6 b8 k2 (2/2) | 4750 | 47.50 "
                    "(+1.50) | most often frank s3 b8 (2/2) | 1300 | 42.50 (-3.50) |"),
            std::string::npos)
      << md;

  const std::string paragraph = answer_paragraph(results, st);
  EXPECT_NE(paragraph.find("On 2 materials, the paper's setting (" + kPaper.label() +
                           ") takes 5500 bytes on average"),
            std::string::npos)
      << paragraph;
  EXPECT_NE(paragraph.find("most often frank s6 b8 k2, 2 of 2) takes 4750 bytes at 47.50 dB "
                           "(+1.50 dB)"),
            std::string::npos)
      << paragraph;

  const std::string closing = closing_summary(results, st, "/x/report.html");
  EXPECT_EQ(closing.rfind(t.title, 0), 0u) << closing;
  EXPECT_NE(
      closing.find("cbrdf encode IN.binary -o OUT.cbrdf --slices 6 --bits 8 --components 2\n"),
      std::string::npos)
      << closing;
  const std::string tail = "\nFull report: /x/report.html\n";
  ASSERT_GE(closing.size(), tail.size());
  EXPECT_EQ(closing.substr(closing.size() - tail.size()), tail);
  const std::string none = closing_summary(results, st, "");
  EXPECT_NE(none.find("add -o DIR for report.html"), std::string::npos) << none;
}

TEST(Answer, PaperOnlySweepSaysWhatToAdd) {
  const auto results = std::vector<MaterialResult>{
      material("m1", {paper_row("m1", 6000, 50, true)}),
  };
  const Settings st = sweep_settings({kPaper.slices}, {kPaper.bits}, {kPaper.components});
  ASSERT_TRUE(st.sweep.only_paper_setting());
  const std::string paragraph = answer_paragraph(results, st);
  EXPECT_NE(paragraph.find("On 1 material, the paper's setting"), std::string::npos) << paragraph;
  EXPECT_NE(paragraph.find(std::string("held only the paper's setting")), std::string::npos);
  EXPECT_NE(paragraph.find(kFrontierSweepExample), std::string::npos) << paragraph;
  // No frontier or gain tables: there is nothing to compare.
  for (const TextTable& t : report_tables(results, st)) {
    EXPECT_TRUE(t.id != "gain" && t.id != "gain-material" && t.id != "frontier") << t.id;
  }
}

std::vector<std::string> table_ids(const std::vector<MaterialResult>& results, const Settings& st) {
  std::vector<std::string> ids;
  for (const TextTable& t : report_tables(results, st)) ids.push_back(t.id);
  return ids;
}

bool has(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

TEST(Answer, GainTablesOnlyWhenSomeGainIsNotZero) {
  const Settings st = sweep_settings({kPaper.slices}, {8, kPaper.bits}, {1});
  // The other setting is smaller and worse: every budget's best is the paper's setting, +0.00.
  const std::vector<MaterialResult> flat = {
      material("m", {copula("m", kPaper.slices, 8, 1, 3000, 40), paper_row("m", 6000, 50, true)})};
  std::vector<std::string> ids = table_ids(flat, st);
  EXPECT_FALSE(has(ids, "gain"));
  EXPECT_FALSE(has(ids, "gain-material"));
  EXPECT_TRUE(has(ids, "frontier"));  // the sweep's frontier still has two settings
  // A setting that beats it within its bytes brings the gain tables back.
  const std::vector<MaterialResult> better = {
      material("m", {copula("m", kPaper.slices, 8, 1, 3000, 51), paper_row("m", 6000, 50, true)})};
  ids = table_ids(better, st);
  EXPECT_TRUE(has(ids, "gain"));
  EXPECT_TRUE(has(ids, "gain-material"));
}

TEST(PaperTables, OnlyForThePapersMaterialsInItsOrder) {
  EXPECT_TRUE(paper_tables({material("plastic", {paper_row("plastic", 6000, 50, true)})}).empty());

  // nickel before blue-metallic-paint in the report; the paper's order in the table.
  const std::vector<MaterialResult> results = {
      material("nickel",
               {paper_row("nickel", 6058, 54.4, true), copula("nickel", 6, 8, 1, 2613, 53.64),
                copula("nickel", 6, 12, 4, 23238, 57.88), copula("nickel", 6, 16, 4, 41400, 60)}),
      material("other", {paper_row("other", 6000, 50, true)}),
      material("blue-metallic-paint", {paper_row("blue-metallic-paint", 5000, 48, true),
                                       copula("blue-metallic-paint", 6, 8, 1, 4096, 47),
                                       copula("blue-metallic-paint", 6, 16, 4, 41369, 59)}),
  };
  const std::vector<TextTable> t = paper_tables(results);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].id, "paper-psnr");
  EXPECT_EQ(t[1].id, "paper-storage");
  for (const TextTable& table : t) {
    EXPECT_EQ(table.header, (std::vector<std::string>{"model", "blue-metallic-paint", "nickel"}));
  }
  auto row = [&](const TextTable& table, const std::string& name) {
    const auto* r = find_row(table, name);
    EXPECT_NE(r, nullptr) << name;
    return r ? *r : std::vector<std::string>{};
  };
  // The published columns.
  EXPECT_EQ(row(t[0], "paper: Frank copula, 40.4 KB"),
            (std::vector<std::string>{"paper: Frank copula, 40.4 KB", "46.39", "43.16"}));
  EXPECT_EQ(row(t[0], "paper: Lawrence et al.")[2], "32.94");
  EXPECT_EQ(row(t[0], "paper: Ward")[1], "32.85");
  EXPECT_EQ(row(t[1], "paper: Lawrence et al.")[1], "139.0 KB");
  EXPECT_EQ(row(t[1], "paper: measured")[2], "33.4 MB");
  // Ours: the paper's setting, the best within 40.4 KB (41369.6 bytes: 41400 is over) and within
  // 4 KB (4096 bytes: at the edge counts).
  const std::string p = "ours: " + kPaper.label() + " (the paper's setting)";
  EXPECT_EQ(row(t[0], p + ", tone-mapped")[2], "54.40");
  EXPECT_EQ(row(t[0], p + ", linear")[2], "69.40");
  EXPECT_EQ(row(t[0], "ours: best within 40.4 KB, tone-mapped"),
            (std::vector<std::string>{"ours: best within 40.4 KB, tone-mapped",
                                      "59.00 (frank s6 b16 k4)", "57.88 (frank s6 b12 k4)"}));
  EXPECT_EQ(row(t[0], "ours: best within 4 KB, tone-mapped"),
            (std::vector<std::string>{"ours: best within 4 KB, tone-mapped", "47.00 (frank s6 b8)",
                                      "53.64 (frank s6 b8)"}));
  EXPECT_EQ(row(t[0], "ours: best within 4 KB, linear")[1], "62.00");
  EXPECT_EQ(find_row(t[0], "ours: Ward fit, tone-mapped"), nullptr);  // no analytic baseline
  EXPECT_EQ(row(t[1], "ours: the MERL table (.binary)")[1], "33.4 MB (34992012 B)");
  EXPECT_EQ(row(t[1], p)[2], "5.9 KB (6058 B)");
  EXPECT_EQ(row(t[1], "ours: best within 4 KB")[1], "4.0 KB (4096 B) frank s6 b8");
  // The note says how the protocols differ.
  EXPECT_NE(t[0].note.find("neural fit"), std::string::npos);
  EXPECT_NE(t[0].note.find("tone mapping"), std::string::npos);
}

}  // namespace
}  // namespace cbrdf::report

namespace cbrdf::report {
namespace {

// `--sweep bits=auto` measures the encoder's default (`--bits auto`) beside fixed depths.
TEST(ReportSweep, BitsAutoIsASweepValueWithItsOwnLabel) {
  auto sweep = parse_sweep({"bits=8,auto"});
  ASSERT_TRUE(sweep.ok()) << sweep.status().message();
  ASSERT_EQ(sweep->bits, (std::vector<int>{8, kAutoBits}));
  std::vector<std::string> labels;
  for (const CodecSetting& s : sweep->settings()) labels.push_back(s.label());
  EXPECT_NE(std::find(labels.begin(), labels.end(), "frank s6 bauto"), labels.end());
  EXPECT_NE(std::find(labels.begin(), labels.end(), "frank s6 b8"), labels.end());
  EXPECT_EQ(bits_name(kAutoBits), "auto");
  EXPECT_EQ(bits_name(10), "10");
  EXPECT_FALSE(parse_sweep({"bits=auto,auto"}).ok());
}

}  // namespace
}  // namespace cbrdf::report
