// SPDX-License-Identifier: MIT
// EncoderSettings{} is `cbrdf encode` without options: the same file, byte for byte.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "cbrdf/container.h"
#include "cbrdf/encoder.h"
#include "cbrdf/file_io.h"
#include "cbrdf/merl_io.h"
#include "table_builder.h"
#include "test_support.h"

namespace cbrdf {
namespace {

TEST(DefaultEncode, DefaultSettingsWriteTheCommandsDefaultFile) {
  // A diffuse base under a specular lobe that narrows towards grazing: enough shape that the
  // fit, the bits search and the 1.3-or-1.2 choice all have something to decide.
  const BrdfTable table = testing::make_table([](int c, int h, int d, int p) {
    const double lobe = std::exp(-0.02 * h * h / (1.0 + 0.05 * d));
    return 0.05 * (1 + c) + 2.0 * lobe * (1.0 + 0.3 * std::cos(p * 0.0349));
  });
  testing::TempDir dir;
  ASSERT_TRUE(write_merl(dir / "synthetic.binary", table).ok());
  const testing::CommandResult r =
      testing::run_cli("-q encode " + (dir / "synthetic.binary").string() + " -o " +
                       (dir / "cli.cbrdf").string() + " --no-metrics");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Expected<std::vector<std::uint8_t>> command_file =
      read_file(dir / "cli.cbrdf", kMaxContainerBytes);
  ASSERT_TRUE(command_file.ok()) << command_file.status().message();

  // The command records the input's file name and fits on every core (the threads change the
  // time, not the bytes); everything else is the defaults.
  const Expected<BrdfTable> input = read_merl(dir / "synthetic.binary");
  ASSERT_TRUE(input.ok()) << input.status().message();
  EncoderSettings settings;
  settings.container.source_name = "synthetic.binary";
  settings.fit.threads = 0;
  const Expected<EncodeResult> library = encode_table(*input, settings);
  ASSERT_TRUE(library.ok()) << library.status().message();
  EXPECT_EQ(library->bytes, *command_file);
}

}  // namespace
}  // namespace cbrdf
