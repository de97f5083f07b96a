// SPDX-License-Identifier: MIT
// `cbrdf report`: the rate-distortion frontier, the gain over the paper's setting at a byte
// budget, and the sweep's parsing, on hand-made inputs (linked from the cbrdf_report library).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "cbrdf/fit.h"
#include "report/frontier.h"
#include "report/sweep.h"

namespace cbrdf::report {
namespace {

std::vector<std::string> frontier_labels(const std::vector<RdPoint>& points) {
  std::vector<std::string> out;
  for (std::size_t i : pareto_frontier(points)) out.push_back(points[i].label);
  return out;
}

TEST(ParetoFrontier, DropsDominatedPointsAndOrdersByBytes) {
  const std::vector<RdPoint> points = {
      {"c", 3000, 45}, {"a", 1000, 40}, {"dominated", 2500, 42},
      {"b", 2000, 43}, {"d", 9000, 50}, {"worse-and-bigger", 9500, 44},
  };
  EXPECT_EQ(frontier_labels(points), (std::vector<std::string>{"a", "b", "c", "d"}));
}

TEST(ParetoFrontier, Ties) {
  // Same bytes: only the higher PSNR. Same PSNR: only the fewer bytes. Identical: the first.
  const std::vector<RdPoint> points = {
      {"same-bytes-lower", 1000, 39},     {"same-bytes-higher", 1000, 41},
      {"same-psnr-more-bytes", 1500, 41}, {"first-of-twins", 2000, 44},
      {"second-of-twins", 2000, 44},      {"top", 4000, 47},
  };
  EXPECT_EQ(frontier_labels(points),
            (std::vector<std::string>{"same-bytes-higher", "first-of-twins", "top"}));
  // The twins in the other order keep the other one: the first met wins.
  const std::vector<RdPoint> swapped = {{"x", 2000, 44}, {"y", 2000, 44}};
  EXPECT_EQ(frontier_labels(swapped), (std::vector<std::string>{"x"}));
}

TEST(ParetoFrontier, IgnoresNonFinitePointsAndHandlesEmpty) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<RdPoint> points = {
      {"nan-psnr", 10, nan}, {"a", 100, 30}, {"nan-bytes", nan, 90}};
  EXPECT_EQ(frontier_labels(points), (std::vector<std::string>{"a"}));
  EXPECT_TRUE(pareto_frontier({}).empty());
  // A single point is its own frontier.
  EXPECT_EQ(frontier_labels({{"only", 5, 5}}), (std::vector<std::string>{"only"}));
}

// Paper setting: 1000 bytes, 40 dB, 1 s to encode.
MaterialPoints material_a() {
  MaterialPoints m;
  m.material = "a";
  m.has_paper = true;
  m.paper = {"frank s6 b12", 1000, 40, 1.0};
  m.sweep = {
      {"small", 800, 41, 1.0},         // within 1x
      {"paper", 1000, 40, 1.0},        // the paper's setting itself, also in the sweep
      {"at-1x", 1000, 43, 2.0},        // exactly at the 1x budget: counts
      {"tie-bigger", 1900, 45, 8.0},   // ties with "tie-smaller" on PSNR: fewer bytes win
      {"tie-smaller", 1700, 45, 6.0},  // within 2x
      {"at-4x", 4000, 50, 12.0},       // within 4x
      {"over-4x", 4001, 60, 20.0},     // just over: never chosen
  };
  return m;
}

TEST(BudgetGain, PicksTheBestSettingWithinEachBudget) {
  const MaterialPoints a = material_a();
  MaterialGain g = material_gain(a, 1.0);
  EXPECT_TRUE(g.has_paper);
  EXPECT_TRUE(g.qualifying);
  EXPECT_EQ(g.best, "at-1x");
  EXPECT_DOUBLE_EQ(g.gain_db, 3.0);
  EXPECT_DOUBLE_EQ(g.bytes_ratio, 1.0);
  EXPECT_DOUBLE_EQ(g.encode_ratio, 2.0);

  g = material_gain(a, 2.0);
  EXPECT_EQ(g.best, "tie-smaller");
  EXPECT_DOUBLE_EQ(g.gain_db, 5.0);
  EXPECT_DOUBLE_EQ(g.bytes_ratio, 1.7);
  EXPECT_DOUBLE_EQ(g.encode_ratio, 6.0);

  g = material_gain(a, 4.0);
  EXPECT_EQ(g.best, "at-4x");
  EXPECT_DOUBLE_EQ(g.gain_db, 10.0);
  EXPECT_DOUBLE_EQ(g.encode_ratio, 12.0);
}

TEST(BudgetGain, MeansOverQualifyingMaterialsOnly) {
  MaterialPoints b;  // per-material budgets: b's paper bytes are 10x a's
  b.material = "b";
  b.has_paper = true;
  b.paper = {"frank s6 b12", 10000, 30, 2.0};
  b.sweep = {{"b-low", 9000, 29, 1.0}, {"b-mid", 15000, 36, 4.0}, {"b-high", 39000, 31, 9.0}};
  MaterialPoints c;  // every setting above 1x
  c.material = "c";
  c.has_paper = true;
  c.paper = {"frank s6 b12", 500, 35, 1.0};
  c.sweep = {{"c-big", 1500, 38, 3.0}};
  MaterialPoints no_paper;
  no_paper.material = "d";
  no_paper.sweep = {{"d-any", 1, 99, 1.0}};
  const std::vector<MaterialPoints> all = {material_a(), b, c, no_paper};

  const BudgetGain x1 = budget_gain(all, 1.0);
  EXPECT_EQ(x1.materials, 4);
  EXPECT_EQ(x1.qualifying, 2);  // a (+3) and b (b-low, -1); c has none, d no paper
  EXPECT_DOUBLE_EQ(x1.mean_gain_db, (3.0 - 1.0) / 2);
  EXPECT_DOUBLE_EQ(x1.min_gain_db, -1.0);
  EXPECT_DOUBLE_EQ(x1.max_gain_db, 3.0);
  EXPECT_DOUBLE_EQ(x1.mean_bytes_ratio, (1.0 + 0.9) / 2);
  EXPECT_DOUBLE_EQ(x1.mean_encode_ratio, (2.0 + 0.5) / 2);
  ASSERT_EQ(x1.per_material.size(), 4u);
  EXPECT_EQ(x1.per_material[1].best, "b-low");
  EXPECT_FALSE(x1.per_material[2].qualifying);
  EXPECT_TRUE(x1.per_material[2].has_paper);
  EXPECT_FALSE(x1.per_material[3].has_paper);
  EXPECT_FALSE(x1.per_material[3].qualifying);

  const BudgetGain x2 = budget_gain(all, 2.0);
  EXPECT_EQ(x2.qualifying, 2);                         // c-big is 3x
  EXPECT_DOUBLE_EQ(x2.mean_gain_db, (5.0 + 6.0) / 2);  // tie-smaller, b-mid

  const BudgetGain x4 = budget_gain(all, 4.0);
  EXPECT_EQ(x4.qualifying, 3);
  // a: at-4x (+10); b: b-mid (+6; b-high is within budget but lower); c: c-big (+3).
  EXPECT_DOUBLE_EQ(x4.mean_gain_db, (10.0 + 6.0 + 3.0) / 3);
  EXPECT_DOUBLE_EQ(x4.min_gain_db, 3.0);
  EXPECT_DOUBLE_EQ(x4.max_gain_db, 10.0);
  EXPECT_EQ(x4.per_material[1].best, "b-mid");

  const BudgetGain none = budget_gain({no_paper}, 4.0);
  EXPECT_EQ(none.qualifying, 0);
  EXPECT_TRUE(std::isnan(none.mean_gain_db));
}

TEST(BudgetGain, TargetsOfTheIssue) {
  EXPECT_EQ(target_gain_db(1.0), 2.0);
  EXPECT_EQ(target_gain_db(4.0), 6.0);
  EXPECT_TRUE(std::isnan(target_gain_db(2.0)));
}

TEST(Sweep, ComponentsKeyAndLabels) {
  auto s = parse_sweep({"components=1,2,auto bits=8,12"});
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->components, (std::vector<int>{1, 2, kAutoComponents}));
  std::vector<std::string> labels;
  for (const CodecSetting& c : s->settings()) labels.push_back(c.label());
  // Components vary outside bits, so that settings sharing a fit are adjacent; K = 1 labels are
  // the plain ones.
  EXPECT_EQ(labels, (std::vector<std::string>{"frank s6 b8", "frank s6 b12", "frank s6 b8 k2",
                                              "frank s6 b12 k2", "frank s6 b8 k-auto",
                                              "frank s6 b12 k-auto"}));
  EXPECT_EQ(s->primary(), paper_setting());

