// SPDX-License-Identifier: MIT
// UTF-8 validation for text the container stores (metadata values).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace cbrdf {

// The longest prefix of s, at most max_bytes long, with every byte that is not part of a valid
// UTF-8 sequence (overlong forms, surrogates and code points above U+10FFFF included) replaced by
// U+FFFD, and no character cut in half by the limit.
std::string valid_utf8(std::string_view s, std::size_t max_bytes);

// Whether s is valid UTF-8 (as above).
bool is_valid_utf8(std::string_view s);

}  // namespace cbrdf
