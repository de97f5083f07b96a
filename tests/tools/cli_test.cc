// SPDX-License-Identifier: MIT
// The `cbrdf` command end to end: exit codes, one-line errors, no partial output files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "cbrdf/merl_io.h"
#include "test_support.h"

namespace cbrdf {
namespace {

namespace fs = std::filesystem;
using testing::run_cli;
using testing::TempDir;

int lines(const std::string& s) {
  return int(std::count(s.begin(), s.end(), '\n'));
}

TEST(Cli, HelpVersionAndUsageErrors) {
  auto r = run_cli("--help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* sub : {"sample", "info", "encode", "decode", "report"}) {
    EXPECT_NE(r.out.find(sub), std::string::npos) << sub;
    EXPECT_EQ(run_cli(std::string(sub) + " --help").exit_code, 0) << sub;
  }
  EXPECT_EQ(run_cli("--version").exit_code, 0);
  r = run_cli("");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  r = run_cli("encode --bits 99 x.binary -o y.cbrdf");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  r = run_cli("frobnicate");
  EXPECT_EQ(r.exit_code, 2);
}

TEST(Cli, SampleEncodeInfoDecodeRoundTrip) {
  TempDir tmp;
  const fs::path bin = tmp / "plastic.binary", enc = tmp / "plastic.cbrdf",
                 dec = tmp / "back.binary", exr = tmp / "back.exr";
  auto r = run_cli("sample --list");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("near-mirror"), std::string::npos);
  ASSERT_EQ(run_cli("sample plastic -o '" + bin.string() + "'").exit_code, 0);
  r = run_cli("encode '" + bin.string() + "' -o '" + enc.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("bytes"), std::string::npos);
  EXPECT_NE(r.out.find("tone-mapped"), std::string::npos);
  EXPECT_LT(fs::file_size(enc), 8192u);
  r = run_cli("info '" + enc.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The command writes version 1.3 where smaller (issue 28): the model in BASE.
  EXPECT_NE(r.out.find("BASE"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("version 1.3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frank"), std::string::npos);
  // The evaluator's memory, against the 35 MB table it replaces.
  EXPECT_NE(r.out.find("evaluator: "), std::string::npos) << r.out;
  r = run_cli("info --json '" + enc.string() + "'");
  ASSERT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("\"slices\""), std::string::npos);
  EXPECT_NE(r.out.find("\"evaluator_bytes\""), std::string::npos);
  r = run_cli("info '" + bin.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("equals the below-horizon geometry"), std::string::npos);
  r = run_cli("decode '" + enc.string() + "' -o '" + dec.string() + "' --exr '" + exr.string() +
              "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto a = read_merl(bin), b = read_merl(dec);
  ASSERT_TRUE(a.ok() && b.ok());
  // Not-measured bins come back exactly; measured ones are close (a lossy codec).
  std::size_t mask_diff = 0;
  for (int c = 0; c < kChannels; ++c)
    for (std::size_t i = 0; i < kBinsPerChannel; ++i)
      mask_diff += a->measured(c, i) != b->measured(c, i) ||
                   (!a->measured(c, i) && a->stored(c, i) != b->stored(c, i));
  EXPECT_EQ(mask_diff, 0u);
  EXPECT_GT(fs::file_size(exr), 100000u);
}

TEST(Cli, MixturesAndDataChosenSlices) {
  TempDir tmp;
  const fs::path bin = tmp / "plastic.binary", one = tmp / "one.cbrdf", two = tmp / "two.cbrdf",
                 sl = tmp / "auto.cbrdf";
  ASSERT_EQ(run_cli("sample plastic -o '" + bin.string() + "'").exit_code, 0);
  // The 1.0-1.2 coding, where mixtures are what makes a file 1.1.
  auto r = run_cli("encode '" + bin.string() + "' -o '" + one.string() +
                   "' --slices 3 --format-version 1.2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_cli("encode '" + bin.string() + "' -o '" + two.string() +
              "' --slices 3 --components 2 --format-version 1.2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(fs::file_size(two), fs::file_size(one));
  r = run_cli("info '" + two.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("version 1.1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("components R G B"), std::string::npos) << r.out;
  EXPECT_NE(run_cli("info '" + one.string() + "'").out.find("version 1.0"), std::string::npos);
  r = run_cli("info --json '" + two.string() + "'");
  EXPECT_NE(r.out.find("\"components\": 2"), std::string::npos) << r.out;
  r = run_cli("encode '" + bin.string() + "' -o '" + sl.string() + "' --slices auto --no-metrics");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(sl));
  for (const std::string bad :
       {"--components 9", "--components two", "--components 0", "--slices 0", "--slices 91",
        "--slices many", "--slice-placement random", "--mixture-copulas none"}) {
    const fs::path out = tmp / "bad.cbrdf";
    r = run_cli("encode '" + bin.string() + "' -o '" + out.string() + "' " + bad);
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_EQ(lines(r.err), 1) << bad << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << bad;
  }
  r = run_cli("encode '" + bin.string() + "' -o '" + (tmp / "x.cbrdf").string() +
              "' --components 9");
  EXPECT_NE(r.err.find("--components must be from 1 to 8, not 9"), std::string::npos) << r.err;
  r = run_cli("encode '" + bin.string() + "' -o '" + (tmp / "x.cbrdf").string() +
              "' --mixture-copulas none");
  EXPECT_NE(r.err.find("--mixture-copulas must be fit or independence, not 'none'"),
            std::string::npos)
      << r.err;
  // Copulas left at independence: a 2-component file without the copula parameters' bytes.
  const fs::path plain = tmp / "plain.cbrdf";
  r = run_cli("encode '" + bin.string() + "' -o '" + plain.string() +
              "' --slices 3 --components 2 --mixture-copulas independence --no-metrics");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_LT(fs::file_size(plain), fs::file_size(two));
}

TEST(Cli, BadInputIsOneLineExitOneAndNoOutputFile) {
  TempDir tmp;
  const fs::path junk = tmp / "junk.cbrdf", out = tmp / "out.binary";
  { std::ofstream(junk) << "this is not a cbrdf file"; }
  auto r = run_cli("decode '" + junk.string() + "' -o '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("junk.cbrdf"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // A truncated MERL file: named, refused, nothing written.
  const fs::path short_bin = tmp / "short.binary", enc = tmp / "short.cbrdf";
  { std::ofstream(short_bin, std::ios::binary) << std::string(1000, '\0'); }
  r = run_cli("encode '" + short_bin.string() + "' -o '" + enc.string() + "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("short.binary"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(enc));
  // No leftover temporary files either.
  int files = 0;
  for (const auto& e : fs::directory_iterator(tmp.path())) files += e.is_regular_file();
  EXPECT_EQ(files, 2);
  // Missing input: exit code 2 (CLI11 checks it exists) or 1, and one line.
  r = run_cli("info '" + (tmp / "missing.cbrdf").string() + "'");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(lines(r.err), 1) << r.err;
}

}  // namespace
}  // namespace cbrdf
