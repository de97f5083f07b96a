// SPDX-License-Identifier: MIT
// mETA (spec 4.5): key=value metadata lines. The reader (the writer is the encoder's,
// meta_writer.cc).
#include <string>

#include "chunks.h"

namespace cbrdf {
Status decode_metadata_chunk(std::span<const std::uint8_t> payload,
                             std::vector<std::pair<std::string, std::string>>* out) {
  out->clear();
  std::size_t pos = 0;
  while (pos < payload.size()) {
    if (out->size() == kMaxMetadataEntries) {
      return error(ErrorCode::kLimit,
                   "more than " + std::to_string(kMaxMetadataEntries) + " metadata entries");
    }
    const std::size_t line_start = pos;
    std::size_t eq = pos;
    while (eq < payload.size() && payload[eq] != '=' && payload[eq] != '\n') ++eq;
    if (eq == payload.size() || payload[eq] != '=') {
      return error(ErrorCode::kCorrupt,
                   "metadata line at payload offset " + std::to_string(line_start) + " has no '='");
    }
    std::string key(payload.begin() + std::ptrdiff_t(pos), payload.begin() + std::ptrdiff_t(eq));
    if (key.empty() || key.size() > kMaxMetadataKeyBytes) {
      return error(ErrorCode::kCorrupt, "metadata key at payload offset " +
                                            std::to_string(line_start) +
                                            " is empty or longer than " +
                                            std::to_string(kMaxMetadataKeyBytes) + " bytes");
    }
    for (char ch : key) {
      const bool ok =
          (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_' || ch == '.';
      if (!ok) {
        return error(ErrorCode::kCorrupt, "metadata key at payload offset " +
                                              std::to_string(line_start) +
                                              " has a character outside [a-z0-9_.]");
      }
    }
    for (const auto& kv : *out) {
      if (kv.first == key) {
        return error(ErrorCode::kCorrupt, "metadata key '" + key + "' at payload offset " +
                                              std::to_string(line_start) + " appears twice");
      }
    }
    std::size_t nl = eq + 1;
    while (nl < payload.size() && payload[nl] != '\n') {
      if (payload[nl] < 0x20 || payload[nl] == 0x7F) {
        return error(ErrorCode::kCorrupt, "metadata value at payload offset " + std::to_string(nl) +
                                              " has a control character");
      }
      ++nl;
    }
    if (nl == payload.size()) {
      return error(ErrorCode::kCorrupt, "metadata line at payload offset " +
                                            std::to_string(line_start) +
                                            " is not terminated by LF");
    }
    if (nl - eq - 1 > kMaxMetadataValueBytes) {
      return error(ErrorCode::kCorrupt, "metadata value at payload offset " +
                                            std::to_string(eq + 1) + " is longer than " +
                                            std::to_string(kMaxMetadataValueBytes) + " bytes");
    }
    out->emplace_back(std::move(key), std::string(payload.begin() + std::ptrdiff_t(eq + 1),
                                                  payload.begin() + std::ptrdiff_t(nl)));
    pos = nl + 1;
  }
  return ok_status();
}

}  // namespace cbrdf
