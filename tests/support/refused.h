// SPDX-License-Identifier: MIT
// The check every malformed-file test makes: the decoder refuses the bytes with the expected
// error code and a message that says what is wrong.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/status.h"

namespace cbrdf::testing {

// decode_model(b) fails with `code` and a message containing `needle` (and `also`, when given:
// the chunk a test damaged, say).
inline void expect_refused(const std::vector<std::uint8_t>& b, ErrorCode code,
                           const std::string& needle, const std::string& also = "") {
  Expected<Model> m = decode_model(b);
  ASSERT_FALSE(m.ok()) << "decoded although it should fail with: " << needle;
  EXPECT_EQ(m.status().code(), code)
      << error_code_name(m.status().code()) << ": " << m.status().message();
  EXPECT_NE(m.status().message().find(needle), std::string::npos)
      << "message: " << m.status().message() << "\nexpected to contain: " << needle;
  if (!also.empty()) {
    EXPECT_NE(m.status().message().find(also), std::string::npos)
        << "message: " << m.status().message() << "\nexpected to contain: " << also;
  }
}

}  // namespace cbrdf::testing
