// SPDX-License-Identifier: MIT
// Names of the copula families, as used on the command line and in reports: the registry's.
#include "cbrdf/copula_family.h"

#include "copula/registry.h"

namespace cbrdf {

std::string_view family_name(CopulaFamily f) {
  const CopulaFamilyRow* row = family_row(f);
  return row ? row->name : "unknown";
}

std::optional<CopulaFamily> family_from_name(std::string_view name) {
  for (const CopulaFamilyRow& row : kCopulaFamilies) {
    if (row.name == name) return row.id;
  }
  return std::nullopt;
}

bool family_valid(std::uint8_t raw) {
  return family_row(CopulaFamily(raw)) != nullptr;
}

bool family_has_parameter(CopulaFamily f) {
  const CopulaFamilyRow* row = family_row(f);
  return row && row->has_parameter();
}

std::vector<CopulaFamily> listed_families() {
  std::vector<CopulaFamily> out;
  // The families with a parameter first, by id; the separable model last.
  for (bool parameter : {true, false}) {
    for (const CopulaFamilyRow& row : kCopulaFamilies) {
      if (row.has_parameter() == parameter) out.push_back(row.id);
    }
  }
  return out;
}

std::string family_list(std::string_view separator) {
  std::string out;
  for (CopulaFamily f : listed_families()) {
    if (!out.empty()) out += separator;
    out += family_name(f);
  }
  return out;
}

}  // namespace cbrdf
