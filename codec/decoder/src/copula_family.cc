// SPDX-License-Identifier: MIT
// Names of the copula families, as used on the command line and in reports.
#include "cbrdf/copula_family.h"

#include <array>
#include <utility>

namespace cbrdf {

namespace {
constexpr std::array<std::pair<CopulaFamily, std::string_view>, 5> kNames = {{
    {CopulaFamily::kIndependence, "independence"},
    {CopulaFamily::kFrank, "frank"},
    {CopulaFamily::kClayton, "clayton"},
    {CopulaFamily::kGumbel, "gumbel"},
    {CopulaFamily::kJoe, "joe"},
}};
}  // namespace

std::string_view family_name(CopulaFamily f) {
  for (const auto& [family, name] : kNames) {
    if (family == f) return name;
  }
  return "unknown";
}

std::optional<CopulaFamily> family_from_name(std::string_view name) {
  for (const auto& [family, n] : kNames) {
    if (n == name) return family;
  }
  return std::nullopt;
}

bool family_valid(std::uint8_t raw) {
  return raw <= std::uint8_t(CopulaFamily::kJoe);
}

}  // namespace cbrdf
