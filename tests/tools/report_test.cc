// SPDX-License-Identifier: MIT
// `cbrdf report`: argument errors, and a small run whose figures are checked against what
// `cbrdf encode` writes and what the library measures on the decoded file.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <tuple>

#include "cbrdf/image_io.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/metrics.h"
#include "test_support.h"

namespace cbrdf {
namespace {

using testing::run_cli;
using testing::TempDir;
namespace fs = std::filesystem;

int lines(const std::string& s) {
  return int(std::count(s.begin(), s.end(), '\n'));
}

TEST(ReportArgs, BadSweepsAreOneLineUsageErrors) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"slices=0", "slices must be from 1 to 90, not 0"},
      {"slices=91", "1 to 90"},
      {"bits=5", "bits must be from 6 to 16, not 5"},
      {"bits=17", "6 to 16"},
      {"bits=8.5", "bits='8.5'"},
      {"slices=a", "slices='a'"},
      {"slices=", "has no values"},
      {"slices=2,,3", "slices=''"},
      {"slices=1,1", "lists 1 twice"},
      {"family=frank,foo", "family='foo'"},
      {"colour=red", "unknown key 'colour'"},
      {"slices=2 slices=3", "given twice"},
      {"'slices=2 bits=6' slices=3", "given twice"},
      {"nokey", "'nokey' is not KEY=VALUES"},
      {"components=0", "components must be from 1 to 8, not 0"},
      {"components=1,auto,auto", "components lists auto twice"},
  };
  for (const auto& [sweep, expect] : cases) {
    const auto r = run_cli("report --builtin --sweep " + sweep);
    EXPECT_EQ(r.exit_code, 2) << sweep;
    EXPECT_EQ(lines(r.err), 1) << sweep << ": " << r.err;
    EXPECT_NE(r.err.find("--sweep"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << sweep << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

TEST(ReportArgs, OtherUsageErrors) {
  auto r = run_cli("report --builtin --baselines analytic,bogus");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown baseline 'bogus'"), std::string::npos) << r.err;
  r = run_cli("report --builtin --analytic-loss l1");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--analytic-loss"), std::string::npos) << r.err;
  r = run_cli("report");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--builtin"), std::string::npos) << r.err;
  // --builtin takes a kind; a value that is neither a kind nor a file is an error.
  r = run_cli("report --builtin metals");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--builtin takes measured (the default), analytic or all, not 'metals'"),
            std::string::npos)
      << r.err;
}

// One material, four settings (K = 1 and 2 mixtures, 6 and 16 bits), the paper's setting as the
// reference and two baselines: small enough for a unit test, large enough to
// check every output against an independent computation.
class ReportRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One run for all of the suite's test processes (testing::shared_run).
    fs::path dir;
    run_ = new testing::CommandResult(testing::shared_run(
        "report-run",
        [](const fs::path& d) {
          input_ = d / "plastic.binary";
          out_ = d / "report";
          const auto s = run_cli("sample plastic -o '" + input_.string() + "'");
          if (s.exit_code != 0) return s;
          return report_input("",
                              "--jobs 1 --progress always --sweep slices=3 bits=6,16 "
                              "components=1,2 --baselines float16,separable",
                              out_);
        },
        &dir));
    input_ = dir / "plastic.binary";
    out_ = dir / "report";
  }
  // `cbrdf GLOBAL report INPUT OPTIONS -o OUT` on the fixture's material.
  static testing::CommandResult report_input(const std::string& global, const std::string& options,
                                             const fs::path& out) {
    return run_cli(global + " report '" + input_.string() + "' " + options + " -o '" +
                   out.string() + "'");
  }
  static void TearDownTestSuite() { delete run_; }
  static nlohmann::json row(const nlohmann::json& rows, const std::string& label) {
    for (const auto& r : rows) {
      if (r["label"] == label) return r;
    }
    ADD_FAILURE() << "no row " << label;
    return {};
  }

  static fs::path input_, out_;
  static testing::CommandResult* run_;
};
fs::path ReportRun::input_, ReportRun::out_;
testing::CommandResult* ReportRun::run_ = nullptr;