  s = parse_sweep({"slices=3"});
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->components, std::vector<int>{1});  // the default: the paper's model
  EXPECT_EQ(s->settings().front().label(), "frank s3 b12");

  EXPECT_EQ(paper_setting().label(), "frank s6 b12");
  EXPECT_EQ(paper_setting().components, 1);
  EXPECT_EQ((CodecSetting{"independence", 2, 9, 8}).label(), "separable s2 b9 k8");
  EXPECT_EQ(components_name(kAutoComponents), "auto");
  EXPECT_EQ(components_name(3), "3");
}

TEST(Sweep, ResidualBoundsSitOnThePrimarySettingAtEachComponentCount) {
  auto s = parse_sweep({"bits=8,10 residual=0.1,0.03"});
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->residual, (std::vector<double>{0.1, 0.03}));
  std::vector<std::string> labels;
  for (const CodecSetting& c : s->settings()) labels.push_back(c.label());
  // Without the default setting the primary is the first model; the layer's settings follow the
  // models, whose labels stay as they were.
  EXPECT_EQ(labels, (std::vector<std::string>{"frank s6 b8", "frank s6 b10", "frank s6 b8 E0.1",
                                              "frank s6 b8 E0.03"}));
  EXPECT_EQ(s->primary().label(), "frank s6 b8");
  EXPECT_EQ(s->settings()[3].max_error, 0.03);
  // With the default setting in the sweep, the layer sits on it, at each component count.
  s = parse_sweep({"residual=0.05 components=1,2"});
  ASSERT_TRUE(s.ok());
  const std::vector<CodecSetting> all = s->settings();
  ASSERT_EQ(all.size(), 4u);
  const CodecSetting d = default_setting();
  EXPECT_EQ(all[2], (CodecSetting{d.family, d.slices, d.bits, 1, 0.05}));
  EXPECT_EQ(all[3], (CodecSetting{d.family, d.slices, d.bits, 2, 0.05}));
  // With bits=auto in the sweep, on the bits the command chooses (`encode --max-error E`).
  s = parse_sweep({"bits=12,auto residual=0.2 components=1,2"});
  ASSERT_TRUE(s.ok());
  labels.clear();
  for (const CodecSetting& c : s->settings()) labels.push_back(c.label());
  EXPECT_EQ(labels, (std::vector<std::string>{"frank s6 b12", "frank s6 bauto", "frank s6 b12 k2",
                                              "frank s6 bauto k2", "frank s6 bauto E0.2",
                                              "frank s6 bauto k2 E0.2"}));
  EXPECT_EQ(s->primary().label(), "frank s6 b12");
  EXPECT_TRUE(parse_sweep({"slices=3"})->residual.empty());  // the models alone
  EXPECT_EQ((CodecSetting{"frank", 6, 10, 2, 1e-3}).label(), "frank s6 b10 k2 E0.001");
}

