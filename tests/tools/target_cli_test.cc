// SPDX-License-Identifier: MIT
// `cbrdf encode --target-*` and `cbrdf info` on a valid table far from any BRDF (issue 40, item 7):
// values log-uniform in 1e-30..1e30. An unreachable target ends with the closest file, exit 0, and
// says why; the noise floor is a number or "not measurable", never inf or nan.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "cbrdf/coords.h"
#include "cbrdf/merl_io.h"
#include "table_builder.h"
#include "test_support.h"

namespace cbrdf {
namespace {
namespace fs = std::filesystem;
using testing::contains;
using testing::run_cli;
using testing::TempDir;

std::string q(const fs::path& p) {
  return "'" + p.string() + "'";
}

// Measured values exp(U(log 1e-30, log 1e30)); the bins below the horizon not measured.
fs::path write_log_uniform(const TempDir& tmp) {
  const BrdfTable t = testing::log_uniform_table(1e-30, 1e30, 40);
  const fs::path path = tmp / "log-uniform.binary";
  EXPECT_TRUE(write_merl(path, t).ok());
  return path;
}

constexpr const char* kClosest = "(the target could not be met: this is the closest)";

TEST(TargetCli, UnreachableTargetsWriteTheClosestFileAndSayWhy) {
  TempDir tmp;
  const fs::path in = write_log_uniform(tmp);
  const fs::path out = tmp / "out.cbrdf";
  // The search's lines go to standard output when the file does not.
  auto r = run_cli("encode " + q(in) + " -o " + q(out) + " --target-psnr 50");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, kClosest)) << r.out << r.err;
  // Why: the noise (thousands of per cent per bin).
  EXPECT_TRUE(contains(r.out, "note: the input is noisy (about 42")) << r.out;
  EXPECT_EQ(run_cli("info " + q(out)).exit_code, 0);

  // A budget no file fits: the smallest file.
  fs::remove(out);
  r = run_cli("encode " + q(in) + " -o " + q(out) + " --target-bytes 100");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, kClosest)) << r.out << r.err;
  EXPECT_TRUE(fs::exists(out));
}

TEST(TargetCli, InfoStatesAnUnmeasurableNoiseFloor) {
  TempDir tmp;
  const fs::path in = write_log_uniform(tmp);
  auto r = run_cli("info " + q(in));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The linear renders of the simulated noise overflow: that ceiling is not measurable; the
  // tone-mapped one is a number.
  EXPECT_TRUE(contains(r.out, "linear not measurable")) << r.out;
  EXPECT_TRUE(contains(r.out, "dB tone-mapped")) << r.out;
  EXPECT_FALSE(contains(r.out, "inf")) << r.out;
  EXPECT_FALSE(contains(r.out, "nan")) << r.out;

  r = run_cli("info --json " + q(in));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json noise = nlohmann::json::parse(r.out)["noise"];
  EXPECT_EQ(noise["psnr_ceiling_linear"], "not measurable") << noise.dump();
  ASSERT_TRUE(noise["psnr_ceiling_tonemapped"].is_number()) << noise.dump();
  EXPECT_TRUE(std::isfinite(noise["psnr_ceiling_tonemapped"].get<double>()));
}

}  // namespace
}  // namespace cbrdf
