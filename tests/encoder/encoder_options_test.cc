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

}  // namespace
}  // namespace cbrdf
