// SPDX-License-Identifier: MIT
/// @file
/// The Archimedean copula families cbrdf knows. Values are stable: they are written to .cbrdf
/// files. One internal table holds every family (its name, id, parameter range, density and
/// sampler); the enumerators name the families code refers to by name.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cbrdf {

/// A copula family; the value is its id in .cbrdf files.
enum class CopulaFamily : std::uint8_t {
  kIndependence = 0,  ///< c = 1: the separable model; no parameter
  kFrank = 1,         ///< paper's convention: g_t = e^{theta t} - 1; theta < 0 positive dependence
  kClayton = 2,
  kGumbel = 3,  ///< Gumbel-Hougaard
  kJoe = 4,
};

/// The name the command and files use ("frank", "joe", ...).
std::string_view family_name(CopulaFamily f);
/// The family of a name family_name() gives; nullopt for any other.
std::optional<CopulaFamily> family_from_name(std::string_view name);
/// Whether raw is a known family id.
bool family_valid(std::uint8_t raw);
/// Whether a known family has a parameter (independence has not).
bool family_has_parameter(CopulaFamily f);
/// Every known family in the order the command lists them: those with a parameter by id, then
/// independence (the separable model).
std::vector<CopulaFamily> listed_families();
/// The names of listed_families() joined by separator: "frank, clayton, gumbel, joe,
/// independence" for ", ".
std::string family_list(std::string_view separator);

}  // namespace cbrdf
