// SPDX-License-Identifier: MIT
// validate() and the wording of its problems (cbrdf/encoder_settings.h). The same refusals
// through every front end: tests/tools/settings_frontends_test.cc.
#include "cbrdf/encoder_settings.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cbrdf/encoder.h"
#include "cbrdf/rate_control.h"

namespace cbrdf {
namespace {

std::vector<std::string> settings_of(const std::vector<SettingProblem>& problems) {
  std::vector<std::string> names;
  for (const SettingProblem& p : problems) names.push_back(p.setting);
  return names;
}

TEST(EncoderSettings, DefaultsAreValid) {
  EXPECT_TRUE(validate(EncoderSettings{}).empty());
  EXPECT_TRUE(validate(RateTarget{}).empty());
}

TEST(EncoderSettings, EveryProblemIsNamedInAFixedOrder) {
  EncoderSettings st;
  st.fit.slices = 0;
  st.fit.components = 9;
  st.fit.threads = -1;
  st.auto_bits.enabled = false;
  st.container.bits = 17;
  st.container.zstd_level = 23;
  st.residual.max_error = 20;
  st.residual.lossless = true;
  const std::vector<SettingProblem> problems = validate(st);
  EXPECT_EQ(settings_of(problems),
            (std::vector<std::string>{"slices", "components", "threads", "bits", "zstd_level",
                                      "max_error", "lossless"}));
  EXPECT_EQ(problems[0].message, "must be from 1 to 90, not 0");
  EXPECT_EQ(problems[2].message, "must be from 0 (one per core) to 256, not -1");
  EXPECT_EQ(problems[5].message, "must be from 1e-06 to 16, not 20");
}

// A value the encoder does not read is not checked: the data choose the count, or explicit
// boundaries replace it, or the bits are searched.
TEST(EncoderSettings, ValuesThatAreNotReadAreNotChecked) {
  EncoderSettings st;
  st.fit.slices = 0;
  st.fit.auto_slices = true;
  st.fit.components = 0;
  st.fit.auto_components = true;
  st.container.bits = 3;  // auto_bits is on by default
  EXPECT_TRUE(validate(st).empty());
  st.fit.auto_slices = false;
  st.fit.slice_bounds = {0, 30, 90};
  EXPECT_TRUE(validate(st).empty());
  st.fit.slice_bounds = {0, 30, 30, 90};
  ASSERT_EQ(settings_of(validate(st)), std::vector<std::string>{"slice_bounds"});
  st.fit.slice_bounds = {10, 90};
  EXPECT_EQ(settings_of(validate(st)), std::vector<std::string>{"slice_bounds"});
}

TEST(EncoderSettings, ResidualBoundRangeIncludesItsEndsAndRefusesNan) {
  EncoderSettings st;
  for (double ok : {0.0, kMinResidualBound, 0.01, kMaxResidualBound}) {
    st.residual.max_error = ok;
    EXPECT_TRUE(validate(st).empty()) << ok;
  }
  for (double bad : {-1.0, std::nextafter(kMinResidualBound, 0.0),
                     std::nextafter(kMaxResidualBound, 100.0), std::nan(""), HUGE_VAL}) {
    st.residual.max_error = bad;
    EXPECT_EQ(settings_of(validate(st)), std::vector<std::string>{"max_error"}) << bad;
  }
  st.residual = ResidualSettings{};
  st.residual.row_steps = true;  // steps by visibility need a bound
  const std::vector<SettingProblem> steps = validate(st);
  ASSERT_EQ(settings_of(steps), std::vector<std::string>{"residual_steps"});
  EXPECT_EQ(steps[0].message,
            "visibility needs {max_error} above 0 (the bound of the most visible rows)");
  st.residual = target_residual_settings(0.01);
  EXPECT_TRUE(validate(st).empty());
  st.residual.fine_multiplier = 65;
  EXPECT_EQ(settings_of(validate(st)), std::vector<std::string>{"fine_multiplier"});
}

TEST(EncoderSettings, EnumsOutsideTheirValuesAreRefused) {
  EncoderSettings st;
  st.fit.family = CopulaFamily(200);
  st.fit.loss = FitLoss(7);
  st.container.format = ContainerSettings::Format(9);
  st.container.metadata = ContainerSettings::Metadata(9);
  EXPECT_EQ(settings_of(validate(st)),
            (std::vector<std::string>{"family", "loss", "format_version", "metadata"}));
  st = EncoderSettings{};
  st.fit.family = CopulaFamily(200);
  st.fit.auto_family = true;  // every family is tried; the field is not read
  EXPECT_TRUE(validate(st).empty());
}

TEST(EncoderSettings, RateTargetRanges) {
  RateTarget t;
  t.min_psnr = 1000;
  EXPECT_TRUE(validate(t).empty());
  t.min_psnr = 1000.5;
  t.max_bytes = -1;
  t.max_components = 0;
  t.slice_counts = {3, 91};
  EXPECT_EQ(settings_of(validate(t)), (std::vector<std::string>{"target_bytes", "target_psnr",
                                                                "max_components", "slice_counts"}));
  t = RateTarget{};
  t.slice_counts.clear();
  EXPECT_EQ(settings_of(validate(t)), std::vector<std::string>{"slice_counts"});
}

TEST(EncoderSettings, ProblemsAreSpelledByTheFrontEnd) {
  const SettingProblem p{"lossless", "and {max_error} exclude each other (lossless has no error)"};
  const auto dashed = [](std::string_view s) {
    std::string o = "--" + std::string(s);
    for (char& c : o) c = c == '_' ? '-' : c;
    return o;
  };
  EXPECT_EQ(spell_problem(p, dashed),
            "--lossless and --max-error exclude each other (lossless has no error)");
  EXPECT_EQ(spell_problem(p, cxx_spelling),
            "residual.lossless and residual.max_error exclude each other (lossless has no error)");
  EXPECT_EQ(spell_problem(p, {}),
            "lossless and max_error exclude each other (lossless has no error)");
  const std::vector<SettingProblem> two = {{"slices", "must be from 1 to 90, not 0"}, p};
  const Status s = settings_status(two, dashed);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(s.message(),
            "--slices must be from 1 to 90, not 0; --lossless and --max-error exclude each other "
            "(lossless has no error)");
  EXPECT_TRUE(settings_status({}, dashed).ok());
  EXPECT_EQ(cxx_spelling("target_psnr"), "RateTarget::min_psnr");
  EXPECT_EQ(cxx_spelling("not_a_setting"), "not_a_setting");
}

TEST(EncoderSettings, EncodeTableRefusesBeforeAnyWork) {
  EncoderSettings st;
  st.fit.slices = 91;
  const Expected<EncodeResult> r = encode_table(BrdfTable{}, st);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(r.status().message(), "fit.slices must be from 1 to 90, not 91");
}

}  // namespace
}  // namespace cbrdf