TEST_F(ReportRun, SucceedsWithAProgressBarAndATable) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  EXPECT_NE(run_->err.find("100%"), std::string::npos) << run_->err;  // the bar's last step
  EXPECT_NE(run_->out.find("frank s3 b16"), std::string::npos) << run_->out;
  EXPECT_NE(run_->out.find("float16+zstd"), std::string::npos) << run_->out;
}

TEST_F(ReportRun, StdoutEndsWithTheAnswerAndWhereTheReportIs) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const std::string& out = run_->out;
  const std::size_t summary = out.rfind("Summary: the paper's setting (frank s6 b12)");
  ASSERT_NE(summary, std::string::npos) << out;
  // After the measurement tables: the answer is the last thing printed.
  EXPECT_GT(summary, out.rfind("Table 4: the sweep"));
  const std::string tail = "Full report: " + (out_ / "report.html").string() + "\n";
  ASSERT_GE(out.size(), tail.size());
  EXPECT_EQ(out.substr(out.size() - tail.size()), tail) << out.substr(summary);
  // The plastic row: the paper's setting's bytes and dB as report.json has them.
  const auto json = nlohmann::json::parse(testing::read_text(out_ / "report.json"));
  const auto paper = row(json["rows"], "frank s6 b12");
  char expect[96];
  std::snprintf(expect, sizeof expect, "plastic   %11.0f  %8.2f", paper["bytes"].get<double>(),
                paper["psnr_tonemapped_db"].get<double>());
  EXPECT_NE(out.find(expect, summary), std::string::npos) << expect << "\n" << out.substr(summary);
  // report.md opens with the same answer, then the frontier figure.
  const std::string md = testing::read_text(out_ / "report.md");
  EXPECT_LT(md.find("On 1 material, the paper's setting"), md.find("![frontier_mean.svg]"));
  EXPECT_LT(md.find("![frontier_mean.svg]"), md.find("## Summary: the paper's setting"));
  EXPECT_LT(md.find("## Summary: the paper's setting"), md.find("## Table 1"));
}

TEST_F(ReportRun, NoProgressBarWhenStderrIsNotATerminalAndOnlyThePapersSetting) {
  TempDir other;
  // run_cli sends stderr to a file: the default (auto) draws no bar there. The sweep holds only
  // the paper's setting, so there is no gain table and no target verdict, but a hint.
  const auto r = report_input("", "--sweep slices=6 bits=12 --baselines none", other / "r");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out.find("Gain over the paper's setting"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("held only the paper's setting"), std::string::npos) << r.out;
  const std::string md = testing::read_text(other / "r" / "report.md");
  EXPECT_NE(md.find("held only the paper's setting"), std::string::npos);
  EXPECT_EQ(md.find("## Frontier"), std::string::npos);
  EXPECT_EQ(md.find("## Gain over"), std::string::npos);
  EXPECT_EQ(md.find("| yes |"), std::string::npos);
  EXPECT_EQ(md.find("| no |"), std::string::npos);

  const auto bad = run_cli("report '" + input_.string() + "' --progress sometimes");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--progress"), std::string::npos) << bad.err;
}

TEST_F(ReportRun, QuietPrintsNothing) {
  TempDir other;
  const auto r = report_input("-q", "--sweep bits=6 slices=1 --baselines none", other / "r");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_TRUE(fs::exists(other / "r" / "report.html"));
}

