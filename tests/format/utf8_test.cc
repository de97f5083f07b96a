// SPDX-License-Identifier: MIT
// UTF-8 validation of the text the container stores (metadata values).
#include "utf8.h"

#include <gtest/gtest.h>

namespace cbrdf {
namespace {

TEST(Utf8, InvalidBytesBecomeReplacementCharacters) {
  EXPECT_EQ(valid_utf8("plain.binary", 100), "plain.binary");
  EXPECT_EQ(valid_utf8("bad\xff.binary", 100), "bad\xEF\xBF\xBD.binary");
  EXPECT_EQ(valid_utf8("caf\xC3\xA9", 100), "caf\xC3\xA9");
  EXPECT_EQ(valid_utf8("\xC0\xAF", 100), "\xEF\xBF\xBD\xEF\xBF\xBD");  // overlong '/'
  EXPECT_EQ(valid_utf8("\xED\xA0\x80", 100),
            "\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD");           // a surrogate
  EXPECT_EQ(valid_utf8("\xF4\x90\x80\x80", 100).size(), 12u);  // above U+10FFFF
  EXPECT_EQ(valid_utf8("ab\xC3\xA9", 3), "ab");                // no half character at the limit
  EXPECT_TRUE(is_valid_utf8("\xF0\x9F\x98\x80"));
  EXPECT_FALSE(is_valid_utf8("\xF0\x9F\x98"));
}

}  // namespace
}  // namespace cbrdf
