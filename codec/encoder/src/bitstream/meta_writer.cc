// SPDX-License-Identifier: MIT
// mETA's writer (spec 4.5): key=value metadata lines.
#include "bitstream/chunk_writers.h"

namespace cbrdf {

std::vector<std::uint8_t> encode_metadata_chunk(
    const std::vector<std::pair<std::string, std::string>>& entries) {
  std::vector<std::uint8_t> out;
  for (const auto& [key, value] : entries) {
    out.insert(out.end(), key.begin(), key.end());
    out.push_back('=');
    out.insert(out.end(), value.begin(), value.end());
    out.push_back('\n');
  }
  return out;
}

}  // namespace cbrdf
