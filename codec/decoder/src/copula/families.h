// SPDX-License-Identifier: MIT
// The concrete copula families (internal): one final class per file, registered by copula_for().
#pragma once

#include "copula/copula.h"

namespace cbrdf::internal {

const Copula& independence_copula();
const Copula& frank_copula();
const Copula& clayton_copula();
const Copula& gumbel_copula();
const Copula& joe_copula();

}  // namespace cbrdf::internal