TEST(Sweep, BadComponentsNameTheKeyAndTheValidValues) {
  // Ranges in the encoder's words (validate()), named by the sweep's key.
  const std::string range = "components must be from 1 to " + std::to_string(kMaxComponents);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"components=0", range + ", not 0"},
      {"components=" + std::to_string(kMaxComponents + 1),
       range + ", not " + std::to_string(kMaxComponents + 1)},
      {"components=two", "components='two' is not a whole number or auto"},
      {"components=2.5", "components='2.5'"},
      {"components=", "'components=' has no values"},
      {"components=2,2", "components lists 2 twice"},
      {"components=auto,auto", "components lists auto twice"},
      {"components=1 components=2", "'components' is given twice"},
      {"colour=1", "(keys: slices, bits, family, components, residual)"},
      {"residual=0", "residual=0 adds no layer"},
      {"residual=none", "residual='none' is not a number"},
      {"residual=17", "residual must be from 1e-06 to 16, not 17"},
      {"residual=0.1x", "residual='0.1x' is not a number"},
      {"slices=91", "slices must be from 1 to 90, not 91"},
      {"bits=5", "bits must be from 6 to 16, not 5"},
      {"residual=", "'residual=' has no values"},
      {"residual=0.1,0.1", "residual lists 0.1 twice"},
  };
  for (const auto& [item, expect] : cases) {
    const auto s = parse_sweep({item});
    ASSERT_FALSE(s.ok()) << item;
    EXPECT_EQ(s.status().code(), ErrorCode::kInvalidArgument) << item;
    const std::string msg = s.status().message();
    EXPECT_NE(msg.find(expect), std::string::npos) << item << ": " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_EQ(msg.rfind("--sweep: ", 0), 0u) << msg;
  }
}

}  // namespace
}  // namespace cbrdf::report
