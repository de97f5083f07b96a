// SPDX-License-Identifier: MIT
// The command's option strings (internal: encoder_options.h) and the public command_defaults().
#include "encoder_options.h"

#include <gtest/gtest.h>

#include "cbrdf/encoder.h"

namespace cbrdf {
namespace {

TEST(EncoderOptions, CommandDefaultsAreTheCommandsSettingsWithoutOptions) {
  const EncoderSettings d = command_defaults();
  const Expected<EncoderSettings> o = encoder_settings(EncoderOptions{});
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(d.container.format, ContainerSettings::Format::kAuto);
  EXPECT_EQ(d.container.metadata, ContainerSettings::Metadata::kShort);
  EXPECT_TRUE(d.auto_bits.enabled);
  EXPECT_EQ(d.fit.slices, 6);
  EXPECT_EQ(d.container.format, o->container.format);
  EXPECT_EQ(d.container.bits, o->container.bits);
  EXPECT_EQ(d.container.zstd_level, o->container.zstd_level);
  EXPECT_EQ(d.fit.family, o->fit.family);
  // EncoderSettings{} keeps the older files: 1.2 coding with full metadata.
  EXPECT_EQ(EncoderSettings{}.container.format, ContainerSettings::Format::kV12);
  EXPECT_EQ(EncoderSettings{}.container.metadata, ContainerSettings::Metadata::kFull);
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
  const auto bound = residual_option_conflict({.target = true, .max_error = true});
  ASSERT_TRUE(bound);
  EXPECT_EQ(bound->rfind("--max-error and a target (--target-bytes, --target-psnr) exclude", 0), 0u)
      << *bound;
  const auto lossless = residual_option_conflict({.target = true, .lossless = true});
  ASSERT_TRUE(lossless);
  EXPECT_EQ(lossless->rfind("--lossless and a target", 0), 0u) << *lossless;
  const auto steps = residual_option_conflict({.target = true, .residual_steps = true});
  ASSERT_TRUE(steps);
  EXPECT_NE(steps->find("always steps by visibility"), std::string::npos) << *steps;
  const auto alone = residual_option_conflict({.residual_steps = true});
  ASSERT_TRUE(alone);
  EXPECT_EQ(*alone, "--residual-steps shapes the layer --max-error E adds; give --max-error too");
}

}  // namespace
}  // namespace cbrdf
