// SPDX-License-Identifier: MIT
// The Archimedean copula families cbrdf knows. Values are stable: they are written to .cbrdf files.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace cbrdf {

enum class CopulaFamily : std::uint8_t {
  kIndependence = 0,  // c = 1: the separable model; no parameter
  kFrank = 1,         // paper's convention: g_t = e^{theta t} - 1; theta < 0 positive dependence
  kClayton = 2,
  kGumbel = 3,  // Gumbel-Hougaard
  kJoe = 4,
};

std::string_view family_name(CopulaFamily f);
std::optional<CopulaFamily> family_from_name(std::string_view name);
bool family_valid(std::uint8_t raw);

}  // namespace cbrdf
