// SPDX-License-Identifier: MIT
/// @file
/// A BRDF as a function: what samplers, metrics and renderers take, whatever the representation
/// (the copula model, a measured table, an analytic model).
#pragma once

#include <functional>

#include "cbrdf/coords.h"

namespace cbrdf {

/// A BRDF as a function of local directions (z = normal): physical RGB (1/sr) into rgb.
/// Renders call it from several threads at once: it must not mutate shared state.
using BrdfFn = std::function<void(const Vec3& wi, const Vec3& wo, double rgb[3])>;

}  // namespace cbrdf
