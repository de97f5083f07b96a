// `cbrdf report`: argument errors, and a small run whose figures are checked against what
// `cbrdf encode` writes and what the library measures on the decoded file.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

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
      {"slices=0", "slices='0'"},
      {"slices=91", "1 to 90"},
      {"bits=5", "bits='5'"},
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
}

// One material, two settings and two baselines: small enough for a unit test, large enough to
// check every output against an independent computation.
class ReportRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    input_ = *dir_ / "plastic.binary";
    ASSERT_EQ(run_cli("sample plastic -o '" + input_.string() + "'").exit_code, 0);
    out_ = *dir_ / "report";
    run_ = new testing::CommandResult(
        run_cli("report '" + input_.string() +
                "' --jobs 1 --sweep slices=3 bits=6,16 --baselines float16,separable -o '" +
                out_.string() + "'"));
  }
  static void TearDownTestSuite() {
    delete run_;
    delete dir_;
  }
  static nlohmann::json row(const nlohmann::json& rows, const std::string& label) {
    for (const auto& r : rows) {
      if (r["label"] == label) return r;
    }
    ADD_FAILURE() << "no row " << label;
    return {};
  }

  static TempDir* dir_;
  static fs::path input_, out_;
  static testing::CommandResult* run_;
};
TempDir* ReportRun::dir_ = nullptr;
fs::path ReportRun::input_, ReportRun::out_;
testing::CommandResult* ReportRun::run_ = nullptr;

TEST_F(ReportRun, SucceedsWithAProgressBarAndATable) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  EXPECT_NE(run_->err.find("100%"), std::string::npos) << run_->err;  // the bar's last step
  EXPECT_NE(run_->out.find("frank s3 b16"), std::string::npos) << run_->out;
  EXPECT_NE(run_->out.find("float16+zstd"), std::string::npos) << run_->out;
}

TEST_F(ReportRun, QuietPrintsNothing) {
  TempDir other;
  const auto r =
      run_cli("-q report '" + input_.string() + "' --sweep bits=6 slices=1 --baselines none -o '" +
              (other / "r").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_TRUE(fs::exists(other / "r" / "report.html"));
}

TEST_F(ReportRun, ContainerSizeIsWhatEncodeWritesAndPsnrIsWhatTheLibraryMeasures) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const auto json = nlohmann::json::parse(testing::read_text(out_ / "report.json"));
  const auto rows = json["rows"];
  // Sweep rows, the separable baseline at the primary (first) setting, float16 and lossless.
  std::vector<std::string> labels;
  for (const auto& r : rows) labels.push_back(r["label"]);
  EXPECT_EQ(labels, (std::vector<std::string>{"frank s3 b6", "frank s3 b16", "separable s3 b6",
                                              "float16+zstd"}));
  EXPECT_EQ(json["settings"]["primary"], "frank s3 b6");

  const fs::path cbrdf = *dir_ / "p.cbrdf", decoded = *dir_ / "p.binary";
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
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[2]["label"], "zstd-19");
  EXPECT_EQ(rows[3]["label"], "xz-6");
  for (int i : {2, 3}) {
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

TEST_F(ReportRun, WritesFiguresAndSphereImages) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  for (const char* f : {"rd_mean.svg", "time_psnr.svg", "eval_psnr.svg", "psnr_by_material.svg",
                        "rd_plastic.svg", "polar_plastic.svg"}) {
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
