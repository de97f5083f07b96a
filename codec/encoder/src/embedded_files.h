// SPDX-License-Identifier: MIT
// Files compiled into the library (cmake/embed_files.cmake), so that an installed library needs no
// data folder: the built-in measured samples' weights, data/measured/*.nbrdf.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

namespace cbrdf::internal {

struct EmbeddedFile {
  std::string_view name;  // the file name without its extension
  std::span<const std::uint8_t> bytes;
};

// Every data/measured/*.nbrdf at build time, in name order.
std::span<const EmbeddedFile> embedded_nbrdf_files();

}  // namespace cbrdf::internal