TEST_F(ReportRun, ContainerSizeIsWhatEncodeWritesAndPsnrIsWhatTheLibraryMeasures) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const auto json = nlohmann::json::parse(testing::read_text(out_ / "report.json"));
  const auto rows = json["rows"];
  // Sweep rows, the paper's setting as a reference, the separable baseline at the primary (first)
  // setting, float16.
  std::vector<std::string> labels;
  for (const auto& r : rows) labels.push_back(r["label"]);
  EXPECT_EQ(labels, (std::vector<std::string>{"frank s3 b6", "frank s3 b16", "frank s3 b6 k2",
                                              "frank s3 b16 k2", "frank s6 b12", "separable s3 b6",
                                              "float16+zstd"}));
  EXPECT_EQ(json["settings"]["primary"], "frank s3 b6");
  EXPECT_EQ(json["settings"]["paper"], "frank s6 b12");
  for (const auto& r : rows) {
    const bool paper = r["label"] == "frank s6 b12";
    EXPECT_EQ(r["paper"].get<bool>(), paper) << r["label"];
    if (paper) {
      EXPECT_FALSE(r["in_sweep"].get<bool>());
    }
  }
  EXPECT_EQ(row(rows, "frank s3 b6 k2")["components"], "2");
  EXPECT_EQ(row(rows, "frank s3 b6")["components"], "1");

  const TempDir tmp;
  const fs::path cbrdf = tmp / "p.cbrdf", decoded = tmp / "p.binary";
  ASSERT_EQ(run_cli("-q encode '" + input_.string() + "' -o '" + cbrdf.string() +
                    "' --slices 3 --bits 16 --no-metrics")
                .exit_code,
            0);
  const auto b16 = row(rows, "frank s3 b16");
  EXPECT_EQ(b16["bytes"].get<double>(), double(fs::file_size(cbrdf)));
  EXPECT_EQ(b16["input_bytes"].get<double>(), double(fs::file_size(input_)));

  ASSERT_EQ(run_cli("-q decode '" + cbrdf.string() + "' -o '" + decoded.string() + "'").exit_code,
            0);
  auto ref = read_merl(input_);
  auto dec = read_merl(decoded);
  ASSERT_TRUE(ref.ok() && dec.ok());
  const ImageMetrics im = sphere_psnr(*ref, *dec);
  const BrdfMetrics bm = brdf_metrics(*ref, *dec);
  EXPECT_NEAR(b16["psnr_tonemapped_db"].get<double>(), im.psnr_tonemapped, 1e-9);
  EXPECT_NEAR(b16["psnr_linear_db"].get<double>(), im.psnr_linear, 1e-9);
  EXPECT_NEAR(b16["rel_rmse"].get<double>(), bm.rel_rmse_mean, 1e-12);
  EXPECT_NEAR(b16["cos_rmse"].get<double>(), bm.cos_rmse_mean, 1e-12);

  // More bits cost bytes and buy accuracy; float16 is far more accurate and far larger.
  const auto b6 = row(rows, "frank s3 b6");
  EXPECT_LT(b6["bytes"].get<double>(), b16["bytes"].get<double>());
  EXPECT_LT(b6["psnr_tonemapped_db"].get<double>(), b16["psnr_tonemapped_db"].get<double>());
  const auto half = row(rows, "float16+zstd");
  EXPECT_GT(half["psnr_tonemapped_db"].get<double>(), 70.0);
  EXPECT_GT(half["bytes"].get<double>(), 50 * b16["bytes"].get<double>());
  EXPECT_LT(half["bytes"].get<double>(), 0.1 * half["input_bytes"].get<double>());
  for (const auto& r : rows) {
    EXPECT_GT(r["encode_s"].get<double>(), 0.0) << r["label"];
    EXPECT_GT(r["decode_s"].get<double>(), 0.0) << r["label"];
    EXPECT_GT(r["eval_ns"].get<double>(), 0.0) << r["label"];
  }
}

// Lossless baselines on the most compressible sample (zstd -19 of a MERL file takes seconds).
TEST(ReportLossless, ZstdAndXzOfTheBinary) {
  TempDir tmp;
  const fs::path input = tmp / "lambertian.binary", out = tmp / "report";
  ASSERT_EQ(run_cli("-q sample lambertian -o '" + input.string() + "'").exit_code, 0);
  const auto r =
      run_cli("-q report '" + input.string() +
              "' --sweep slices=1 bits=6 --baselines lossless,float16 -o '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = nlohmann::json::parse(testing::read_text(out / "report.json"))["rows"];
  // The sweep's setting, the paper's setting (the reference), float16, then the lossless rows.
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[1]["label"], "frank s6 b12");
  EXPECT_EQ(rows[3]["label"], "zstd-19");
  EXPECT_EQ(rows[4]["label"], "xz-6");
  for (int i : {3, 4}) {
    const auto& row = rows[std::size_t(i)];
    EXPECT_EQ(row["kind"], "lossless");
    EXPECT_EQ(row["psnr_tonemapped_db"].get<double>(), kPsnrCapDb);
    EXPECT_EQ(row["input_bytes"].get<double>(), double(fs::file_size(input)));
    // A constant-albedo table compresses well, but doubles stay larger than halves.
    EXPECT_LT(row["bytes"].get<double>(), 0.01 * row["input_bytes"].get<double>());
    EXPECT_GT(row["bytes"].get<double>(), 1000.0);
    EXPECT_GT(row["decode_s"].get<double>(), 0.0);
  }
  const std::string md = testing::read_text(out / "report.md");
  EXPECT_NE(md.find("| zstd-19 | xz-6 |"), std::string::npos) << md;
}

