// SPDX-License-Identifier: MIT
// The encoder's settings as text (cbrdf/encoder_options.h): defaults, parsing, residual requests.
#include "cbrdf/encoder_options.h"

#include <gtest/gtest.h>

#include "cbrdf/encoder.h"

namespace cbrdf {
namespace {

// EncoderSettings{} is what the command writes without options (the bytes: default_encode_test).
TEST(EncoderOptions, DefaultSettingsAreTheCommandsWithoutOptions) {
  const EncoderSettings d;
  const Expected<EncoderSettings> o = encoder_settings(EncoderOptions{});
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(d.container.format, ContainerSettings::Format::kAuto);
  EXPECT_EQ(d.container.metadata, ContainerSettings::Metadata::kShort);
  EXPECT_TRUE(d.container.write_metadata);
  EXPECT_TRUE(d.auto_bits.enabled);
  EXPECT_EQ(d.fit.slices, 6);
  EXPECT_EQ(d.container.format, o->container.format);
  EXPECT_EQ(d.container.metadata, o->container.metadata);
  EXPECT_EQ(d.auto_bits.enabled, o->auto_bits.enabled);
  EXPECT_EQ(d.container.bits, o->container.bits);
  EXPECT_EQ(d.container.zstd_level, o->container.zstd_level);
  EXPECT_EQ(d.fit.family, o->fit.family);
  EXPECT_EQ(d.fit.components, o->fit.components);
  EXPECT_EQ(d.fit.impute_missing, o->fit.impute_missing);
  EXPECT_EQ(d.fit.mixture_copulas, o->fit.mixture_copulas);
  EXPECT_TRUE(validate(d).empty());
}

// Every value that cannot be read is named, not only the first, beside validate()'s problems.
TEST(EncoderOptions, ParseNamesEveryProblem) {
  EncoderOptions o;
  o.slices = "six";
  o.family = "gauss";
  o.bits = "17";
  o.metadata = "long";
  const ParsedOptions parsed = parse_options(o);
  const std::vector<SettingProblem> expected = {
      {"slices", "must be a whole number or auto, not 'six'"},
      {"family", "must be " + family_list(", ") + " or auto, not 'gauss'"},
      {"metadata", "must be none, short or full, not 'long'"},
      {"bits", "must be from 6 to 16, not 17"},
  };
  EXPECT_EQ(parsed.problems, expected);
  const auto dashed = [](std::string_view s) { return "--" + std::string(s); };
  EXPECT_EQ(encoder_settings(o, dashed).status().message(),
            "--slices must be a whole number or auto, not 'six'; --family must be " +
                family_list(", ") +
                " or auto, not 'gauss'; --metadata must be none, short or full, not 'long'; "
                "--bits must be from 6 to 16, not 17");
}

TEST(EncoderOptions, CountOrAutoParsesOnlyIntegersInRangeAndAuto) {
  EXPECT_EQ(parse_count_or_auto("6", 1, 90, true)->count, 6);
  EXPECT_TRUE(parse_count_or_auto("auto", 1, 90, true)->is_auto);
  EXPECT_FALSE(parse_count_or_auto("auto", 1, 90, false));
  EXPECT_FALSE(parse_count_or_auto("0", 1, 90, true));
  EXPECT_FALSE(parse_count_or_auto("91", 1, 90, true));
  EXPECT_FALSE(parse_count_or_auto(" 6", 1, 90, true));
  EXPECT_FALSE(parse_count_or_auto("+6", 1, 90, true));
  EXPECT_FALSE(parse_count_or_auto("6.0", 1, 90, true));
}

// One residual layer for every front end: a bound alone bounds every bin, visibility steps add
// rate control's levels and row steps under the same bound, lossless stores the table.
TEST(EncoderOptions, ResidualRequestIsWhatTheOptionsWrite) {
  const ResidualSettings none = residual_request(0, false, false);
  EXPECT_EQ(none.max_error, 0);
  EXPECT_FALSE(none.lossless);
  EXPECT_FALSE(none.row_steps);
  const ResidualSettings one = residual_request(0.01, false, false);
  EXPECT_EQ(one.max_error, 0.01);
  EXPECT_FALSE(one.row_steps);
  EXPECT_EQ(one.levels, 0);
  const ResidualSettings steps = residual_request(0.01, false, true);
  const ResidualSettings target = target_residual_settings(0.01);
  EXPECT_EQ(steps.max_error, 0.01);
  EXPECT_TRUE(steps.row_steps);
  EXPECT_EQ(steps.levels, target.levels);
  EXPECT_EQ(steps.fine_multiplier, target.fine_multiplier);
  EXPECT_TRUE(residual_request(0, true, false).lossless);
  // The command's path gives the same.
  EncoderOptions o;
  o.max_error = 0.01;
  o.residual_steps = "visibility";
  const Expected<EncoderSettings> st = encoder_settings(o);
  ASSERT_TRUE(st.ok()) << st.status().message();
  EXPECT_TRUE(st->residual.row_steps);
  EXPECT_EQ(st->residual.levels, target.levels);
  EXPECT_EQ(st->residual.max_error, 0.01);
}

TEST(EncoderOptions, ResidualOptionsBesideATargetAreNamed) {
  EXPECT_FALSE(residual_option_conflict({}));
  EXPECT_FALSE(residual_option_conflict({.target = true}));
  EXPECT_FALSE(residual_option_conflict({.max_error = true, .residual_steps = true}));
  const auto dashed = [](std::string_view s) { return "--" + std::string(s); };
  const auto bound = residual_option_conflict({.target = true, .max_error = true});
  ASSERT_TRUE(bound);
  EXPECT_EQ(bound->setting, "max_error");
  EXPECT_EQ(spell_problem(*bound, dashed)
                .rfind("--max_error and a target (--target_bytes, --target_psnr) exclude", 0),
            0u)
      << bound->message;
  const auto lossless = residual_option_conflict({.target = true, .lossless = true});
  ASSERT_TRUE(lossless);
  EXPECT_EQ(lossless->setting, "lossless");
  const auto steps = residual_option_conflict({.target = true, .residual_steps = true});
  ASSERT_TRUE(steps);
  EXPECT_EQ(steps->setting, "residual_steps");
  EXPECT_NE(steps->message.find("always steps by visibility"), std::string::npos) << steps->message;
  // Steps without a bound are validate()'s to refuse (visibility) or harmless ("one").
  EXPECT_FALSE(residual_option_conflict({.residual_steps = true}));
  EncoderOptions o;
  o.residual_steps = "visibility";
  EXPECT_EQ(encoder_settings(o, dashed).status().message(),
            "--residual_steps visibility needs --max_error above 0 (the bound of the most visible "
            "rows)");
}

}  // namespace
}  // namespace cbrdf