// `--sweep residual=...`: the model plus the residual layer, the same bytes as the command that
// the setting names, and more accurate than the model alone.
TEST(ReportResidual, ResidualSettingsAreWhatEncodeWritesWithVisibilitySteps) {
  TempDir tmp;
  const fs::path input = tmp / "plastic.binary", out = tmp / "report";
  ASSERT_EQ(run_cli("-q sample plastic -o '" + input.string() + "'").exit_code, 0);
  const auto r = run_cli("-q report '" + input.string() +
                         "' --jobs 1 --sweep slices=3 bits=8 residual=0.05 --baselines none "
                         "-o '" +
                         out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto json = nlohmann::json::parse(testing::read_text(out / "report.json"));
  EXPECT_EQ(json["settings"]["residual"], nlohmann::json::parse("[0.05]"));
  const auto& rows = json["rows"];
  ASSERT_GE(rows.size(), 2u);
  EXPECT_EQ(rows[0]["label"], "frank s3 b8");
  EXPECT_EQ(rows[1]["label"], "frank s3 b8 E0.05");
  EXPECT_EQ(rows[0]["max_error"].get<double>(), 0.0);
  EXPECT_EQ(rows[1]["max_error"].get<double>(), 0.05);

  const fs::path visible = tmp / "v.cbrdf", one = tmp / "o.cbrdf";
  const std::string encode = "-q encode '" + input.string() + "' --slices 3 --bits 8 --no-metrics ";
  ASSERT_EQ(
      run_cli(encode + "--max-error 0.05 --residual-steps visibility -o '" + visible.string() + "'")
          .exit_code,
      0);
  ASSERT_EQ(run_cli(encode + "--max-error 0.05 -o '" + one.string() + "'").exit_code, 0);
  EXPECT_EQ(rows[1]["bytes"].get<double>(), double(fs::file_size(visible)));
  // Coarser steps where bins count less: fewer bytes than one bound everywhere.
  EXPECT_LT(fs::file_size(visible), fs::file_size(one));
  const auto info = run_cli("info --json '" + visible.string() + "'");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const auto residual = nlohmann::json::parse(info.out)["residual"];
  EXPECT_EQ(residual["mode"], 4) << residual;  // a 1.3 file: a step per level
  // E bounds the most visible rows; the file's bound is the coarsest row's (cbrdf info).
  EXPECT_EQ(residual["min_error"].get<double>(), 0.05);
  EXPECT_GT(residual["max_error"].get<double>(), 0.05);

  // The layer buys accuracy for bytes.
  EXPECT_GT(rows[1]["bytes"].get<double>(), rows[0]["bytes"].get<double>());
  EXPECT_GT(rows[1]["psnr_tonemapped_db"].get<double>(),
            rows[0]["psnr_tonemapped_db"].get<double>() + 1.0);
  const std::string csv = testing::read_text(out / "report.csv");
  EXPECT_NE(csv.find(",detail,max_error\n"), std::string::npos);
  EXPECT_NE(csv.find(",0.05\n"), std::string::npos) << csv;
}

TEST(EncodeResidualSteps, ErrorsNameWhatToGive) {
  TempDir tmp;
  const fs::path input = tmp / "plastic.binary", out = tmp / "o.cbrdf";
  ASSERT_EQ(run_cli("-q sample plastic -o '" + input.string() + "'").exit_code, 0);
  const std::string encode = "encode '" + input.string() + "' -o '" + out.string() + "' ";
  auto r = run_cli(encode + "--residual-steps visibility");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--residual-steps visibility needs --max-error above 0"), std::string::npos)
      << r.err;
  r = run_cli(encode + "--residual-steps visibility --target-psnr 50");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--residual-steps and a target"), std::string::npos) << r.err;
  r = run_cli(encode + "--max-error 0.05 --residual-steps rows");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--residual-steps must be one or visibility, not 'rows'"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// Points on no other point's dominated side: an independent, quadratic frontier.
std::vector<std::string> slow_frontier(
    const std::vector<std::tuple<std::string, double, double>>& p) {
  std::vector<std::pair<double, std::string>> kept;
  for (const auto& [label, bytes, psnr] : p) {
    bool dominated = false;
    for (const auto& [l2, b2, p2] : p) {
      if (b2 <= bytes && p2 >= psnr && (b2 < bytes || p2 > psnr)) dominated = true;
    }
    if (!dominated) kept.emplace_back(bytes, label);
  }
  std::sort(kept.begin(), kept.end());
  std::vector<std::string> out;
  for (const auto& k : kept) out.push_back(k.second);
  return out;
}

// The page's navigation names every section once, each by a name of its own, and every link
// leads to a section of the page.
TEST_F(ReportRun, NavigationNamesEachSectionOnce) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const std::string html = testing::read_text(out_ / "report.html");
  const std::size_t begin = html.find("<nav>"), end = html.find("</nav>");
  ASSERT_NE(begin, std::string::npos);
  ASSERT_NE(end, std::string::npos);
  const std::string nav = html.substr(begin, end - begin);
  const std::regex link("<a href=\"#([^\"]+)\">([^<]+)</a>");
  std::set<std::string> names, ids;
  int links = 0;
  for (auto it = std::sregex_iterator(nav.begin(), nav.end(), link); it != std::sregex_iterator();
       ++it, ++links) {
    const std::string id = (*it)[1].str(), name = (*it)[2].str();
    EXPECT_TRUE(names.insert(name).second) << "'" << name << "' names two sections: " << nav;
    EXPECT_TRUE(ids.insert(id).second) << id;
    EXPECT_NE(html.find(" id=\"" + id + "\""), std::string::npos) << id;
    EXPECT_LE(name.size(), 32u) << "a navigation name, not a title: " << name;
  }
  // The summary, the three frontier tables, the per-model tables, figures and materials.
  EXPECT_GE(links, 10) << nav;
  for (const char* name : {"Gain by budget", "Frontier settings", "Gain per material"}) {
    EXPECT_TRUE(names.count(name)) << name << " missing from " << nav;
  }
}

TEST_F(ReportRun, MixturesFrontierAndGainOverThePapersSetting) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const auto json = nlohmann::json::parse(testing::read_text(out_ / "report.json"));
  const auto rows = json["rows"];
  // On the plastic sample two components cost bytes and buy accuracy, at both bit depths.
  for (const char* b : {"b6", "b16"}) {
    const auto k1 = row(rows, std::string("frank s3 ") + b);
    const auto k2 = row(rows, std::string("frank s3 ") + b + " k2");
    EXPECT_GT(k2["bytes"].get<double>(), k1["bytes"].get<double>()) << b;
    EXPECT_GT(k2["psnr_tonemapped_db"].get<double>(), k1["psnr_tonemapped_db"].get<double>() + 3)
        << b;
  }
  // The K = 2 row is what `cbrdf encode --components 2` writes.
  const TempDir tmp;
  const fs::path k2file = tmp / "k2.cbrdf";
  ASSERT_EQ(run_cli("-q encode '" + input_.string() + "' -o '" + k2file.string() +
                    "' --slices 3 --bits 16 --components 2 --no-metrics")
                .exit_code,
            0);
  EXPECT_EQ(row(rows, "frank s3 b16 k2")["bytes"].get<double>(), double(fs::file_size(k2file)));

  // frontier.csv: the sweep's frontier (not the paper's reference row) for the material and the
  // means (one material: the same points).
  std::vector<std::tuple<std::string, double, double>> sweep;
  const nlohmann::json* paper = nullptr;
  for (const auto& r : rows) {
    if (r["in_sweep"].get<bool>()) {
      sweep.emplace_back(r["label"], r["bytes"].get<double>(),
                         r["psnr_tonemapped_db"].get<double>());
    }
    if (r["paper"].get<bool>()) paper = &r;
  }
  ASSERT_NE(paper, nullptr);
  const std::vector<std::string> want = slow_frontier(sweep);
  ASSERT_TRUE(fs::exists(out_ / "frontier.csv"));
  std::istringstream csv(testing::read_text(out_ / "frontier.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "scope,setting,bytes,psnr_tonemapped_db,encode_s");
  std::vector<std::string> got_material, got_mean;
  while (std::getline(csv, line)) {
    const std::string scope = line.substr(0, line.find(','));
    const std::size_t a = line.find(',') + 1;
    const std::string label = line.substr(a, line.find(',', a) - a);
    (scope == "mean" ? got_mean : got_material).push_back(label);
    EXPECT_TRUE(scope == "mean" || scope == "plastic") << line;
  }
  EXPECT_EQ(got_material, want);
  EXPECT_EQ(got_mean, want);
  EXPECT_EQ(json["frontier"]["per_material"]["plastic"].get<std::vector<std::string>>(), want);

  // The gain table: per budget, the best sweep setting within it against the paper's setting.
  const std::string md = testing::read_text(out_ / "report.md");
  EXPECT_NE(md.find("## Gain over the paper's setting (frank s6 b12) at 1x, 2x and 4x its bytes"),
            std::string::npos);
  const double paper_bytes = (*paper)["bytes"].get<double>();
  const double paper_psnr = (*paper)["psnr_tonemapped_db"].get<double>();
  for (double f : {1.0, 2.0, 4.0}) {
    double best = -1e9;
    for (const auto& [label, bytes, psnr] : sweep) {
      if (bytes <= f * paper_bytes) best = std::max(best, psnr);
    }
    char expect[96];
    if (best > -1e9) {
      std::snprintf(expect, sizeof expect, "| %gx | 1/1 | %+.2f |", f, best - paper_psnr);
    } else {
      std::snprintf(expect, sizeof expect, "| %gx | 0/1 | - |", f);
    }
    EXPECT_NE(md.find(expect), std::string::npos) << expect << "\n" << md.substr(0, 3000);
  }
  EXPECT_NE(md.find("frontier.csv"), std::string::npos);
  // The frontier plot marks the paper's setting and names the frontier's settings.
  const std::string svg = testing::read_text(out_ / "frontier_plastic.svg");
  EXPECT_NE(svg.find("paper: frank s6 b12"), std::string::npos);
  for (const std::string& l : want)
    EXPECT_NE(svg.find(">" + l + "</text>"), std::string::npos) << l;
}

TEST_F(ReportRun, CsvHoldsTheSameRows) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const auto json = nlohmann::json::parse(testing::read_text(out_ / "report.json"));
  std::istringstream csv(testing::read_text(out_ / "report.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("material,model,kind,slices,bits,", 0), 0u) << line;
  std::size_t n = 0;
  while (std::getline(csv, line)) {
    ASSERT_LT(n, json["rows"].size());
    const auto& r = json["rows"][n++];
    std::vector<std::string> f;
    std::istringstream fields(line);
    for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
    ASSERT_GE(f.size(), 9u) << line;
    EXPECT_EQ(f[0], r["material"]);
    EXPECT_EQ(f[1], r["model"]);
    EXPECT_EQ(std::stod(f[8]), r["bytes"].get<double>());
  }
  EXPECT_EQ(n, json["rows"].size());
}

TEST_F(ReportRun, MarkdownHasThePapersTablesAndTheCostOfAccuracy) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const std::string md = testing::read_text(out_ / "report.md");
  for (const char* s : {"## Table 1: sphere PSNR", "## Table 2: storage", "## Table 3: means",
                        "## Table 4: the sweep", "## Table 5: what accuracy costs in time",
                        "| frank s3 b6 -> frank s3 b16 |", "xz preset 6", "| plastic |"}) {
    EXPECT_NE(md.find(s), std::string::npos) << s;
  }
}

// Table 3 times the figure-4 layout rendered from the primary and the paper's models and from the
// measured table (nearest-bin and trilinear); the ratio cells are the model's time over the
// table's as report.json records them.
TEST_F(ReportRun, TimeTableComparesRenderingWithTheMeasuredTable) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const auto json = nlohmann::json::parse(testing::read_text(out_ / "report.json"));
  ASSERT_EQ(json["table_renders"].size(), 1u);
  const auto& t = json["table_renders"][0];
  EXPECT_EQ(t["material"], "plastic");
  EXPECT_EQ(t["width"], 1320);
  EXPECT_EQ(t["height"], 240);
  const double nearest = t["nearest_s"], trilinear = t["trilinear_s"];
  EXPECT_GT(nearest, 0.0);
  EXPECT_GT(trilinear, 0.0);
  EXPECT_GT(t["trilinear_eval_ns"].get<double>(), 0.0);
  const auto primary = row(json["rows"], "frank s3 b6");
  const auto paper = row(json["rows"], "frank s6 b12");
  ASSERT_TRUE(primary["render_s"].is_number());
  ASSERT_TRUE(paper["render_s"].is_number());
  EXPECT_TRUE(row(json["rows"], "float16+zstd")["render_s"].is_null());
  const double model = primary["render_s"];
  const std::string md = testing::read_text(out_ / "report.md");
  const std::size_t table3 = md.find("## Table 3: means");
  ASSERT_NE(table3, std::string::npos);
  const std::string t3 = md.substr(table3, md.find("## Table 4") - table3);
  EXPECT_NE(t3.find("| render s | render / nearest table | render / trilinear table |"),
            std::string::npos)
      << t3;
  // One material: mean and max are the same ratio.
  char cells[160];
  std::snprintf(cells, sizeof cells, "| %.2fx (max %.2fx) | %.2fx (max %.2fx) |", model / nearest,
                model / nearest, model / trilinear, model / trilinear);
  const std::size_t primary_row = t3.find("| frank s3 b6 |");
  ASSERT_NE(primary_row, std::string::npos) << t3;
  const std::string line = t3.substr(primary_row, t3.find('\n', primary_row) - primary_row);
  EXPECT_NE(line.find(cells), std::string::npos) << line << "\n" << cells;
  for (const char* r : {"| measured table, nearest-bin lookup | 34992012 | 1:1 |",
                        "| measured table, trilinear lookup | 34992012 | 1:1 |"}) {
    EXPECT_NE(t3.find(r), std::string::npos) << r << "\n" << t3;
  }
}

TEST_F(ReportRun, WritesFiguresAndSphereImages) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  for (const char* f : {"frontier_mean.svg", "time_psnr.svg", "eval_psnr.svg",
                        "psnr_by_material.svg", "frontier_plastic.svg", "polar_plastic.svg"}) {
    const std::string svg = testing::read_text(out_ / f);
    EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u) << f;
    EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n") << f;
    EXPECT_NE(svg.find("<polyline"), std::string::npos) << f;
  }
  // The polar plot holds the measured curve and the primary setting's, at three incidences.
  const std::string polar = testing::read_text(out_ / "polar_plastic.svg");
  for (const char* s : {"frank s3 b6, theta_i 0", "theta_i 45", "theta_i 75"}) {
    EXPECT_NE(polar.find(s), std::string::npos) << s;
  }
  for (const char* which : {"reference", "decoded", "difference"}) {
    auto png = read_png(out_ / ("sphere_plastic_" + std::string(which) + ".png"));
    ASSERT_TRUE(png.ok()) << png.status().message();
    EXPECT_EQ(png->width, 256);
    EXPECT_EQ(png->height, 256);
  }
  auto ref = read_png(out_ / "sphere_plastic_reference.png");
  auto dec = read_png(out_ / "sphere_plastic_decoded.png");
  ASSERT_TRUE(ref.ok() && dec.ok());
  EXPECT_NE(ref->data, dec->data);  // lossy at 6 bits
  const auto mask = sphere_mask(256);
  EXPECT_GT(psnr(*ref, *dec, 1, 1.0, &mask), 30.0);  // but close
}

}  // namespace
}  // namespace cbrdf
